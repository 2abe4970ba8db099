#include "fix_agreement.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "median.hpp"

namespace coloc::pipeline {

namespace {

Duration spanOf(const FixAgreementConfig& c) { return fromSeconds(2.0 * std::max(c.window, 0.0) + 1.0); }

}  // namespace

FixAgreement::FixAgreement(FixAgreementConfig config) : config_(config), distance_(spanOf(config)) {}

void FixAgreement::addSpeed(Stamp stamp, double speed) {
  if (config_.window > 0.0) distance_.add(stamp, speed);
}

void FixAgreement::addFix(Stamp stamp, const Eigen::Vector2d& position, double variance) {
  if (config_.window <= 0.0 || !position.allFinite()) return;
  if (!(std::isfinite(variance) && variance > 0.0)) variance = 0.0;
  // Fixes arrive in any order (each RSU's link its own delay): kept sorted by stamp.
  const auto at = std::upper_bound(fixes_.begin(), fixes_.end(), stamp, [](Stamp s, const Fix& f) { return s < f.stamp; });
  fixes_.insert(at, {stamp, position, variance});
  const Stamp keep = fixes_.back().stamp - 2 * fromSeconds(config_.window);
  while (!fixes_.empty() && fixes_.front().stamp < keep) fixes_.pop_front();
}

void FixAgreement::reset() {
  distance_ = OdometryIntegral(spanOf(config_));
  fixes_.clear();
}

std::optional<Eigen::Vector2d> FixAgreement::check(Stamp stamp, const Eigen::Vector2d& position, double yaw, double ndt_variance) {
  if (config_.window <= 0.0 || distance_.empty() || !position.allFinite() || !std::isfinite(yaw)) return std::nullopt;
  const Stamp window = fromSeconds(config_.window);
  const Eigen::Vector2d heading(std::cos(yaw), std::sin(yaw));
  const double here = distance_.at(stamp);
  std::vector<double> dx, dy, variances;
  for (const Fix& f : fixes_) {
    if (f.stamp < stamp - window || f.stamp > stamp + window) continue;
    variances.push_back(f.variance);
    // Where NDT's pose puts the vehicle at the fix's stamp: the odometry's distance along its heading.
    const Eigen::Vector2d ndt_then = position + (distance_.at(f.stamp) - here) * heading;
    dx.push_back(f.position.x() - ndt_then.x());
    dy.push_back(f.position.y() - ndt_then.y());
  }
  if (static_cast<int>(dx.size()) < std::max(1, config_.min_fixes)) return std::nullopt;
  const Eigen::Vector2d difference(median(dx), median(dy));
  const double norm = difference.norm();
  if (norm <= config_.tolerance) return Eigen::Vector2d::Zero().eval();
  double share = 1.0;
  const double fix_variance = median(variances);
  if (std::isfinite(ndt_variance) && ndt_variance > 0.0 && fix_variance > 0.0) share = ndt_variance / (ndt_variance + fix_variance);
  return (difference * (share * (norm - config_.tolerance) / norm)).eval();
}

}  // namespace coloc::pipeline
