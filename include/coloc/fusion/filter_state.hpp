#pragma once
// What the filter knows at one tick: the EKF's 6-state Gaussian and, beside it, the separate 1-D
// filters for z, roll and pitch (Autoware keeps those outside the EKF so that a poor height or tilt
// never disturbs the planar estimate).
#include <array>

#include "coloc/core/types.hpp"

namespace coloc::fusion {

/// A scalar random-walk Kalman filter; unset until its first measurement.
struct ScalarFilter {
  double value = 0.0;
  double variance = kInfinity;
  bool initialized = false;
};

enum AuxIndex : int { kAuxZ = 0, kAuxRoll = 1, kAuxPitch = 2 };

/// States beside the six, kept as one block of their own so that a filter without them runs
/// Autoware's 6-state arithmetic untouched: the map-matching bias (x, y in the map frame;
/// EkfConfig::map_match_bias_sd) that the poses of a source that is not an anchor carry, and the
/// odometry's slow errors (EkfConfig::odometry_scale_sd, odometry_yaw_rate_bias_sd): the share by which
/// the twist's speed reads high (it measures (1 + scale) vx) and its gyro's bias (it measures wz + bias).
/// A part not modelled keeps zero variance and never moves.
struct ExtraStates {
  enum Index : int { kBiasX = 0, kBiasY = 1, kScale = 2, kGyroBias = 3 };
  bool bias_modelled = false;
  bool odometry_modelled = false;
  bool any() const { return bias_modelled || odometry_modelled; }
  Eigen::Vector4d v = Eigen::Vector4d::Zero();
  Eigen::Matrix4d P = Eigen::Matrix4d::Zero();                              ///< their covariance
  Eigen::Matrix<double, 6, 4> cross = Eigen::Matrix<double, 6, 4>::Zero();  ///< the six states' covariance with them
  Eigen::Vector2d bias() const { return v.head<2>(); }
  Eigen::Matrix2d biasCovariance() const { return P.topLeftCorner<2, 2>(); }
};

struct FilterState {
  Vector6d x = Vector6d::Zero();  ///< [x, y, yaw, yaw_bias, vx, wz]
  Matrix6d P = Matrix6d::Identity();
  std::array<ScalarFilter, 3> aux{};  ///< z, roll, pitch
  ExtraStates extra;
};

}  // namespace coloc::fusion
