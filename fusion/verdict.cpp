#include "coloc/fusion/verdict.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace coloc::fusion {

const char* toString(Outcome outcome) {
  switch (outcome) {
    case Outcome::kApplied: return "applied";
    case Outcome::kPending: return "pending";
    case Outcome::kRejected: return "rejected";
  }
  return "?";
}

const char* toString(Reason reason) {
  switch (reason) {
    case Reason::kNone: return "none";
    case Reason::kNotInitialized: return "not_initialized";
    case Reason::kUnknownSource: return "unknown_source";
    case Reason::kInvalid: return "invalid";
    case Reason::kTooOld: return "too_old";
    case Reason::kFromFuture: return "from_future";
    case Reason::kGated: return "gated";
    case Reason::kClockBackwards: return "clock_backwards";
    case Reason::kClockJump: return "clock_jump";
    case Reason::kNumerical: return "numerical";
  }
  return "?";
}

const char* toString(InputKind kind) {
  switch (kind) {
    case InputKind::kPose: return "pose";
    case InputKind::kTwist: return "twist";
    case InputKind::kInitialPose: return "initial pose";
    case InputKind::kClock: return "clock";
  }
  return "?";
}

std::string Verdict::message() const {
  std::ostringstream out;
  out << toString(input);
  if (input == InputKind::kClock) {
    out << " at " << formatSeconds(stamp);
  } else {
    if (!source.empty()) out << " from '" << source << "'";
    out << " stamped " << formatSeconds(stamp);
  }
  out << " " << toString(outcome);
  if (outcome == Outcome::kRejected) out << " (" << toString(reason) << ")";
  if (outcome == Outcome::kApplied && ticks_back >= 0)
    out << " " << ticks_back << " ticks back (squared Mahalanobis distance " << mahalanobis_squared << ")";
  if (!detail.empty()) out << ": " << detail;
  return out.str();
}

const char* toString(NisComponent component) {
  switch (component) {
    case kNisAlong: return "along";
    case kNisAcross: return "across";
    case kNisYaw: return "yaw";
    case kNisSpeed: return "speed";
    case kNisYawRate: return "yaw_rate";
  }
  return "?";
}

std::pair<double, double> nisBand(std::uint64_t dof) {
  if (dof == 0) return {0.0, 0.0};
  // Wilson-Hilferty: (X/k)^(1/3) is nearly normal with mean 1 - 2/(9k) and variance 2/(9k); the
  // quantiles over k are within 1 % of the exact ones from k = 10 on.
  const double k = static_cast<double>(dof);
  const double v = 2.0 / (9.0 * k);
  const auto at = [&](double z) { return std::pow(std::max(0.0, 1.0 - v + z * std::sqrt(v)), 3.0); };
  return {at(-1.959964), at(1.959964)};
}

}  // namespace coloc::fusion
