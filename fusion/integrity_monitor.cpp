#include "integrity_monitor.hpp"

#include <cmath>
#include <sstream>

namespace coloc::fusion {

const char* toString(LocalizationState state) {
  switch (state) {
    case LocalizationState::kInitialising: return "initialising";
    case LocalizationState::kLocalized: return "localized";
    case LocalizationState::kDegraded: return "degraded";
    case LocalizationState::kLost: return "lost";
  }
  return "?";
}

IntegrityMonitor::IntegrityMonitor(const EkfConfig& config) : config_(config) {}

void IntegrityMonitor::restart(Stamp stamp, bool initialized) {
  const std::uint64_t degradations = status_.degradations, losses = status_.losses;
  status_ = {};
  status_.state = initialized ? LocalizationState::kLocalized : LocalizationState::kInitialising;
  status_.since = stamp;
  status_.degradations = degradations;
  status_.losses = losses;
  cause_ = Cause::kNone;
  inflation_.setZero();
  anchor_gated_in_a_row_ = 0;
  anchor_window_.clear();
  last_applied_ = stamp;
}

void IntegrityMonitor::enter(LocalizationState state, Cause cause, std::string reason, Stamp now) {
  if (state != status_.state) {
    status_.since = now;
    if (state == LocalizationState::kDegraded) ++status_.degradations;
    if (state == LocalizationState::kLost) ++status_.losses;
  }
  status_.state = state;
  status_.reason = std::move(reason);
  cause_ = cause;
  if (state == LocalizationState::kLocalized) inflation_.setZero();
}

void IntegrityMonitor::onPose(const std::string& source, bool anchor, bool applied, const Eigen::Vector2d& innovation, double d2,
                              int gated_in_a_row, Stamp now) {
  if (status_.state == LocalizationState::kInitialising) return;
  const bool planar = innovation.allFinite();
  if (anchor && planar) {
    if (applied) {
      anchor_gated_in_a_row_ = 0;
      // An anchor that agrees again ends whatever its disagreement started; one that agrees well
      // (within chi-square(2)'s 0.99 quantile) confirms a doubted position.
      const bool confirms = d2 <= 9.21;
      if (confirms) status_.doubted = false;
      if (cause_ == Cause::kAnchor || (cause_ == Cause::kDoubt && confirms)) enter(LocalizationState::kLocalized, Cause::kNone, {}, now);
      onAnchorApplied(source, innovation, d2, now);
    } else {
      // Gated fixes that disagree by the same vector are one story told again: the filter is off by it.
      const bool same_story = anchor_gated_in_a_row_ > 0 && (innovation - anchor_disagreement_).norm() <= config_.integrity_anchor_agreement;
      anchor_gated_in_a_row_ = same_story ? anchor_gated_in_a_row_ + 1 : 1;
      anchor_disagreement_ = innovation;
      anchor_gated_at_ = now;
      inflation_ = innovation * innovation.transpose();
      std::ostringstream why;
      why.precision(3);
      const int lost_after = config_.integrity_lost_after_gated_anchors;
      if (lost_after > 0 && anchor_gated_in_a_row_ >= lost_after && innovation.norm() >= lostDistance()) {
        why << anchor_gated_in_a_row_ << " poses of " << source << " in a row disagree with the filter by " << innovation.norm()
            << " m (squared Mahalanobis distance " << d2 << ")";
        enter(LocalizationState::kLost, Cause::kAnchor, why.str(), now);
      } else if (status_.state != LocalizationState::kLost) {
        why << "a pose of " << source << " disagrees with the filter by " << innovation.norm() << " m (squared Mahalanobis distance " << d2 << ")";
        enter(LocalizationState::kDegraded, Cause::kAnchor, why.str(), now);
      }
    }
    if (applied) last_applied_ = now;
    return;
  }
  if (applied) {
    last_applied_ = now;
    if (cause_ == Cause::kDeadReckoning || (cause_ == Cause::kGated && gated_source_ == source))
      enter(LocalizationState::kLocalized, Cause::kNone, {}, now);
    // One anchor's disagreement, not repeated while the other sources went on agreeing, was the anchor's.
    if (cause_ == Cause::kAnchor && status_.state == LocalizationState::kDegraded &&
        now - anchor_gated_at_ >= fromSeconds(config_.integrity_anchor_memory)) {
      anchor_gated_in_a_row_ = 0;
      enter(LocalizationState::kLocalized, Cause::kNone, {}, now);
    }
    return;
  }
  const int limit = config_.integrity_degraded_after_gated;
  if (limit > 0 && gated_in_a_row >= limit && status_.state == LocalizationState::kLocalized) {
    std::ostringstream why;
    why.precision(3);
    why << gated_in_a_row << " poses of " << source << " in a row gated (squared Mahalanobis distance " << d2 << ")";
    gated_source_ = source;
    enter(LocalizationState::kDegraded, Cause::kGated, why.str(), now);
  }
}

void IntegrityMonitor::onAnchorApplied(const std::string& source, const Eigen::Vector2d& innovation, double d2, Stamp now) {
  const std::size_t n = static_cast<std::size_t>(config_.integrity_anchor_window);
  if (n == 0) return;
  anchor_window_.push_back({now, innovation, d2});
  while (anchor_window_.size() > n || (!anchor_window_.empty() && anchor_window_.front().at < now - fromSeconds(2.0))) anchor_window_.pop_front();
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  double mean_d2 = 0.0;
  for (const AnchorUse& u : anchor_window_) mean += u.innovation / anchor_window_.size(), mean_d2 += u.d2 / anchor_window_.size();
  bool one_story = anchor_window_.size() == n;
  for (const AnchorUse& u : anchor_window_) one_story = one_story && (u.innovation - mean).norm() <= config_.integrity_anchor_agreement;
  if (!one_story || mean_d2 <= config_.integrity_anchor_mean_nis) {
    if (cause_ == Cause::kAnchorWindow) enter(LocalizationState::kLocalized, Cause::kNone, {}, now);
    return;
  }
  std::ostringstream why;
  why.precision(3);
  why << "the last " << n << " poses of " << source << " disagree with the filter by " << mean.norm() << " m on average (mean squared Mahalanobis distance "
      << mean_d2 << ")";
  if (mean.norm() >= lostDistance()) {
    anchor_window_.clear();
    enter(LocalizationState::kLost, Cause::kAnchor, why.str(), now);
  } else if (status_.state != LocalizationState::kLost) {
    enter(LocalizationState::kDegraded, Cause::kAnchorWindow, why.str(), now);
  }
  inflation_ = mean * mean.transpose();
}

void IntegrityMonitor::doubt(const std::string& reason, const Eigen::Vector2d& offset, Stamp now) {
  if (offset.allFinite()) doubt(reason, Eigen::Matrix2d(offset * offset.transpose()), now);
}

void IntegrityMonitor::doubt(const std::string& reason, const Eigen::Matrix2d& spread, Stamp now) {
  if (status_.state == LocalizationState::kInitialising || status_.state == LocalizationState::kLost || !spread.allFinite()) return;
  enter(LocalizationState::kDegraded, Cause::kDoubt, reason, now);
  status_.doubted = true;
  inflation_ = spread;
}

void IntegrityMonitor::confirm(Stamp now) {
  if (cause_ != Cause::kDoubt) return;
  status_.doubted = false;
  enter(LocalizationState::kLocalized, Cause::kNone, {}, now);
}

void IntegrityMonitor::onTick(Stamp now) {
  if (status_.state != LocalizationState::kLocalized || config_.integrity_dead_reckoning_limit <= 0.0) return;
  const Duration without = now - last_applied_;
  if (without > fromSeconds(config_.integrity_dead_reckoning_limit))
    enter(LocalizationState::kDegraded, Cause::kDeadReckoning, "no pose applied for " + formatSeconds(without) + " s", now);
}

}  // namespace coloc::fusion
