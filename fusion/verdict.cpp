#include "coloc/fusion/verdict.hpp"

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

}  // namespace coloc::fusion
