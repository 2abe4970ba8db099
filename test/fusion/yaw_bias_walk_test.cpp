// The yaw bias as a random walk (EkfConfig::yaw_bias_walk): NDT's heading is off the direction of
// motion by an angle that changes with the place, and a filter that takes NDT's yaw near its noise
// must let its yaw bias follow, or its predicted path turns aside between poses.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "coloc/core/error.hpp"
#include "coloc/fusion/localizer.hpp"
#include "measurements.hpp"

namespace coloc::fusion {
namespace {

using namespace coloc::testing;

constexpr double kSpeed = 10.0;          // m/s, straight east
constexpr double kStep = 0.005;          // rad: NDT's heading off the motion from 15 s on
constexpr double kNdtNoise = 0.003;      // m per axis
constexpr double kNdtYawNoise = 0.0003;  // rad
constexpr double kSpeedNoise = 0.05, kYawRateNoise = 0.005;

struct DriveOutcome {
  double bias_error = 0.0;     // rad: the yaw bias against -kStep, mean over 25-40 s
  double across_error = 0.0;   // m: the fused position's mean distance off the road, 25-40 s
};

DriveOutcome drive(const EkfConfig& config, std::uint32_t seed) {
  Localizer filter(config);
  const SourceId odom = filter.addTwistSource("odom");
  const SourceId ndt = filter.addPoseSource("ndt");
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> unit;
  DriveOutcome run;
  int samples = 0;
  const int ticks = 2000;  // 40 s at 50 Hz
  for (int k = 0; k <= ticks; ++k) {
    const Stamp t = kStart + k * kTick;
    const double x = kSpeed * toSeconds(k * kTick), offset = k >= 750 ? kStep : 0.0;
    if (k > 0) filter.advanceTo(t);
    const TwistMeasurement odometry = twist(t, kSpeed + kSpeedNoise * unit(rng), kYawRateNoise * unit(rng), kSpeedNoise * kSpeedNoise, kYawRateNoise * kYawRateNoise);
    if (k % 5 == 0) {
      const PoseMeasurement pose = planarPose(t, x + kNdtNoise * unit(rng), kNdtNoise * unit(rng), offset + kNdtYawNoise * unit(rng), kNdtNoise * kNdtNoise,
                                              kNdtYawNoise * kNdtYawNoise);
      if (k == 0) {
        EXPECT_TRUE(filter.initialize(pose, odometry).applied());
        continue;
      }
      filter.feedPose(ndt, pose);
    }
    filter.feedTwist(odom, odometry);
    if (k >= 1250) {
      const Estimate e = *filter.estimate();
      run.bias_error += std::abs(e.yaw_bias + kStep);
      run.across_error += std::abs(e.pose.position.y());
      ++samples;
    }
  }
  run.bias_error /= samples;
  run.across_error /= samples;
  return run;
}

EkfConfig honest() {
  EkfConfig c;
  c.pose_smoothing_steps = 1;
  c.twist_smoothing_steps = 1;
  c.pose_gate_alpha = 0.0;
  return c;
}

TEST(YawBiasWalk, TheYawBiasFollowsNdtsHeadingOffsetWhereItStepsAndTheConstantOneLags) {
  for (std::uint32_t seed = 1; seed <= 3; ++seed) {
    EkfConfig walking = honest();
    walking.yaw_bias_walk = 0.002;
    const DriveOutcome constant = drive(honest(), seed), walked = drive(walking, seed);
    // 10-25 s after the step: the walk's bias within a milliradian of it, the constant one's off by more.
    EXPECT_LT(walked.bias_error, 0.001) << seed;
    EXPECT_GT(constant.bias_error, 2.0 * walked.bias_error) << seed;
    EXPECT_LT(walked.across_error, constant.across_error) << seed;
  }
}

TEST(YawBiasWalk, WithoutYawBiasEstimationTheWalkChangesNothing) {
  EkfConfig off = honest();
  off.enable_yaw_bias_estimation = false;
  EkfConfig off_walking = off;
  off_walking.yaw_bias_walk = 0.002;
  const DriveOutcome a = drive(off, 4), b = drive(off_walking, 4);
  EXPECT_EQ(a.across_error, b.across_error);
  EXPECT_EQ(a.bias_error, b.bias_error);
}

TEST(YawBiasWalk, ANegativeOrNonFiniteWalkIsRefusedNamingIt) {
  for (const double walk : {-0.001, std::nan(""), std::numeric_limits<double>::infinity()}) {
    EkfConfig c;
    c.yaw_bias_walk = walk;
    try {
      Localizer filter(c);
      ADD_FAILURE() << walk << " taken";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("yaw_bias_walk"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace coloc::fusion
