#pragma once
// A vehicle driving a curve at 50 Hz with on-time odometry: the common backdrop of the delay tests.
#include <gtest/gtest.h>

#include <cmath>

#include "coloc/fusion/localizer.hpp"
#include "measurements.hpp"

namespace coloc::testing {

struct Drive {
  double speed = 8.0;     ///< m/s
  double yaw_rate = 0.2;  ///< rad/s

  /// The true planar pose at tick k (the filter starts at tick 0 at the origin, heading 0.3 rad).
  Eigen::Vector3d truth(int k) const {
    const double t = k * toSeconds(kTick);
    const double yaw0 = 0.3;
    const double yaw = yaw0 + yaw_rate * t;
    const double r = speed / yaw_rate;
    return {r * (std::sin(yaw) - std::sin(yaw0)), -r * (std::cos(yaw) - std::cos(yaw0)), yaw};
  }
};

inline fusion::EkfConfig quietConfig() {
  fusion::EkfConfig c;
  c.auto_initialize = false;
  return c;
}

/// A Localizer with "ndt" and "rsu" pose sources and an "odom" twist source, initialised at tick 0.
inline fusion::Localizer startedLocalizer(const fusion::EkfConfig& config = quietConfig()) {
  fusion::Localizer localizer(config);
  localizer.addPoseSource("ndt");
  localizer.addPoseSource("rsu");
  localizer.addTwistSource("odom");
  localizer.initialize(planarPose(kStart, 0.0, 0.0, 0.3, 0.05, 0.001));
  return localizer;
}

/// Advances to tick k and feeds that tick's odometry on time (slightly off the truth, as real odometry).
inline void driveTick(fusion::Localizer& localizer, const Drive& drive, int k) {
  localizer.advanceTo(kStart + k * kTick);
  localizer.feedTwist("odom", twist(kStart + k * kTick, drive.speed * 1.01, drive.yaw_rate - 0.002));
}

/// A slightly wrong pose of tick k, as a scan matcher would produce.
inline PoseMeasurement ndtPoseAt(const Drive& drive, int k) {
  const Eigen::Vector3d p = drive.truth(k);
  return planarPose(kStart + k * kTick, p.x() + 0.05, p.y() - 0.04, p.z() + 0.004);
}

inline PoseMeasurement rsuFixAt(const Drive& drive, int k, double sigma = 0.00681) {
  const Eigen::Vector3d p = drive.truth(k);
  return fix2d(kStart + k * kTick, p.x() - 0.01, p.y() + 0.012, sigma);
}

inline void expectSameEstimate(fusion::Localizer& a, fusion::Localizer& b, double tolerance) {
  const fusion::Estimate ea = *a.estimate(), eb = *b.estimate();
  ASSERT_EQ(ea.stamp, eb.stamp);
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(ea.state[i], eb.state[i], tolerance) << "state " << i;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      EXPECT_NEAR(ea.state_covariance(i, j), eb.state_covariance(i, j), tolerance) << "P(" << i << "," << j << ")";
}

}  // namespace coloc::testing
