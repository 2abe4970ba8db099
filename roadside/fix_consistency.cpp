#include "coloc/roadside/fix_consistency.hpp"

namespace coloc::roadside {

bool FixConsistency::near(const Candidate& from, const Candidate& to, double max_dt) const {
  const double dt = toSeconds(to.stamp - from.stamp);
  if (dt <= 0.0 || dt > max_dt) return false;
  // The mean of the two velocities: in a bend the heading turns between the frames.
  const Eigen::Vector2d predicted = from.position + 0.5 * (from.velocity + to.velocity) * dt;
  return (to.position - predicted).norm() <= gate_;
}

bool FixConsistency::agrees(Stamp stamp, const Eigen::Vector2d& position, const Eigen::Vector2d& velocity) {
  const Candidate candidate{stamp, position, velocity};
  const bool tracked = track_ && toSeconds(stamp - track_->stamp) <= track_time_;
  const bool ok = tracked ? near(*track_, candidate, track_time_) : previous_ && near(*previous_, candidate, pair_gap_);
  if (ok) track_ = candidate;
  previous_ = candidate;
  return ok;
}

}  // namespace coloc::roadside
