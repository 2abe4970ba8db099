#include "coloc/rsu_client/rsu_fix.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <sstream>

#include "coloc/core/principal_variances.hpp"
#include "coloc/core/utf8.hpp"

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
    case FixRejection::kWrongFrame: return "wrong_frame";
    case FixRejection::kBadCovariance: return "bad_covariance";
    case FixRejection::kBadStamp: return "bad_stamp";
    case FixRejection::kBadAddress: return "bad_address";
    case FixRejection::kAddressedToAnother: return "addressed_to_another";
    case FixRejection::kUnaddressed: return "unaddressed";
  }
  return "?";
}

std::vector<std::pair<const char*, std::uint64_t>> refusals(const FixCounters& c) {
  using R = FixRejection;
  return {{toString(R::kUnknownRsu), c.unknown_rsu},   {toString(R::kNonFinite), c.non_finite},     {toString(R::kOutOfCoverage), c.out_of_coverage},
          {toString(R::kStale), c.stale},              {toString(R::kFromFuture), c.from_future},   {toString(R::kDuplicate), c.duplicate},
          {toString(R::kWrongFrame), c.wrong_frame},   {toString(R::kBadCovariance), c.bad_covariance}, {toString(R::kBadStamp), c.bad_stamp},
          {toString(R::kBadAddress), c.bad_address},   {toString(R::kAddressedToAnother), c.addressed_to_another},
          {toString(R::kUnaddressed), c.unaddressed}};
}

std::optional<std::uint32_t> parseStationId(const std::string& text) {
  if (text.empty() || text.size() > 10) return std::nullopt;
  std::uint64_t value = 0;
  for (const char ch : text) {
    if (ch < '0' || ch > '9') return std::nullopt;
    value = value * 10 + static_cast<std::uint64_t>(ch - '0');
  }
  if (value > 0xFFFFFFFFull) return std::nullopt;
  return static_cast<std::uint32_t>(value);
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
  if (fix.sent)
    if (FixVerdict v = checkSent(fix, *rsu, c); !v.accepted()) return v;
  if (FixVerdict v = checkAddress(fix, c); !v.accepted()) return v;
  return checkKnown(rsu->calibration ? corrected(fix, *rsu) : fix, now, *rsu, c);
}

FixVerdict FixChecker::checkAddress(const RsuFix& fix, FixCounters& c) const {
  auto reject = [&](FixRejection reason, const std::string& why, std::uint64_t& counter) { return rejected(fix, reason, why, counter); };
  if (!fix.station_id) {
    if (config_.accept_unaddressed) return {};
    return reject(FixRejection::kUnaddressed,
                  "the fix names no vehicle; with more than one connected vehicle it may be another's (rsu.accept_unaddressed takes such fixes)",
                  c.unaddressed);
  }
  if (!config_.station_id)
    return reject(FixRejection::kAddressedToAnother,
                  "addressed to station " + std::to_string(*fix.station_id) + ", and this vehicle has no station id (rsu.station_id)",
                  c.addressed_to_another);
  if (*fix.station_id != *config_.station_id)
    return reject(FixRejection::kAddressedToAnother,
                  "addressed to station " + std::to_string(*fix.station_id) + ", this vehicle is " + std::to_string(*config_.station_id),
                  c.addressed_to_another);
  return {};
}

