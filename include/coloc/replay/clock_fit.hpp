#pragma once
// Relating two clocks from the data alone. A log recorded with simulation time stamps its messages on
// the simulator's clock and logs them on the recorder's wall clock; the simulator may also run a
// little slower or faster than real time. Every message arrives after it was sensed, so the mapping
// from log time to the stamp clock is the line lying above all (log time, stamp) points that keeps the
// delays (line minus stamp) smallest in total: a supporting line of their upper convex hull, at the
// mean log time.
#include <vector>

#include "coloc/core/time.hpp"

namespace coloc::replay {

struct ClockFit {
  Stamp log_origin = 0;    ///< log time of the first point
  Stamp stamp_origin = 0;  ///< arrival (on the stamp clock) at log_origin
  double rate = 1.0;       ///< stamp-clock seconds per log-time second

  /// The log time `log_time` on the stamp clock.
  Stamp toStampClock(Stamp log_time) const;
};

struct ClockSample {
  Stamp log_time;
  Stamp stamp;
};

/// Needs at least one sample. A rate outside [0.5, 2] (a log too short or too odd to tell) falls back to
/// rate 1 with the smallest delay zero.
ClockFit fitClock(const std::vector<ClockSample>& samples);

}  // namespace coloc::replay
