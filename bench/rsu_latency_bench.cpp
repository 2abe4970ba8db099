// Added latency from an RSU publishing a fix to the fix being in the filter: publish over Fast DDS
// (UDP on loopback, ROS 2 sensor-data QoS), receive, check, convert, feed the Localizer. Reports the
// median and 99th percentile of the whole path and of coloc's own part (check + feed), both measured
// in the same run, over 1,000 fixes at 100 Hz.
//
//   build/bench/rsu_latency_bench
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <mutex>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "coloc/fusion/localizer.hpp"
#include "coloc/rsu_client/dds_transport.hpp"

using namespace coloc;
using Clock = std::chrono::steady_clock;

namespace {

double percentileUs(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return 1e6 * v[static_cast<std::size_t>(p * static_cast<double>(v.size() - 1))];
}

}  // namespace

int main() {
  constexpr int kFixes = 1000;
  rsu_client::FixChecker checker(
      rsu_client::RsuRegistry::parse("rsus:\n  - {id: rsu_a, position: [0, 0], lidar_model: VLP-32C}\n", "bench"));
  fusion::EkfConfig ekf;
  ekf.auto_initialize = false;
  fusion::Localizer localizer(ekf);
  const fusion::SourceId rsu = localizer.addPoseSource("rsu_a");
  PoseMeasurement start;
  start.stamp = rsu_client::systemNow() - 100'000'000;
  start.pose.position = {10.0, 0.5, 0.0};
  start.covariance = Matrix6d::Zero();
  start.covariance.diagonal() << 1.0, 1.0, kInfinity, kInfinity, kInfinity, 0.1;
  localizer.initialize(start);

  std::mutex mutex;
  std::unordered_map<Stamp, Clock::time_point> sent;
  std::vector<double> total, own;
  int applied = 0, pending = 0;
  std::vector<std::string> rejections;
  rsu_client::DdsConfig config;
  config.domain = 73;
  rsu_client::FixSubscriber subscriber(config, {"rsu_a"}, [&](const rsu_client::RsuFix& fix, Stamp now) {
    const auto arrived = Clock::now();
    std::lock_guard<std::mutex> lock(mutex);
    localizer.advanceTo(now);
    const rsu_client::FixVerdict v = checker.check(fix, now);
    if (!v.accepted() && rejections.size() < 3) rejections.push_back(v.detail);
    if (v.accepted()) {
      const fusion::Verdict verdict = localizer.feedPose(rsu, v.measurement);
      if (verdict.applied()) ++applied;
      else if (verdict.outcome == fusion::Outcome::kPending) ++pending;  // stamped past the newest tick: applied at the next
      else if (rejections.size() < 3) rejections.push_back(verdict.message());
    }
    const auto done = Clock::now();
    const auto it = sent.find(fix.stamp);
    if (it == sent.end()) return;
    total.push_back(std::chrono::duration<double>(done - it->second).count());
    own.push_back(std::chrono::duration<double>(done - arrived).count());
  });
  rsu_client::FixPublisher publisher(config, "rsu_a");
  if (!publisher.waitForSubscribers(1, std::chrono::seconds(10))) {
    std::fprintf(stderr, "rsu_latency_bench: the subscriber never matched\n");
    return 1;
  }
  for (int i = 0; i < kFixes; ++i) {
    const Stamp stamp = rsu_client::systemNow();
    {
      std::lock_guard<std::mutex> lock(mutex);
      sent[stamp] = Clock::now();
    }
    publisher.publish({stamp, "rsu_a", 10.0, 0.5, std::nullopt}, 0.00681);  // a vehicle standing in view
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  std::lock_guard<std::mutex> lock(mutex);
  std::printf("fixes: %d published, %zu received; in the filter: %d applied at once, %d held for their tick\n", kFixes,
              total.size(), applied, pending);
  for (const std::string& r : rejections) std::printf("  %s\n", r.c_str());
  std::printf("%-44s %10s %10s\n", "path", "median us", "p99 us");
  std::printf("%-44s %10.1f %10.1f\n", "publish -> in the Localizer (whole path)", percentileUs(total, 0.5), percentileUs(total, 0.99));
  std::printf("%-44s %10.1f %10.1f\n", "of which coloc: check + convert + feed", percentileUs(own, 0.5), percentileUs(own, 0.99));
  std::vector<double> transport(total.size());
  for (std::size_t i = 0; i < total.size(); ++i) transport[i] = total[i] - own[i];
  std::printf("%-44s %10.1f %10.1f\n", "of which Fast DDS on loopback", percentileUs(transport, 0.5), percentileUs(transport, 0.99));
  return 0;
}
