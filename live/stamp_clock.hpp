#pragma once
// The node's time on the clock of the messages' header stamps. A node runs on the system clock or on
// /clock; a recording made with simulation time stamps its messages on the simulator's clock while a
// player's /clock is the recorder's wall clock (the nav2 recording: stamps near 924 s, /clock near
// 1.78e9 s). As `coloc fuse` does offline (replay.clock), such stamps are recognised and the node's time
// is moved onto their clock by the smallest delay seen: every message arrives after it was stamped, and
// the least-delayed one arrived the moment it was stamped. Over the recent inputs only, and only among
// delays near their median: one message stamped far off (a bad clock, a hostile sender) neither decides
// the mode nor moves the node's time.
#include <deque>
#include <mutex>

#include "coloc/core/time.hpp"
#include "coloc/pipeline/config.hpp"

namespace coloc::live {

class StampClock {
 public:
  /// `same_within`: offsets (arrival - stamp) from minus `tolerance` to this many seconds mean one clock (auto).
  StampClock(pipeline::ClockMode mode, double tolerance, double same_within = 10.0);

  /// A stamped input arrived at `arrival` (node time). False: it was sent before the clock's last
  /// jump back (see reset), and is not observed.
  bool observe(Stamp arrival, Stamp stamp);
  /// Node time on the stamps' clock. In auto mode, 0 until the first stamped input decides: the filter
  /// then sees its clock start rather than jump back.
  Stamp toStampClock(Stamp node_time) const;
  /// The node's clock went back from `from` to `to` (a log played again): the clocks are related
  /// afresh. Each topic has a reader of its own, so inputs sent before the jump can still arrive after
  /// /clock's: until the new relation has a few inputs of its own, an input whose stamp the old relation
  /// puts past the halfway point back to `from`, or whose arrival was read there, is one of them
  /// (stale), and must neither decide the new relation nor reach the filter.
  void reset(Stamp from, Stamp to);
  bool separate() const;
  /// Node time minus stamp time, when separate.
  Duration offset() const;

 private:
  pipeline::ClockMode mode_;
  Duration tolerance_, same_within_;
  mutable std::mutex mutex_;
  bool decided_ = false, separate_ = false, have_offset_ = false;
  Duration offset_ = 0;
  std::deque<Duration> recent_;  // the last delays (arrival - stamp)
  /// After a jump back: the halfway point (node time), and the old relation's offset (node - stamp).
  bool after_jump_ = false;
  Stamp halfway_ = 0;
  Duration old_offset_ = 0;
  int taken_since_jump_ = 0;
  void clear();
};

}  // namespace coloc::live
