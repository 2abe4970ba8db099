#pragma once
// What became of one input: applied, waiting for the filter's clock, or rejected for a named reason.
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>

#include "coloc/core/time.hpp"

namespace coloc::fusion {

enum class Outcome : std::uint8_t { kApplied, kPending, kRejected };

enum class Reason : std::uint8_t {
  kNone,
  kNotInitialized,   ///< no initial pose yet
  kUnknownSource,    ///< source name or id never registered
  kInvalid,          ///< non-finite value, bad covariance, nothing measured
  kTooOld,           ///< stamp older than the state history
  kFromFuture,       ///< stamp ahead of the caller's clock beyond the tolerance
  kGated,            ///< Mahalanobis gate refused it
  kClockBackwards,   ///< advanceTo with an earlier time than before
  kClockJump,        ///< advanceTo so far ahead that the prediction would need millions of ticks
  kNumerical,        ///< innovation covariance not positive definite
};

const char* toString(Outcome outcome);
const char* toString(Reason reason);

enum class InputKind : std::uint8_t { kPose, kTwist, kInitialPose, kClock };

const char* toString(InputKind kind);

struct Verdict {
  Outcome outcome = Outcome::kApplied;
  Reason reason = Reason::kNone;
  InputKind input = InputKind::kPose;
  std::string source;   ///< the source's name ("" for clock calls)
  Stamp stamp = 0;      ///< the input's stamp (the clock's new time for clock calls)
  int ticks_back = -1;  ///< tick the measurement was applied at, counted back from the newest
  double mahalanobis_squared = 0.0;  ///< of the first use, when gated or applied
  std::string detail;   ///< why it was rejected, or what else happened

  bool applied() const { return outcome == Outcome::kApplied; }
  bool rejected() const { return outcome == Outcome::kRejected; }
  /// One line for people: names the input, its stamp, the outcome and the reason. Built on demand so
  /// that the hot path never formats text.
  std::string message() const;
};

/// The components of SourceCounters::nis_component_sum: a pose's position along and across the
/// filter's yaw at its first use, and its yaw; a twist's speed and yaw rate.
enum NisComponent : int { kNisAlong = 0, kNisAcross = 1, kNisYaw = 2, kNisSpeed = 3, kNisYawRate = 4 };
inline constexpr std::size_t kNisComponents = 5;
const char* toString(NisComponent component);

/// Per-source tallies; every input lands in exactly one of the final counters or in `pending`.
struct SourceCounters {
  std::uint64_t received = 0;
  std::uint64_t applied = 0;
  std::uint64_t pending = 0;          ///< waiting for the filter's clock (not final)
  std::uint64_t gated = 0;
  std::uint64_t too_old = 0;
  std::uint64_t from_future = 0;
  std::uint64_t invalid = 0;
  std::uint64_t not_initialized = 0;
  std::uint64_t numerical = 0;
  /// Applied, but with fewer smoothing steps than configured because the history or the queue ran
  /// out; the measurement's full information still went in.
  std::uint64_t smoothing_shortened = 0;
  /// Applied although over the gate, at reduced weight, by gate recovery (pose_gate_recovery, twist_gate_recovery).
  std::uint64_t gate_recovered = 0;
  /// How well the source's covariance describes it: its normalized innovation squared
  /// d^2 = e' (H P H' + R)^-1 e at each first use (gated ones too), which a source and a filter whose
  /// covariances are honest give as chi-square with the measured dimensions' degrees of freedom.
  std::uint64_t nis_samples = 0;
  std::uint64_t nis_dof = 0;      ///< the samples' degrees of freedom summed
  double nis_sum = 0.0;           ///< their d^2 summed: nis_sum / nis_dof is 1 when honest
  std::uint64_t nis_above = 0;    ///< samples above their chi-square's 97.5 % quantile (2.5 % if honest)
  std::uint64_t nis_below = 0;    ///< samples below its 2.5 % quantile (2.5 % if honest)
  /// The same for each component alone, e_i^2 / S_ii (chi-square(1) when honest), summed over the
  /// samples that measured it (NisComponent): a whole figure near 1 can hide one component trusted
  /// too little and another too much, and a corridor's direction is along the road, not along x.
  std::array<double, kNisComponents> nis_component_sum{};
  std::array<std::uint64_t, kNisComponents> nis_component_samples{};
  /// Each component's share of S that is the filter's own prediction, (H P H')_ii / S_ii, summed over
  /// the same samples: near 1, the source's covariance hardly enters its NIS, which then says how
  /// honest the prediction is (the odometry's stated covariance, the process noise) more than the source.
  std::array<double, kNisComponents> nis_prediction_share_sum{};
};

/// The band the mean NIS per degree of freedom (nis_sum / nis_dof) lies in 95 % of the time when the
/// covariances are honest: the chi-square(dof) quantiles over dof (Wilson-Hilferty), {lower, upper}.
std::pair<double, double> nisBand(std::uint64_t dof);

}  // namespace coloc::fusion
