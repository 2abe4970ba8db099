#pragma once
// Small builders for the measurements tests feed the Localizer.
#include <cstring>

#include "coloc/core/types.hpp"
#include "coloc/fusion/localizer.hpp"

namespace coloc::testing {

constexpr Duration kTick = 20'000'000;  // 50 Hz
constexpr Stamp kStart = 1'700'000'000'000'000'000LL;

/// A planar pose: x, y, yaw measured with the given variances, z / roll / pitch not measured.
inline PoseMeasurement planarPose(Stamp stamp, double x, double y, double yaw, double var_xy = 0.0225,
                                  double var_yaw = 0.000625) {
  PoseMeasurement m;
  m.stamp = stamp;
  m.pose.position = {x, y, 0.0};
  m.pose.orientation = quaternionFromRollPitchYaw(0.0, 0.0, yaw);
  m.covariance = Matrix6d::Zero();
  m.covariance.diagonal() << var_xy, var_xy, kInfinity, kInfinity, kInfinity, var_yaw;
  return m;
}

/// An RSU-style fix: x and y only, every other component +inf.
inline PoseMeasurement fix2d(Stamp stamp, double x, double y, double var_xy) {
  PoseMeasurement m = planarPose(stamp, x, y, 0.0, var_xy, 1.0);
  m.covariance(5, 5) = kInfinity;
  return m;
}

inline TwistMeasurement twist(Stamp stamp, double vx, double wz, double var_vx = 0.04, double var_wz = 0.01) {
  TwistMeasurement m;
  m.stamp = stamp;
  m.linear = {vx, 0.0, 0.0};
  m.angular = {0.0, 0.0, wz};
  m.covariance = Matrix6d::Zero();
  m.covariance.diagonal() << var_vx, kInfinity, kInfinity, kInfinity, kInfinity, var_wz;
  return m;
}

/// The filter's full numeric state, for bit-for-bit comparisons.
struct Snapshot {
  Vector6d x;
  Matrix6d P;
  Matrix6d pose_covariance;
  Stamp stamp;
  bool operator==(const Snapshot& o) const {
    return stamp == o.stamp && std::memcmp(x.data(), o.x.data(), sizeof(double) * 6) == 0 &&
           std::memcmp(P.data(), o.P.data(), sizeof(double) * 36) == 0 &&
           std::memcmp(pose_covariance.data(), o.pose_covariance.data(), sizeof(double) * 36) == 0;
  }
};

inline Snapshot snapshot(fusion::Localizer& localizer) {
  const fusion::Estimate e = *localizer.estimate();
  return {e.state, e.state_covariance, e.pose_covariance, e.stamp};
}

}  // namespace coloc::testing
