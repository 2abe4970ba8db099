#include "speed_scale.hpp"

#include <cmath>

namespace coloc::pipeline {

void SpeedScaleEstimator::addTwist(Stamp stamp, double vx) { odometry_.add(stamp, std::abs(vx)); }

void SpeedScaleEstimator::addPose(Stamp stamp, const Eigen::Vector2d& position, double sd) {
  if (!config_.enabled || odometry_.empty() || !position.allFinite()) return;
  if (!(sd >= 0.0)) sd = 0.0;  // NaN: not stated
  const double odometry = odometry_.at(stamp);
  const Anchor here{position, odometry, sd};
  if (!anchor_) {
    if (candidate_) {
      const double moved = (position - candidate_->position).norm(), claimed = odometry - candidate_->odometry;
      if (claimed >= 0.0 && std::abs(moved - claimed) <= config_.anchor_agreement) anchor_ = candidate_;
    }
    candidate_ = here;
    if (!anchor_) return;
  }
  const double travelled = odometry - anchor_->odometry;
  if (travelled < config_.chord) {
    if (travelled < 0.0) anchor_ = here;  // a pose older than the anchor: start again
    return;
  }
  const double chord = (position - anchor_->position).norm();
  // The chord's weight: its two ends' stated variance, relative to a well-placed pair's.
  double weight = 1.0;
  if (config_.pose_sd_floor > 0.0) {
    const double floor = config_.pose_sd_floor * config_.pose_sd_floor;
    weight = 2.0 * floor / (2.0 * floor + anchor_->sd * anchor_->sd + sd * sd);
  }
  const double anchor_sd = anchor_->sd;
  anchor_ = here;
  const double ratio = chord / travelled;
  if (!(std::abs(ratio - 1.0) <= 3.0 * config_.max_error)) return;  // a jump of NDT, not a scale
  // Forgetting by distance: a comparison made `memory` metres of travel ago weighs 1/e.
  const double keep = std::exp(-travelled / config_.memory);
  weighted_pose_ = keep * weighted_pose_ + weight * chord;
  weighted_odometry_ = keep * weighted_odometry_ + weight * travelled;
  const double floor = config_.pose_sd_floor * config_.pose_sd_floor;
  weighted_variance_ = keep * keep * weighted_variance_ + weight * weight * std::max(anchor_sd * anchor_sd + sd * sd, 2.0 * floor);
  compared_ += travelled;
  const double estimate = weighted_pose_ / weighted_odometry_;
  if (std::abs(estimate - 1.0) <= config_.max_error) estimate_ = estimate;
}

double SpeedScaleEstimator::scaleSd() const {
  if (!usable() || !(weighted_odometry_ > 0.0)) return config_.prior_sd;
  return std::sqrt(weighted_variance_) / weighted_odometry_;
}

}  // namespace coloc::pipeline
