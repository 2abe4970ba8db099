#include "yaw_rate_bias.hpp"

#include <cmath>

#include "coloc/core/types.hpp"

namespace coloc::pipeline {

void YawRateBiasEstimator::addTwist(Stamp stamp, double wz) { odometry_.add(stamp, wz); }

void YawRateBiasEstimator::addPose(Stamp stamp, double yaw) {
  if (!config_.enabled || odometry_.empty() || !std::isfinite(yaw)) return;
  const double odometry = odometry_.at(stamp);
  if (!anchor_) {
    anchor_ = {stamp, {yaw, odometry}};
    return;
  }
  const double dt = toSeconds(stamp - anchor_->first);
  if (dt < config_.window) {
    if (dt < 0.0) anchor_ = {stamp, {yaw, odometry}};  // a pose older than the anchor: start again
    return;
  }
  // The odometry's heading change minus NDT's, wrapped: NDT's yaw wraps at +-pi, the integral does not.
  const double difference = wrapAngle((odometry - anchor_->second.second) - (yaw - anchor_->second.first));
  anchor_ = {stamp, {yaw, odometry}};
  if (!(std::abs(difference) <= config_.max_bias * dt)) return;
  const double keep = std::exp(-dt / config_.memory);
  weighted_difference_ = keep * weighted_difference_ + difference;
  weighted_time_ = keep * weighted_time_ + dt;
  compared_ += dt;
  estimate_ = weighted_difference_ / weighted_time_;
}

}  // namespace coloc::pipeline
