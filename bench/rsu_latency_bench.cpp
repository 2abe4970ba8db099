// Added latency from an RSU publishing a fix to the fix being in the filter, through the vehicle
// pipeline a stack links: publish over Fast DDS (UDP on loopback, ROS 2 sensor-data QoS), receive, queue
// in the pipeline's inbox, drained at the next tick, checked, converted, fed. Reports the median and 99th
// percentile of the whole path and of its two parts, measured in the same run, over 1,000 fixes at 100 Hz.
//
//   build/bench/rsu_latency_bench
#include <cstdlib>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <mutex>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "coloc/pipeline/pipeline.hpp"
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

int main(int argc, char** argv) {
  // The number of fixes; fewer for the smoke run that keeps the benchmark working (ctest).
  const int kFixes = argc > 1 ? std::max(1, std::atoi(argv[1])) : 1000;
  pipeline::Config config;
  config.fusion.auto_initialize = false;
  config.rsu.checks.station_id = 7;  // the vehicle's CAM station id: fixes are addressed to it (docs/rsu-protocol.md)
  pipeline::PipelineOptions options;
  options.registry = rsu_client::RsuRegistry::parse("rsus:\n  - {id: rsu_a, position: [0, 0], lidar_model: VLP-32C}\n", "bench");
  pipeline::Pipeline vehicle(config, std::move(options));
  PoseMeasurement start;
  start.stamp = rsu_client::systemNow() - 100'000'000;
  start.pose.position = {10.0, 0.5, 0.0};
  start.covariance = Matrix6d::Zero();
  start.covariance.diagonal() << 1.0, 1.0, kInfinity, kInfinity, kInfinity, 0.1;
  vehicle.pushInitialPose(start, start.stamp);

  std::mutex mutex;
  std::unordered_map<Stamp, Clock::time_point> sent, queued;
  std::vector<double> total, transport, waiting;
  std::vector<std::string> rejections;
  vehicle.onPoseInput([&](const std::string&, const PoseMeasurement& m) {  // the fix is handed to the filter
    const auto now = Clock::now();
    std::lock_guard<std::mutex> lock(mutex);
    const auto s = sent.find(m.stamp);
    const auto q = queued.find(m.stamp);
    if (s == sent.end() || q == queued.end()) return;
    total.push_back(std::chrono::duration<double>(now - s->second).count());
    transport.push_back(std::chrono::duration<double>(q->second - s->second).count());
    waiting.push_back(std::chrono::duration<double>(now - q->second).count());
  });
  vehicle.onRejection([&](const std::string& line) {
    std::lock_guard<std::mutex> lock(mutex);
    if (rejections.size() < 3) rejections.push_back(line);
  });
  vehicle.start();

  rsu_client::DdsConfig dds;
  dds.domain = 73;
  dds.loopback_only = true;  // measured on loopback: nothing leaves the machine
  rsu_client::FixSubscriber subscriber(dds, {"rsu_a"}, [&](const rsu_client::RsuFix& fix, Stamp now) {
    {
      std::lock_guard<std::mutex> lock(mutex);
      queued[fix.stamp] = Clock::now();
    }
    vehicle.pushFix(fix, now);  // what a DDS callback of a vehicle stack does: queue, nothing else
  });
  rsu_client::FixPublisher publisher(dds, "rsu_a");
  if (!publisher.waitForSubscribers(1, std::chrono::seconds(10))) {
    std::fprintf(stderr, "rsu_latency_bench: the subscriber never matched\n");
    return 1;
  }
  // Fixes go best effort (ROS 2's sensor-data QoS): the publisher matching the subscriber is half of
  // discovery, and what it sends before the subscriber has matched it back is dropped on arrival (7 of
  // 50 fixes in 1 run of 20). Both sides matched, nothing is lost on loopback.
  for (int waited = 0; subscriber.matchedPublishers() < 1; ++waited) {
    if (waited == 1000) {
      std::fprintf(stderr, "rsu_latency_bench: the subscriber never matched the publisher\n");
      return 1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  for (int i = 0; i < kFixes; ++i) {
    const Stamp stamp = rsu_client::systemNow();
    {
      std::lock_guard<std::mutex> lock(mutex);
      sent[stamp] = Clock::now();
    }
    publisher.publish({stamp, "rsu_a", 10.0, 0.5, std::nullopt, std::nullopt, 7u}, 0.00681);  // a vehicle standing in view
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  vehicle.stop();
  const pipeline::PipelineReport report = vehicle.report();
  std::lock_guard<std::mutex> lock(mutex);
  std::printf("fixes: %d published, %zu queued, %llu accepted by the checks, %zu handed to the filter\n", kFixes, queued.size(),
              static_cast<unsigned long long>(report.fixes.count("rsu_a") ? report.fixes.at("rsu_a").passed_checks : 0), total.size());
  for (const std::string& r : rejections) std::printf("  %s\n", r.c_str());
  std::printf("%-52s %10s %10s\n", "path", "median us", "p99 us");
  std::printf("%-52s %10.1f %10.1f\n", "publish -> in the filter (whole path)", percentileUs(total, 0.5), percentileUs(total, 0.99));
  std::printf("%-52s %10.1f %10.1f\n", "of which Fast DDS on loopback (publish -> queued)", percentileUs(transport, 0.5),
              percentileUs(transport, 0.99));
  std::printf("%-52s %10.1f %10.1f\n", "of which the pipeline (queued -> checked, in the filter)", percentileUs(waiting, 0.5),
              percentileUs(waiting, 0.99));
  std::printf("(the pipeline drains its queue at the filter's 50 Hz ticks, as Autoware's node does: a fix waits up to 20 ms)\n");
  // Every fix must reach the filter: a benchmark of a path that drops them measures nothing.
  return total.size() == static_cast<std::size_t>(kFixes) ? 0 : 1;
}
