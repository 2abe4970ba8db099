#include "travel_check.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "median.hpp"

namespace coloc::pipeline {

namespace {

constexpr std::size_t kIntervals = 9;  // the poses' interval as the median of the last few

// The odometry kept: three of the longest window, and a second to spare.
Duration spanOf(const TravelCheckConfig& c) { return fromSeconds(3.0 * std::max({c.window, c.max_window, 0.0}) + 1.0); }

}  // namespace

TravelCheck::TravelCheck(TravelCheckConfig config) : config_(config), distance_(spanOf(config)), heading_(spanOf(config)) {}

Duration TravelCheck::window() const {
  const Duration configured = fromSeconds(config_.window);
  // Three intervals before the pace is believed; their lower median, so that one gap (a scan lost, a
  // stretch NDT refused) does not stretch the window.
  if (intervals_.size() < 3) return configured;
  std::vector<Duration> sorted(intervals_.begin(), intervals_.end());
  const auto mid = sorted.begin() + static_cast<std::ptrdiff_t>((sorted.size() - 1) / 2);
  std::nth_element(sorted.begin(), mid, sorted.end());
  const Duration two = 2 * *mid;
  return std::max(configured, std::min(two, fromSeconds(std::max(config_.max_window, config_.window))));
}

void TravelCheck::addSpeed(Stamp stamp, double speed) {
  if (config_.window > 0.0) distance_.add(stamp, speed);
}

void TravelCheck::addYawRate(Stamp stamp, double yaw_rate) {
  if (config_.window > 0.0) heading_.add(stamp, yaw_rate);
}

Eigen::Vector2d TravelCheck::odometryChord(Stamp from, Stamp to, double from_yaw, double to_yaw) const {
  if (heading_.empty()) {
    const double travelled = distance_.at(to) - distance_.at(from);
    // No yaw rate: an arc of constant curvature between NDT's two headings. Its chord lies along the
    // mean heading and is shorter than the arc by sin(h) / h, h half the turn.
    const double half_turn = 0.5 * std::remainder(to_yaw - from_yaw, 2.0 * M_PI);
    const double heading = from_yaw + half_turn;
    const double chord = std::abs(half_turn) < 1e-6 ? 1.0 : std::sin(half_turn) / half_turn;
    return chord * travelled * Eigen::Vector2d(std::cos(heading), std::sin(heading));
  }
  // The odometry's own path from the chord's start: into a corner the turn is not spread evenly over
  // the chord, and its mean heading is not the chord's direction. Its heading starts at NDT's and ends
  // at NDT's: the odometry's turn over the chord is corrected evenly in time to NDT's, which takes out
  // a gyro's bias (0.01 rad/s turns a 1 s chord at 8 m/s 4 cm aside) and keeps the turn's shape.
  constexpr int kSteps = 16;
  const double start = heading_.at(from);
  const double correction = std::remainder(to_yaw - from_yaw, 2.0 * M_PI) - (heading_.at(to) - start);
  Eigen::Vector2d path = Eigen::Vector2d::Zero();
  double s0 = distance_.at(from), h0 = start;
  for (int k = 1; k <= kSteps; ++k) {
    const Stamp b = from + (to - from) * k / kSteps;
    const double s1 = distance_.at(b), h1 = heading_.at(b);
    const double heading = from_yaw + 0.5 * (h0 + h1) - start + correction * (k - 0.5) / kSteps;
    path += (s1 - s0) * Eigen::Vector2d(std::cos(heading), std::sin(heading));
    s0 = s1, h0 = h1;
  }
  return path;
}

void TravelCheck::reset() {
  distance_ = OdometryIntegral(spanOf(config_));
  heading_ = OdometryIntegral(spanOf(config_));
  intervals_.clear();
  poses_.clear();
}

std::optional<Eigen::Vector2d> TravelCheck::check(Stamp stamp, const Eigen::Vector2d& position, double yaw) {
  turn_disagreement_ = 0.0;
  if (config_.window <= 0.0) return Eigen::Vector2d::Zero().eval();
  if (!position.allFinite() || !std::isfinite(yaw)) return std::nullopt;
  // Poses out of order (a late scan) are neither compared nor kept: chords run forward in time.
  if (!poses_.empty() && stamp <= poses_.back().stamp) return std::nullopt;
  if (!poses_.empty()) {
    intervals_.push_back(stamp - poses_.back().stamp);
    if (intervals_.size() > kIntervals) intervals_.pop_front();
  }
  const Duration window = this->window();
  while (!poses_.empty() && poses_.front().stamp < stamp - 2 * window) poses_.pop_front();
  // Every kept pose one to two windows old starts a chord; the median of their disagreements is
  // NDT's: a single bad match at either end of a chord does not make the other look bad.
  std::vector<double> dx, dy;
  std::vector<double> travels, turns, spans;
  const bool turning = config_.turn_tolerance > 0.0 && !heading_.empty();
  if (!distance_.empty()) {
    const double here = distance_.at(stamp);
    for (const Kept& from : poses_) {
      if (from.stamp > stamp - window) break;
      const double travelled = here - distance_.at(from.stamp);
      const Eigen::Vector2d difference = (position - from.position) - odometryChord(from.stamp, stamp, from.yaw, yaw);
      dx.push_back(difference.x());
      dy.push_back(difference.y());
      travels.push_back(std::abs(travelled));
      if (turning) {
        turns.push_back(std::remainder(yaw - from.yaw, 2.0 * M_PI) - (heading_.at(stamp) - heading_.at(from.stamp)));
        spans.push_back(toSeconds(stamp - from.stamp));
      }
    }
  }
  poses_.push_back({stamp, position, yaw});
  // One chord cannot tell which of its ends is wrong; of two, the one that agrees better is taken.
  if (dx.size() < 2) return std::nullopt;
  Eigen::Vector2d difference(median(dx), median(dy));
  if (dx.size() == 2) {
    const Eigen::Vector2d a(dx[0], dy[0]), b(dx[1], dy[1]);
    difference = a.norm() <= b.norm() ? a : b;
  }
  if (turning && !turns.empty()) {
    double turn = median(turns);
    if (turns.size() == 2) turn = std::abs(turns[0]) <= std::abs(turns[1]) ? turns[0] : turns[1];
    // Beyond the tolerance the whole turn is NDT's: a heading that steps where the map or the scene
    // does (site C's corner: 4-6 mrad for four scans) is off by all of it, and widened by the excess
    // alone its poses still stood 8-12 standard deviations off the filter's yaw.
    if (std::abs(turn) > config_.turn_tolerance + config_.turn_tolerance_per_second * median(spans)) turn_disagreement_ = std::abs(turn);
  }
  const double tolerance = config_.tolerance + config_.tolerance_per_metre * median(travels);
  const double norm = difference.norm();
  if (norm <= tolerance) return Eigen::Vector2d::Zero().eval();
  return (difference * ((norm - tolerance) / norm)).eval();
}

}  // namespace coloc::pipeline
