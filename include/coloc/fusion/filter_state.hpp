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

/// The map-matching bias (EkfConfig::map_match_bias_sd): two more states beside the six, kept as
/// blocks of their own so that a filter without them runs Autoware's 6-state arithmetic untouched.
struct MapMatchBias {
  bool modelled = false;
  Eigen::Vector2d b = Eigen::Vector2d::Zero();       ///< m, map frame
  Eigen::Matrix2d P = Eigen::Matrix2d::Zero();       ///< its covariance
  Eigen::Matrix<double, 6, 2> cross = Eigen::Matrix<double, 6, 2>::Zero();  ///< the six states' covariance with it
};

struct FilterState {
  Vector6d x = Vector6d::Zero();  ///< [x, y, yaw, yaw_bias, vx, wz]
  Matrix6d P = Matrix6d::Identity();
  std::array<ScalarFilter, 3> aux{};  ///< z, roll, pitch
  MapMatchBias bias;
};

}  // namespace coloc::fusion
