#include "speed_scale.hpp"

#include <cmath>

namespace coloc::pipeline {

void SpeedScaleEstimator::addTwist(Stamp stamp, double vx) {
  if (!std::isfinite(vx)) return;
  if (!marks_.empty() && stamp <= marks_.back().stamp) return;  // out of order: the integral keeps its course
  const double distance =
      marks_.empty() ? 0.0 : marks_.back().distance + 0.5 * (std::abs(vx) + std::abs(marks_.back().vx)) * toSeconds(stamp - marks_.back().stamp);
  marks_.push_back({stamp, vx, distance});
  while (marks_.size() > 2 && marks_.front().stamp < stamp - 2 * kNanosPerSecond) marks_.pop_front();
}

double SpeedScaleEstimator::odometryAt(Stamp stamp) const {
  auto after = marks_.begin();
  while (after != marks_.end() && after->stamp < stamp) ++after;
  if (after == marks_.begin()) return marks_.front().distance - std::abs(marks_.front().vx) * toSeconds(marks_.front().stamp - stamp);
  if (after == marks_.end()) return marks_.back().distance + std::abs(marks_.back().vx) * toSeconds(stamp - marks_.back().stamp);
  const auto before = after - 1;
  const double w = static_cast<double>(stamp - before->stamp) / static_cast<double>(after->stamp - before->stamp);
  return before->distance + w * (after->distance - before->distance);
}

void SpeedScaleEstimator::addPose(Stamp stamp, const Eigen::Vector2d& position) {
  if (!config_.enabled || marks_.empty() || !position.allFinite()) return;
  const double odometry = odometryAt(stamp);
  if (!anchor_) {
    anchor_ = {position, odometry};
    return;
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