FixVerdict FixChecker::checkSent(const RsuFix& fix, const RsuInfo& rsu, FixCounters& c) const {
  const SentFields& sent = *fix.sent;
  auto reject = [&](FixRejection reason, const std::string& why, std::uint64_t& counter) { return rejected(fix, reason, why, counter); };
  if (sent.nanosec >= 1000000000u)
    return reject(FixRejection::kBadStamp, "header.stamp.nanosec " + std::to_string(sent.nanosec) + " is not below 1e9", c.bad_stamp);
  // The frame name is checked for shape before it is quoted: it may be anything a sender wrote.
  const std::string& frame = sent.frame_id;
  if (frame.size() > kMaxFrameIdBytes)
    return reject(FixRejection::kWrongFrame, "frame_id of " + std::to_string(frame.size()) + " bytes (at most " + std::to_string(kMaxFrameIdBytes) + ")",
                  c.wrong_frame);
  if (!isValidUtf8(frame.data(), frame.size()) || frame.find('\0') != std::string::npos)
    return reject(FixRejection::kWrongFrame, "frame_id is not UTF-8 text", c.wrong_frame);
  if (frame != registry_.mapFrame())
    return reject(FixRejection::kWrongFrame, "frame '" + frame + "', the registry's map frame is '" + registry_.mapFrame() + "'", c.wrong_frame);
  if (sent.child_frame_id) {
    const std::string& child = *sent.child_frame_id;
    if (!parseStationId(child) || !fix.station_id || *fix.station_id != *parseStationId(child)) {
      const bool printable = child.size() <= 16 && isValidUtf8(child.data(), child.size()) && child.find('\0') == std::string::npos;
      return reject(FixRejection::kBadAddress,
                    "child_frame_id " + (printable ? "'" + child + "'" : std::to_string(child.size()) + " bytes") +
                        " is not a station id (decimal, 0 to 4294967295)",
                    c.bad_address);
    }
  }
  // The covariance: each entry finite or +inf (+inf: not measured), the matrix symmetric with a
  // non-negative diagonal, and x and y measured, since a fix is nothing but x and y.
  const Matrix6d& m = sent.covariance;
  static const char* const kAxis[] = {"x", "y", "z", "roll", "pitch", "yaw"};
  auto entry = [&](int i, int j) { return std::string("covariance[") + kAxis[i] + "," + kAxis[j] + "]"; };
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      if (std::isnan(m(i, j)) || m(i, j) == -kInfinity)
        return reject(FixRejection::kBadCovariance, entry(i, j) + " is " + (std::isnan(m(i, j)) ? "NaN" : "-inf"), c.bad_covariance);
  for (int i = 0; i < 6; ++i)
    for (int j = i + 1; j < 6; ++j) {
      const double a = m(i, j), b = m(j, i);
      if (!(a == b || std::abs(a - b) <= 1e-9 * std::max({1.0, std::abs(a), std::abs(b)})))
        return reject(FixRejection::kBadCovariance, "not symmetric: " + entry(i, j) + " " + std::to_string(a) + ", " + entry(j, i) + " " + std::to_string(b),
                      c.bad_covariance);
    }
  for (int i = 0; i < 6; ++i)
    if (m(i, i) < 0.0) return reject(FixRejection::kBadCovariance, entry(i, i) + " is negative (" + std::to_string(m(i, i)) + ")", c.bad_covariance);
  for (int i = 0; i < 2; ++i)
    if (!std::isfinite(m(i, i)) || m(i, i) <= 0.0)
      return reject(FixRejection::kBadCovariance, entry(i, i) + (std::isfinite(m(i, i)) ? " is 0" : " is +inf (not measured)") + ": a fix must measure x and y",
                    c.bad_covariance);
  // The x/y block a covariance: its correlation within [-1, 1].
  if (m(0, 1) * m(0, 1) > m(0, 0) * m(1, 1) * (1.0 + 1e-9))
    return reject(FixRejection::kBadCovariance, "covariance[x,y] " + std::to_string(m(0, 1)) + " exceeds what the x and y variances allow", c.bad_covariance);
  // The variance the RSU sent against the registry's: an RSU may say a fix is less sure than its
  // LiDAR's figure (each fix's covariance from its own fit: a far car seen on one face), never surer;
  // one that claims more is misconfigured (another LiDAR model, another placement) and its fixes are
  // not trusted blindly. With a calibrated variance, the vehicle's own measurement of this RSU, the
  // figure is not held against the RSU: the calibration replaces it (checkKnown).
  if (!rsu.calibrated_variance) {
    const double expected = registry_.variance(rsu);
    for (int i = 0; i < 2; ++i)
      if (m(i, i) < expected * (1.0 - 1e-6)) {
        std::ostringstream why;
        why << entry(i, i) << " " << m(i, i) << " is below the registry's " << expected << " for its " << rsu.lidar.name << " ("
            << (registry_.placement() == CovariancePlacement::kPublished ? "published" : "standard_deviation")
            << " placement): an RSU may send a fix as less sure than its LiDAR's figure, never as surer";
        return reject(FixRejection::kBadCovariance, why.str(), c.bad_covariance);
      }
  }
  return {};
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
  // One RSU frame gives a fix per vehicle it sees, all with the frame's stamp: a duplicate is the same
  // stamp for the same vehicle.
  std::deque<Stamp>& seen = recent_[{fix.rsu_id, fix.station_id}];
  while (!seen.empty() && seen.front() < now - fromSeconds(config_.max_age)) seen.pop_front();
  if (std::find(seen.begin(), seen.end(), fix.stamp) != seen.end())
    return reject(FixRejection::kDuplicate, "a fix with this stamp was already received", c.duplicate);
  seen.push_back(fix.stamp);
  ++c.passed_checks;
  const Eigen::Matrix2d calibrated = registry_.covarianceAt(*rsu, Eigen::Vector2d(fix.x, fix.y));
  v.measurement.stamp = fix.stamp;
  v.measurement.pose.position = {fix.x, fix.y, 0.0};
  v.measurement.covariance = Matrix6d::Zero();
  v.measurement.covariance.diagonal() << 0.0, 0.0, kInfinity, kInfinity, kInfinity, kInfinity;
  v.measurement.covariance.topLeftCorner<2, 2>() = calibrated;
  // What the RSU sent of this fix (checked: at least the registry's figure). The vehicle's own
  // calibration of this RSU replaces that figure, the floor an RSU raises each principal variance of
  // its fit to; what a fix says beyond it (its own fit's doubt along a direction: a car far off, one
  // face seen) is this fix's and stays, at least what the calibration says along that direction.
  if (fix.sent) {
    const Eigen::Matrix2d sent = fix.sent->covariance.topLeftCorner<2, 2>();
    if (!rsu->calibrated_variance) {
      v.measurement.covariance.topLeftCorner<2, 2>() = sent;
    } else {
      const double figure = registry_.lidarVariance(*rsu) * (1.0 + 1e-6);
      if (rsu->calibrated_error_by_range.empty()) {
        const double variance = calibrated(0, 0);
        v.measurement.covariance.topLeftCorner<2, 2>() =
            mapPrincipalVariances(sent, [&](double sent_variance) { return sent_variance > figure ? std::max(sent_variance, variance) : variance; });
      } else if (const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> principal(sent); principal.eigenvalues().maxCoeff() > figure) {
        // One axis sent beyond the figure: it keeps that, at least the calibration's along it, and the
        // other takes the calibration's. Sent at the figure on both (the fit knew no more), the fix
        // keeps the calibration's covariance as set above: an isotropic matrix's axes are arbitrary.
        Eigen::Matrix2d taken = Eigen::Matrix2d::Zero();
        for (int i = 0; i < 2; ++i) {
          const Eigen::Vector2d axis = principal.eigenvectors().col(i);
          const double sent_variance = principal.eigenvalues()(i), calibration = axis.dot(calibrated * axis);
          taken += (sent_variance > figure ? std::max(sent_variance, calibration) : calibration) * axis * axis.transpose();
        }
        v.measurement.covariance.topLeftCorner<2, 2>() = taken;
      }
    }
  }
  return v;
}

}  // namespace coloc::rsu_client
