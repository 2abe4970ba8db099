#include "coloc/replay/evaluation.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace coloc::replay {
namespace {

// A straight drive east at 10 m/s, ground truth at 100 Hz.
std::vector<io::TrajectoryPoint> truthEast(double seconds) {
  std::vector<io::TrajectoryPoint> truth;
  for (int k = 0; k <= static_cast<int>(seconds * 100); ++k) {
    io::TrajectoryPoint p;
    p.stamp = fromSeconds(0.01 * k);
    p.pose.position = Eigen::Vector3d(0.1 * k, 0.0, 0.0);
    truth.push_back(p);
  }
  return truth;
}

ErrorSample sampleAt(double t, double error) {
  ErrorSample e;
  e.stamp = fromSeconds(t);
  e.truth = Eigen::Vector2d(10.0 * t, 0.0);
  e.error = error;
  return e;
}

TEST(Evaluation, EstimatesAreInterpolatedToStampsBetweenTicksAndScoredWithTheirHeading) {
  const auto truth = truthEast(1.0);
  // Ticks at 50 Hz, 5 cm to the left and yawed 0.01 rad.
  std::vector<io::TrajectoryPoint> ticks;
  for (int k = 0; k <= 50; ++k) {
    io::TrajectoryPoint p;
    p.stamp = fromSeconds(0.02 * k);
    p.pose.position = Eigen::Vector3d(0.2 * k, 0.05, 0.0);
    p.pose.orientation = Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitZ());
    ticks.push_back(p);
  }
  const auto at = evaluateAt(ticks, {fromSeconds(0.31), fromSeconds(0.555), fromSeconds(2.0)}, truth, fromSeconds(0.2));
  ASSERT_EQ(at.size(), 2u);  // 2 s is past the estimates
  for (const ErrorSample& e : at) {
    EXPECT_NEAR(e.error, 0.05, 1e-9);   // midway between ticks the estimate moved on with them
    EXPECT_NEAR(e.across, 0.05, 1e-9);
    EXPECT_NEAR(e.heading_error, 0.01, 1e-9);
  }
}

TEST(Evaluation, InputComparisonJudgesAccuracyByStretchOfRoadNotByScan) {
  // 10 Hz input over 4 s (40 m): the first 20 m NDT errs 1 cm on average with one scan at 3 cm,
  // the last 20 m 5 cm. The fused output errs 0.8 cm everywhere, the settled estimate 0.6 cm.
  std::vector<ErrorSample> input, fused, settled;
  for (int k = 0; k < 40; ++k) {
    const double t = 0.1 * k;
    double e = k < 20 ? (k % 2 ? 0.005 : 0.015) : 0.05;
    if (k == 7) e = 0.03;
    input.push_back(sampleAt(t, e));
    input.back().heading_error = k % 2 ? 0.002 : 0.004;  // a 3 mrad mounting yaw, +-1 mrad of noise
    if (k != 39) fused.push_back(sampleAt(t, 0.008));  // one stamp without a fused estimate
    settled.push_back(sampleAt(t, 0.006));
  }
  const InputComparison c = compareWithInput(input, fused, settled, 10.0, 0.02);
  EXPECT_EQ(c.samples, 39u);
  EXPECT_NEAR(c.fused_mean, 0.008, 1e-12);
  // Stretches of 10 m: [0, 10) and [10, 20) are accurate; the scan at 3 cm stays in its stretch.
  EXPECT_EQ(c.accurate_samples, 20u);
  double in = 0.0;
  for (int k = 0; k < 20; ++k) in += input[k].error;
  EXPECT_NEAR(c.accurate_input_mean, in / 20.0, 1e-12);
  EXPECT_NEAR(c.accurate_fused_mean, 0.008, 1e-12);
  EXPECT_NEAR(c.accurate_settled_mean, 0.006, 1e-12);
  // Yaw about its mean: the mounting yaw is the pipeline's to learn, not noise.
  EXPECT_NEAR(c.yaw_mean, (20 * 0.004 + 19 * 0.002) / 39.0, 1e-12);
  EXPECT_NEAR(c.yaw_variance, 1e-6, 3e-8);
  double ms = 0.0;
  for (int k = 0; k < 39; ++k) ms += 0.5 * input[k].error * input[k].error;
  EXPECT_NEAR(c.mean_square_xy, ms / 39.0, 1e-15);
}

TEST(Evaluation, InputComparisonWithNothingInCommonIsEmpty) {
  const InputComparison c = compareWithInput({sampleAt(0.0, 0.01)}, {sampleAt(0.5, 0.01)}, {sampleAt(0.0, 0.01)}, 10.0, 0.02);
  EXPECT_EQ(c.samples, 0u);
  EXPECT_EQ(c.accurate_samples, 0u);
}

}  // namespace
}  // namespace coloc::replay
