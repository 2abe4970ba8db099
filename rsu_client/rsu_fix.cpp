#include "coloc/rsu_client/rsu_fix.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>
#include <sstream>

namespace coloc::rsu_client {

const char* toString(FixRejection reason) {
  switch (reason) {
    case FixRejection::kNone: return "none";
    case FixRejection::kUnknownRsu: return "unknown_rsu";
    case FixRejection::kNonFinite: return "non_finite";
    case FixRejection::kOutOfCoverage: return "out_of_coverage";
    case FixRejection::kStale: return "stale";
    case FixRejection::kFromFuture: return "from_future";
    case FixRejection::kDuplicate: return "duplicate";
  }
  return "?";
}

FixChecker::FixChecker(RsuRegistry registry, FixCheckConfig config) : registry_(std::move(registry)), config_(config) {}

namespace {

// A fix as its RSU would have sent it with a true survey and clock: the RSU computed it through its
// surveyed pose (off by dx, dy, dyaw) and stamped it on its clock (off by clock_offset).
RsuFix corrected(const RsuFix& fix, const RsuInfo& rsu) {
  const RsuCalibrationEntry& c = *rsu.calibration;
  const Eigen::Vector2d local = Eigen::Vector2d(fix.x, fix.y) - rsu.position;
  const Eigen::Vector2d p = rsu.position - Eigen::Vector2d(c.dx, c.dy) + Eigen::Rotation2Dd(-c.dyaw) * local;
  RsuFix out = fix;
  out.x = p.x();
  out.y = p.y();
  if (out.yaw) *out.yaw -= c.dyaw;
  out.stamp = fix.stamp - fromSeconds(c.clock_offset);
  return out;
}

// A refusal: counted, and said with the fix and the reason.
FixVerdict rejected(const RsuFix& fix, FixRejection reason, const std::string& why, std::uint64_t& counter) {
  ++counter;
  FixVerdict v;
  v.rejection = reason;
  std::ostringstream out;
  out << "fix from '" << fix.rsu_id << "' stamped " << formatSeconds(fix.stamp) << " rejected (" << toString(reason) << "): " << why;
  v.detail = out.str();
  return v;
}

}  // namespace

FixVerdict FixChecker::check(const RsuFix& fix, Stamp now) {
  FixCounters& c = counters_[fix.rsu_id];
  ++c.received;
  auto reject = [&](FixRejection reason, const std::string& why, std::uint64_t& counter) { return rejected(fix, reason, why, counter); };
  const RsuInfo* rsu = registry_.find(fix.rsu_id);
  if (!rsu) return reject(FixRejection::kUnknownRsu, "no such RSU in the registry", c.unknown_rsu);
  if (!std::isfinite(fix.x) || !std::isfinite(fix.y) || (fix.yaw && !std::isfinite(*fix.yaw)))
    return reject(FixRejection::kNonFinite, "position or yaw is not finite", c.non_finite);
  return checkKnown(rsu->calibration ? corrected(fix, *rsu) : fix, now, *rsu, c);
}

FixVerdict FixChecker::checkKnown(const RsuFix& fix, Stamp now, const RsuInfo& known, FixCounters& c) {
  const RsuInfo* rsu = &known;
  auto reject = [&](FixRejection reason, const std::string& why, std::uint64_t& counter) { return rejected(fix, reason, why, counter); };
  FixVerdict v;
  const double distance = (Eigen::Vector2d(fix.x, fix.y) - rsu->position).norm();
  if (distance > rsu->coverage_radius) {
    std::ostringstream why;
    why << "the fix lies " << distance << " m from the RSU, beyond its coverage of " << rsu->coverage_radius << " m";
    return reject(FixRejection::kOutOfCoverage, why.str(), c.out_of_coverage);
  }
  if (fix.stamp > now + fromSeconds(config_.future_tolerance))
    return reject(FixRejection::kFromFuture, "stamped " + formatSeconds(fix.stamp - now) + " s after its arrival", c.from_future);
  if (fix.stamp < now - fromSeconds(config_.max_age))
    return reject(FixRejection::kStale, formatSeconds(now - fix.stamp) + " s old (limit " + std::to_string(config_.max_age) + " s)", c.stale);
  std::deque<Stamp>& seen = recent_[fix.rsu_id];
  while (!seen.empty() && seen.front() < now - fromSeconds(config_.max_age)) seen.pop_front();
  if (std::find(seen.begin(), seen.end(), fix.stamp) != seen.end())
    return reject(FixRejection::kDuplicate, "a fix with this stamp was already received", c.duplicate);
  seen.push_back(fix.stamp);
  ++c.accepted;
  const double variance = registry_.variance(*rsu);
  v.measurement.stamp = fix.stamp;
  v.measurement.pose.position = {fix.x, fix.y, 0.0};
  v.measurement.covariance = Matrix6d::Zero();
  v.measurement.covariance.diagonal() << variance, variance, kInfinity, kInfinity, kInfinity, kInfinity;
  return v;
}

}  // namespace coloc::rsu_client
