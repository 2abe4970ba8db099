#include "speed_scale.hpp"

#include <cmath>

namespace coloc::pipeline {

void SpeedScaleEstimator::addTwist(Stamp stamp, double vx) { odometry_.add(stamp, std::abs(vx)); }

void SpeedScaleEstimator::addPose(Stamp stamp, const Eigen::Vector2d& position) {
  if (!config_.enabled || odometry_.empty() || !position.allFinite()) return;
  const double odometry = odometry_.at(stamp);
  if (!anchor_) {
    if (candidate_) {
      const double moved = (position - candidate_->first).norm(), claimed = odometry - candidate_->second;
      if (claimed >= 0.0 && std::abs(moved - claimed) <= config_.anchor_agreement) anchor_ = candidate_;
    }
    candidate_ = {position, odometry};
    if (!anchor_) return;
  }
  const double travelled = odometry - anchor_->second;
  if (travelled < config_.chord) {
    if (travelled < 0.0) anchor_ = {position, odometry};  // a pose older than the anchor: start again
    return;
  }
  const double chord = (position - anchor_->first).norm();
  anchor_ = {position, odometry};
  const double ratio = chord / travelled;
  if (!(std::abs(ratio - 1.0) <= 3.0 * config_.max_error)) return;  // a jump of NDT, not a scale
  // Forgetting by distance: a comparison made `memory` metres of travel ago weighs 1/e.
  const double keep = std::exp(-travelled / config_.memory);
  weighted_pose_ = keep * weighted_pose_ + chord;
  weighted_odometry_ = keep * weighted_odometry_ + travelled;
  compared_ += travelled;
  const double estimate = weighted_pose_ / weighted_odometry_;
  if (std::abs(estimate - 1.0) <= config_.max_error) estimate_ = estimate;
}

}  // namespace coloc::pipeline
