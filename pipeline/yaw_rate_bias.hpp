#pragma once
// Online calibration of the odometry's yaw-rate bias against NDT. A gyro (or wheel-speed yaw rate)
// carries a bias of a few mrad/s that drifts slowly with temperature; the filter, as Autoware's, has no
// state for it and takes the yaw rate as unbiased, so once the odometry is trusted as much as its noise
// deserves, 0.002 rad/s turns the predicted heading 0.1 deg a second and the track drifts sideways
// between NDT poses. NDT's heading changes are free of it (a LiDAR mounting error cancels in the
// difference): the bias is the odometry's integrated yaw minus NDT's over windows of a few seconds,
// per second, with exponential forgetting so that it follows the drift.
#include <optional>

#include "coloc/core/time.hpp"
#include "odometry_integral.hpp"

namespace coloc::pipeline {

struct YawRateBiasConfig {
  bool enabled = true;
  double window = 2.0;    ///< s between the two poses of one comparison
  double memory = 60.0;   ///< s over which old comparisons fade to 1/e
  double min_time = 10.0; ///< s compared before the estimate is used
  double max_bias = 0.05; ///< rad/s; a window that says more is a jump of NDT, not a bias (refused)
};

class YawRateBiasEstimator {
 public:
  explicit YawRateBiasEstimator(YawRateBiasConfig config = {}) : config_(config) {}

  /// A yaw rate as measured: integrates the heading change the odometry claims.
  void addTwist(Stamp stamp, double wz);
  /// The heading of a pose of the anchoring source (NDT) that the filter accepted, rad.
  void addPose(Stamp stamp, double yaw);
  /// Measured minus true yaw rate, rad/s; 0 until enough time was compared.
  double bias() const { return usable() ? estimate_ : 0.0; }
  bool usable() const { return config_.enabled && compared_ >= config_.min_time; }
  double comparedTime() const { return compared_; }

 private:
  YawRateBiasConfig config_;
  OdometryIntegral odometry_;  ///< the odometry's heading
  std::optional<std::pair<Stamp, std::pair<double, double>>> anchor_;  ///< stamp, (NDT yaw, odometry yaw)
  double weighted_difference_ = 0.0, weighted_time_ = 0.0;             ///< forgetful sums
  double estimate_ = 0.0, compared_ = 0.0;
};

}  // namespace coloc::pipeline
