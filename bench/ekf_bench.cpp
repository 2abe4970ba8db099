// Cost of one filter cycle -- a prediction, a pose update 5 ticks late (m = 3) and a twist update
// 1 tick late (m = 2) -- for coloc's Localizer and for an augmented-state filter built as Autoware's
// ekf_localizer is, measured in the same run. Ends with a table of medians and ratios, and checks
// that both filters produce the same estimates.
//
//   build/bench/ekf_bench                      # full run, about a minute
//   build/bench/ekf_bench --benchmark_filter=/50   # window 50 only
#include <benchmark/benchmark.h>

#include "median_collector.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "augmented_state_ekf.hpp"
#include "coloc/fusion/localizer.hpp"
#include "measurement_record.hpp"
#include "measurements.hpp"

namespace {

using namespace coloc;
using namespace coloc::fusion;
using coloc::testing::kStart;
using coloc::testing::kTick;
using Clock = std::chrono::steady_clock;

enum Phase { kPredict = 0, kPoseUpdate = 1, kTwistUpdate = 2 };
const char* const kPhaseNames[] = {"predict", "pose_update", "twist_update"};
constexpr int kPoseDelay = 5, kTwistDelay = 1;

// A vehicle circling at 10 m/s and 0.1 rad/s; the measurements agree with it, so no gate ever fires.
PoseMeasurement poseAt(int k) {
  const double t = k * 0.02;
  return testing::planarPose(kStart + k * kTick, 100.0 * std::sin(0.1 * t), 100.0 * (1.0 - std::cos(0.1 * t)),
                             wrapAngle(0.1 * t));
}
TwistMeasurement twistAt(int k) { return testing::twist(kStart + k * kTick, 10.0, 0.1); }

EkfConfig benchConfig(int window, bool relinearize) {
  EkfConfig c;
  c.history_steps = window;
  c.relinearize_on_replay = relinearize;
  c.auto_initialize = false;
  // One use per measurement, as the cost figures of Autoware's filter were taken per single update.
  c.pose_smoothing_steps = c.twist_smoothing_steps = 1;
  return c;
}

double seconds(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

void BM_Coloc(benchmark::State& state) {
  const int window = static_cast<int>(state.range(0));
  const Phase phase = static_cast<Phase>(state.range(1));
  Localizer localizer(benchConfig(window, true));
  const SourceId ndt = localizer.addPoseSource("ndt"), odom = localizer.addTwistSource("odom");
  localizer.initialize(poseAt(0));
  int k = 0;
  auto cycle = [&](bool timed) {
    double elapsed = 0.0;
    ++k;
    auto t0 = Clock::now();
    localizer.advanceTo(kStart + k * kTick);
    auto t1 = Clock::now();
    if (phase == kPredict) elapsed = seconds(t0, t1);
    t0 = Clock::now();
    localizer.feedPose(ndt, poseAt(k - kPoseDelay));
    localizer.estimate();  // the replay the update causes is part of its cost
    t1 = Clock::now();
    if (phase == kPoseUpdate) elapsed = seconds(t0, t1);
    t0 = Clock::now();
    localizer.feedTwist(odom, twistAt(k - kTwistDelay));
    localizer.estimate();
    t1 = Clock::now();
    if (phase == kTwistUpdate) elapsed = seconds(t0, t1);
    (void)timed;
    return elapsed;
  };
  for (int i = 0; i < 2 * window + 10; ++i) cycle(false);  // fill the history
  for (auto _ : state) state.SetIterationTime(cycle(true));
  state.SetLabel(kPhaseNames[phase]);
}

void BM_Augmented(benchmark::State& state) {
  const int window = static_cast<int>(state.range(0));
  const Phase phase = static_cast<Phase>(state.range(1));
  const EkfConfig c = benchConfig(window, false);
  testing::AugmentedStateEkf ekf(window, {c.proc_stddev_yaw_c, c.proc_stddev_vx_c, c.proc_stddev_wz_c}, 0.02);
  Vector6d x0 = Vector6d::Zero();
  Matrix6d P0 = Matrix6d::Zero();
  P0.diagonal() << 0.0225, 0.0225, 0.000625, 1e-4, 100.0, 1.0;
  ekf.initialize(x0, P0);
  const Eigen::Vector3d pose_y(0.0, 0.0, 0.0);
  const Eigen::Matrix3d pose_R = Eigen::Vector3d(0.0225, 0.0225, 0.000625).asDiagonal();
  const Eigen::Matrix2d twist_R = Eigen::Vector2d(0.04, 0.01).asDiagonal();
  int k = 0;
  auto cycle = [&]() {
    double elapsed = 0.0;
    ++k;
    const PoseMeasurement pose = poseAt(k - kPoseDelay);
    const Eigen::Vector3d y(pose.pose.position.x(), pose.pose.position.y(), wrapAngle(0.1 * (k - kPoseDelay) * 0.02));
    auto t0 = Clock::now();
    ekf.predict();
    auto t1 = Clock::now();
    if (phase == kPredict) elapsed = seconds(t0, t1);
    t0 = Clock::now();
    ekf.update(kPoseDelay, {kX, kY, kYaw}, y, pose_R);
    t1 = Clock::now();
    if (phase == kPoseUpdate) elapsed = seconds(t0, t1);
    t0 = Clock::now();
    ekf.update(kTwistDelay, {kVx, kWz}, Eigen::Vector2d(10.0, 0.1), twist_R);
    t1 = Clock::now();
    if (phase == kTwistUpdate) elapsed = seconds(t0, t1);
    return elapsed;
  };
  for (int i = 0; i < window + 10; ++i) cycle();
  for (auto _ : state) state.SetIterationTime(cycle());
  state.SetLabel(kPhaseNames[phase]);
}

void windowsAndPhases(benchmark::internal::Benchmark* b) {
  for (int window : {10, 50, 100})
    for (int phase = 0; phase < 3; ++phase) b->Args({window, phase});
  b->UseManualTime()->Unit(benchmark::kMicrosecond)->MinTime(0.2)->Repetitions(3)->ReportAggregatesOnly(true);
}
BENCHMARK(BM_Coloc)->Apply(windowsAndPhases);
BENCHMARK(BM_Augmented)->Apply(windowsAndPhases);


// Runs both filters on the same inputs and returns the largest difference of the newest state and
// covariance. Frozen linearisation must agree to rounding; relinearised differs at second order.
double largestDifference(int window, bool relinearize, int cycles, int from_cycle) {
  const EkfConfig c = benchConfig(window, relinearize);
  Localizer localizer(c);
  const SourceId ndt = localizer.addPoseSource("ndt"), odom = localizer.addTwistSource("odom");
  localizer.initialize(poseAt(0));
  testing::AugmentedStateEkf ekf(window, {c.proc_stddev_yaw_c, c.proc_stddev_vx_c, c.proc_stddev_wz_c}, 0.02);
  ekf.initialize(localizer.estimate()->state, localizer.estimate()->state_covariance);
  double largest = 0.0;
  for (int k = 1; k <= cycles; ++k) {
    localizer.advanceTo(kStart + k * kTick);
    ekf.predict();
    if (k <= kPoseDelay) continue;  // Autoware fills the ticks before its initial pose with uncorrelated copies
    const PoseMeasurement pose = poseAt(k - kPoseDelay);
    const TwistMeasurement tw = twistAt(k - kTwistDelay);
    localizer.feedPose(ndt, pose);
    localizer.feedTwist(odom, tw);
    for (const auto& [record, delay] : {std::pair{std::get<UpdateRecord>(makePoseRecord(pose)), kPoseDelay},
                                        std::pair{std::get<UpdateRecord>(makeTwistRecord(tw, 0.0)), kTwistDelay}}) {
      std::vector<int> index(record.index.begin(), record.index.begin() + record.m);
      Eigen::VectorXd y(record.m);
      for (int i = 0; i < record.m; ++i) y[i] = record.value[i];
      ekf.update(delay, index, y, record.R.topLeftCorner(record.m, record.m));
    }
    if (k < from_cycle) continue;
    const Estimate e = *localizer.estimate();
    Vector6d difference = e.state - ekf.latest();
    difference[kYaw] = wrapAngle(difference[kYaw]);  // coloc keeps yaw wrapped after updates, Autoware does not
    largest = std::max(largest, difference.cwiseAbs().maxCoeff());
    largest = std::max(largest, (e.state_covariance - ekf.latestCovariance()).cwiseAbs().maxCoeff());
  }
  return largest;
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  coloc::bench::MedianCollector reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);

  std::printf("\nMedian cost per operation, microseconds (augmented = Autoware's extended-state filter)\n");
  std::printf("%-7s %-13s %11s %11s %9s\n", "window", "operation", "augmented", "coloc", "ratio");
  for (int window : {10, 50, 100})
    for (int phase = 0; phase < 3; ++phase) {
      const std::string key = std::to_string(window) + "/" + std::to_string(phase);
      const auto a = reporter.medians["BM_Augmented"].find(key);
      const auto c = reporter.medians["BM_Coloc"].find(key);
      if (a == reporter.medians["BM_Augmented"].end() || c == reporter.medians["BM_Coloc"].end()) continue;
      std::printf("%-7d %-13s %11.3f %11.3f %8.1fx\n", window, kPhaseNames[phase], a->second, c->second, a->second / c->second);
    }
  std::printf("\nSame inputs through both filters (window 50, 2000 cycles), largest |difference| of state and covariance:\n");
  std::printf("  frozen linearisation (relinearize_on_replay: false): %.3g\n", largestDifference(50, false, 2000, 0));
  std::printf("  relinearised replay (default):                      %.3g (start-up, vx 0 -> 10 m/s in one update)\n",
              largestDifference(50, true, 2000, 0));
  std::printf("  relinearised replay, after the first 4 s:           %.3g (second-order terms of small corrections)\n",
              largestDifference(50, true, 2000, 200));
  benchmark::Shutdown();
  return 0;
}
