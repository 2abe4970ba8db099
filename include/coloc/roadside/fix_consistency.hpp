#pragma once
// Consistency over frames, the roadside perception's last check before a fix is sent. The RSU keeps a
// track of the vehicle's last sent fix; a new fix must agree with it, carried forward by the velocity
// in the vehicle's CAM. A fix that jumps (the box on the wrong corner of a vehicle seen through too few
// points, part of a neighbour taken for it) disagrees and is refused, and so are its wrong successors,
// however well they agree among themselves. Without a track (the vehicle just came into view, or
// nothing was sent for a while) two consecutive frames that agree start one. A refused fix beats a
// wrong one.
#include <Eigen/Core>
#include <optional>

#include "coloc/core/time.hpp"

namespace coloc::roadside {

class FixConsistency {
 public:
  /// `gate`: m of disagreement allowed; `track_time`: s a sent fix keeps the track alive (the CAM's
  /// velocity carries it well for that long, in a bend too); `pair_gap`: s between two frames that may
  /// start a track.
  explicit FixConsistency(double gate = 0.3, double track_time = 0.5, double pair_gap = 0.25)
      : gate_(gate), track_time_(track_time), pair_gap_(pair_gap) {}

  /// Whether the candidate at `stamp` (velocity in m/s, map frame) may be sent: it agrees with the
  /// track, or, without one, with the previous candidate. A candidate that may be sent becomes the track.
  bool agrees(Stamp stamp, const Eigen::Vector2d& position, const Eigen::Vector2d& velocity);
  /// A frame without a candidate: it cannot pair with the next one.
  void miss() { previous_.reset(); }

 private:
  struct Candidate {
    Stamp stamp;
    Eigen::Vector2d position, velocity;
  };
  bool near(const Candidate& from, const Candidate& to, double max_dt) const;
  double gate_, track_time_, pair_gap_;
  std::optional<Candidate> track_, previous_;
};

}  // namespace coloc::roadside
