#include "coloc/fusion/verdict.hpp"

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
    case Reason::kNumerical: return "numerical";
  }
  return "?";
}

}  // namespace coloc::fusion
