// The pipeline's other two calibrations against NDT: the odometry's yaw-rate bias and the LiDAR's
// mounting yaw.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "mount_yaw.hpp"
#include "yaw_rate_bias.hpp"

namespace coloc::pipeline {
namespace {

constexpr Stamp kStart = 1'700'000'000'000'000'000LL;

// A drive at 10 m/s on a circle of `curvature` (0: straight): a gyro at 50 Hz reading the true yaw rate
// plus `bias` and 5 mrad/s of noise, and NDT poses at 10 Hz (2 cm, 0.02 deg of noise, heading off by
// `mount` rad), each reaching the estimators 105 ms after its stamp.
struct Drive {
  YawRateBiasEstimator bias;
  MountYawEstimator mount;
};
Drive drive(double gyro_bias, double mount, double curvature, double seconds) {
  Drive d;
  std::mt19937 rng(5);
  std::normal_distribution<double> gyro_noise(0.0, 0.005), pose_noise(0.0, 0.02), yaw_noise(0.0, 0.02 * M_PI / 180.0);
  const double v = 10.0, rate = v * curvature;
  auto truth = [&](double t) {
    const double yaw = rate * t;
    const Eigen::Vector2d p = curvature == 0.0 ? Eigen::Vector2d(v * t, 0.0)
                                               : Eigen::Vector2d(std::sin(yaw) / curvature, (1.0 - std::cos(yaw)) / curvature);
    return std::make_pair(p, yaw);
  };
  for (int k = 0; k * 0.02 <= seconds; ++k) {
    const double t = k * 0.02;
    d.bias.addTwist(kStart + static_cast<Stamp>(t * 1e9), rate + gyro_bias + gyro_noise(rng));
    if (k % 5 == 0 && t >= 0.105) {
      const double taken = t - 0.105;
      auto [p, yaw] = truth(taken);
      p += Eigen::Vector2d(pose_noise(rng), pose_noise(rng));
      const double ndt_yaw = wrapAngle(yaw + mount + yaw_noise(rng));
      d.bias.addPose(kStart + static_cast<Stamp>(taken * 1e9), ndt_yaw);
      d.mount.addPose(p, ndt_yaw);
    }
  }
  return d;
}

TEST(YawRateBias, LearnsAGyroBiasOfTwoMilliradiansPerSecondToATenth) {
  const Drive d = drive(0.002, 0.0, 0.0, 30.0);
  ASSERT_TRUE(d.bias.usable());
  EXPECT_NEAR(d.bias.bias(), 0.002, 0.0002);
}

TEST(YawRateBias, AMountingYawAndABendDoNotLookLikeABias) {
  // Heading differences cancel the mounting yaw; a 100 m-radius circle wraps NDT's yaw past +-pi.
  EXPECT_NEAR(drive(0.0, 0.01, 0.0, 30.0).bias.bias(), 0.0, 0.0002);
  EXPECT_NEAR(drive(-0.003, 0.0, 0.01, 80.0).bias.bias(), -0.003, 0.0002);
}

TEST(YawRateBias, IsZeroUntilEnoughTimeWasCompared) {
  const Drive d = drive(0.002, 0.0, 0.0, 5.0);
  EXPECT_FALSE(d.bias.usable());
  EXPECT_EQ(d.bias.bias(), 0.0);
}

// Each 5 m chord of 2 cm poses gives the direction of travel to 0.3 deg; a minute of driving averages
// about a hundred of them (forgetting over 500 m) to 0.03 deg.
TEST(MountYaw, LearnsAThreeTenthsDegreeMountingYawToAFewHundredthsOfADegree) {
  EXPECT_TRUE(drive(0.0, 0.3 * M_PI / 180.0, 0.0, 1.0).mount.usable());  // after one chord
  const Drive d = drive(0.0, 0.3 * M_PI / 180.0, 0.0, 60.0);
  EXPECT_NEAR(d.mount.yaw() * 180.0 / M_PI, 0.3, 0.06);
}

TEST(MountYaw, OnABendTheChordIsTakenAlongTheMeanHeading) {
  // 50 m radius: each 5 m chord turns 5.7 deg; taken at an end's heading it would read 2.9 deg.
  EXPECT_NEAR(drive(0.0, -0.2 * M_PI / 180.0, 0.02, 60.0).mount.yaw() * 180.0 / M_PI, -0.2, 0.06);
}

TEST(MountYaw, AnNdtJumpOrAStandstillIsNotTakenForAMountingYaw) {
  MountYawEstimator e;
  e.addPose({0.0, 0.0}, 0.0);
  for (int i = 0; i < 100; ++i) e.addPose({0.0, 0.001 * i}, 0.0);  // standing: no chord completes
  EXPECT_FALSE(e.usable());
  e.addPose({5.0, 0.0}, 0.0);
  e.addPose({10.0, 1.0}, 0.0);  // an 11 deg chord: a jump, refused
  e.addPose({15.0, 1.0}, 0.0);
  EXPECT_NEAR(e.yaw(), 0.0, 1e-12);
  EXPECT_NEAR(e.comparedDistance(), 10.0, 1e-9);
}

}  // namespace
}  // namespace coloc::pipeline
