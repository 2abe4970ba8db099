#pragma once
// Core value types shared by every module: poses, 6x6 covariances and the two measurement kinds the
// filter takes. Covariances follow ROS ordering: (x, y, z, roll, pitch, yaw) for poses and
// (vx, vy, vz, wx, wy, wz) for twists. A diagonal entry of +infinity means "not measured".
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <limits>

#include "coloc/core/time.hpp"

namespace coloc {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

constexpr double kInfinity = std::numeric_limits<double>::infinity();

/// A pose in a named frame: position and orientation.
struct Pose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
};

/// A pose observed by a sensor at its sensing time.
struct PoseMeasurement {
  Stamp stamp = 0;  ///< sensing time, not arrival time
  Pose pose;
  Matrix6d covariance = Matrix6d::Identity();  ///< over (x, y, z, roll, pitch, yaw); +inf = not measured
};

/// Body-frame velocity observed at its sensing time.
struct TwistMeasurement {
  Stamp stamp = 0;
  Eigen::Vector3d linear = Eigen::Vector3d::Zero();   ///< m/s
  Eigen::Vector3d angular = Eigen::Vector3d::Zero();  ///< rad/s
  Matrix6d covariance = Matrix6d::Identity();  ///< over (vx, vy, vz, wx, wy, wz); +inf = not measured
};

/// Roll, pitch, yaw (ZYX convention, as tf2 getRPY) of a rotation.
Eigen::Vector3d rollPitchYaw(const Eigen::Quaterniond& q);
Eigen::Quaterniond quaternionFromRollPitchYaw(double roll, double pitch, double yaw);

/// Angle wrapped to (-pi, pi].
double wrapAngle(double angle);

}  // namespace coloc
