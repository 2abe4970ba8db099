// smoother_bench: the cost of smoothing a drive of 1x, 4x and 16x the reference (300 m at
// 30 km/h: 1,800 ticks, about 370 NDT poses, 60 roadside fixes), against the filter over the same
// inputs in the same run, and as a fraction of the drive's own duration.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <random>

#include "coloc/fusion/localizer.hpp"
#include "coloc/smoother/smoother.hpp"
#include "median_collector.hpp"

namespace coloc {
namespace {

constexpr Stamp kStart = 1'700'000'000'000'000'000LL;
constexpr double kTickS = 0.02;
constexpr int kTicksPer300m = 1800;  // 36 s at 8.33 m/s
constexpr double kSpeed = 300.0 / (kTicksPer300m * kTickS);

// One drive's measurements: odometry every tick (1 % slow, noisy), NDT every 5th tick less about one in
// twenty (370 per 300 m), and an RSU's fixes at 10 Hz for the 6 s of every 36 s that it covers (60).
struct Inputs {
  int ticks = 0;
  std::vector<TwistMeasurement> twists;
  std::vector<PoseMeasurement> ndt, fixes;
  std::vector<std::pair<Stamp, Vector6d>> filtered;  ///< the filter's states: the smoother's first guess
};

Vector6d truthAt(double t) {
  const double yaw = 0.3 * std::sin(t / 20.0);  // a gently winding road
  const double wz = 0.3 / 20.0 * std::cos(t / 20.0);
  return (Vector6d() << kSpeed * t, 0.0, yaw, 0.0, kSpeed, wz).finished();
}

Inputs makeInputs(int length) {
  Inputs in;
  in.ticks = kTicksPer300m * length;
  std::mt19937 rng(42);
  std::normal_distribution<double> n01;
  Eigen::Vector2d position(0.0, 0.0);
  for (int k = 0; k <= in.ticks; ++k) {
    const double t = k * kTickS;
    const Vector6d s = truthAt(t);
    if (k > 0) position += kSpeed * kTickS * Eigen::Vector2d(std::cos(s[2]), std::sin(s[2]));
    const Stamp stamp = kStart + fromSeconds(t);
    TwistMeasurement tw;
    tw.stamp = stamp;
    tw.linear = {0.99 * s[4] + 0.02 * n01(rng), 0.0, 0.0};
    tw.angular = {0.0, 0.0, s[5] + 0.002 * n01(rng)};
    tw.covariance = Matrix6d::Zero();
    tw.covariance.diagonal() << 0.04, kInfinity, kInfinity, kInfinity, kInfinity, 0.01;
    in.twists.push_back(tw);
    if (k % 5 == 0 && k % 100 != 50) {
      PoseMeasurement p;
      p.stamp = stamp;
      p.pose.position = {position.x() + 0.03 * n01(rng), position.y() + 0.03 * n01(rng), 0.0};
      p.pose.orientation = quaternionFromRollPitchYaw(0.0, 0.0, s[2] + 0.003 * n01(rng));
      p.covariance = Matrix6d::Zero();
      p.covariance.diagonal() << 0.0225, 0.0225, kInfinity, kInfinity, kInfinity, 0.000625;
      in.ndt.push_back(p);
    }
    if (k % kTicksPer300m < 300 && k % 5 == 2) {
      PoseMeasurement f;
      f.stamp = stamp + 3'000'000;  // between two ticks
      f.pose.position = {position.x() + 0.0068 * n01(rng), position.y() + 0.0068 * n01(rng), 0.0};
      f.covariance = Matrix6d::Zero();
      f.covariance.diagonal() << 4.6e-5, 4.6e-5, kInfinity, kInfinity, kInfinity, kInfinity;
      in.fixes.push_back(f);
    }
  }
  return in;
}

// The filter over the inputs, in stamp order at its ticks.
std::vector<std::pair<Stamp, Vector6d>> filter(const Inputs& in) {
  fusion::EkfConfig c;
  c.auto_initialize = false;
  fusion::Localizer localizer(c);
  const fusion::SourceId ndt = localizer.addPoseSource("ndt"), rsu = localizer.addPoseSource("rsu"), odom = localizer.addTwistSource("odom");
  localizer.initialize(in.ndt.front());
  std::vector<std::pair<Stamp, Vector6d>> states;
  std::size_t p = 0, f = 0;
  for (int k = 0; k <= in.ticks; ++k) {
    const Stamp stamp = kStart + fromSeconds(k * kTickS);
    localizer.advanceTo(stamp);
    localizer.feedTwist(odom, in.twists[static_cast<std::size_t>(k)]);
    while (p < in.ndt.size() && in.ndt[p].stamp <= stamp) localizer.feedPose(ndt, in.ndt[p++]);
    while (f < in.fixes.size() && in.fixes[f].stamp <= stamp) localizer.feedPose(rsu, in.fixes[f++]);
    states.emplace_back(stamp, localizer.estimate()->state);
  }
  return states;
}

const Inputs& inputs(int length) {
  static std::map<int, Inputs> cache;
  auto it = cache.find(length);
  if (it == cache.end()) {
    it = cache.emplace(length, makeInputs(length)).first;
    it->second.filtered = filter(it->second);
  }
  return it->second;
}

void BM_Filter(benchmark::State& state) {
  const Inputs& in = inputs(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(filter(in));
  state.counters["drive_s"] = in.ticks * kTickS;
}

void BM_Smoother(benchmark::State& state) {
  const Inputs& in = inputs(static_cast<int>(state.range(0)));
  smoother::SmootherOptions o;
  o.covariances = state.range(1) != 0;
  for (auto _ : state) {
    smoother::Smoother s(o);
    for (const auto& [stamp, x] : in.filtered) s.addGuess(stamp, x);
    for (const auto& t : in.twists) s.addTwist("odom", t);
    for (const auto& p : in.ndt) s.addPose("ndt", p);
    for (const auto& f : in.fixes) s.addPose("rsu", f);
    const smoother::SmootherResult r = s.solve(in.filtered.front().first, in.filtered.back().first);
    if (!r.summary.usable()) state.SkipWithError(r.summary.report.c_str());
    benchmark::DoNotOptimize(r);
  }
  state.counters["drive_s"] = in.ticks * kTickS;
}

BENCHMARK(BM_Filter)->Arg(1)->Arg(4)->Arg(16)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_Smoother)->ArgsProduct({{1, 4, 16}, {0, 1}})->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace coloc

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  coloc::bench::MedianCollector reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  std::printf("\nMedian wall time, ms (drive: 300 m per unit of length, 30 km/h; 2 solver threads)\n");
  std::printf("%-7s %8s %9s %13s %13s %12s %12s\n", "length", "drive s", "filter", "smoother", "+covariances", "vs filter", "of drive");
  for (int length : {1, 4, 16}) {
    const std::string l = std::to_string(length);
    auto& f = reporter.medians["BM_Filter"];
    auto& s = reporter.medians["BM_Smoother"];
    if (!f.count(l) || !s.count(l + "/0") || !s.count(l + "/1")) continue;
    const double drive_ms = length * coloc::kTicksPer300m * coloc::kTickS * 1e3;
    std::printf("%-7s %8.0f %9.1f %13.1f %13.1f %11.1fx %11.4f\n", (l + "x").c_str(), drive_ms / 1e3, f[l], s[l + "/0"], s[l + "/1"],
                s[l + "/1"] / f[l], s[l + "/1"] / drive_ms);
  }
  benchmark::Shutdown();
  return 0;
}
