#include "mount_yaw.hpp"

#include <cmath>

namespace coloc::pipeline {

void MountYawEstimator::addPose(const Eigen::Vector2d& position, double yaw) {
  if (!config_.enabled || !position.allFinite() || !std::isfinite(yaw)) return;
  if (!anchor_) {
    anchor_ = {position, yaw};
    return;
  }
  const Eigen::Vector2d chord = position - anchor_->first;
  const double length = chord.norm();
  if (length < config_.chord) return;
  // On a circular arc the chord runs along the mean of the end headings.
  const double heading = wrapAngle(anchor_->second + 0.5 * wrapAngle(yaw - anchor_->second));
  const double offset = wrapAngle(heading - std::atan2(chord.y(), chord.x()));
  anchor_ = {position, yaw};
  if (!(std::abs(offset) <= config_.max_yaw)) return;
  const double keep = std::exp(-length / config_.memory);
  weighted_offset_ = keep * weighted_offset_ + offset * length;
  weighted_length_ = keep * weighted_length_ + length;
  compared_ += length;
  estimate_ = weighted_offset_ / weighted_length_;
}

}  // namespace coloc::pipeline
