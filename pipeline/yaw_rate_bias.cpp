#include "yaw_rate_bias.hpp"

#include <cmath>

#include "coloc/core/types.hpp"

namespace coloc::pipeline {

void YawRateBiasEstimator::addTwist(Stamp stamp, double wz) {
  if (!std::isfinite(wz)) return;
  if (!marks_.empty() && stamp <= marks_.back().stamp) return;  // out of order: the integral keeps its course
  const double yaw = marks_.empty() ? 0.0 : marks_.back().yaw + 0.5 * (wz + marks_.back().wz) * toSeconds(stamp - marks_.back().stamp);
  marks_.push_back({stamp, wz, yaw});
  // Poses arrive a sweep and a match after their stamp; keep enough to interpolate there.
  while (marks_.size() > 2 && marks_.front().stamp < stamp - 2 * kNanosPerSecond) marks_.pop_front();
}

double YawRateBiasEstimator::odometryAt(Stamp stamp) const {
  auto after = marks_.begin();
  while (after != marks_.end() && after->stamp < stamp) ++after;
  if (after == marks_.begin()) return marks_.front().yaw - marks_.front().wz * toSeconds(marks_.front().stamp - stamp);
  if (after == marks_.end()) return marks_.back().yaw + marks_.back().wz * toSeconds(stamp - marks_.back().stamp);
  const auto before = after - 1;
  const double w = static_cast<double>(stamp - before->stamp) / static_cast<double>(after->stamp - before->stamp);
  return before->yaw + w * (after->yaw - before->yaw);
}

void YawRateBiasEstimator::addPose(Stamp stamp, double yaw) {
  if (!config_.enabled || marks_.empty() || !std::isfinite(yaw)) return;
  const double odometry = odometryAt(stamp);
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
