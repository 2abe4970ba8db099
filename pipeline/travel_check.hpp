#pragma once
// NDT's travel held against the odometry's. NDT's covariance from its score (its curvature at the
// optimum) describes how sharply the scan fits the map there, not whether the optimum is the right
// one: where the map no longer matches (a building torn down) or the scene repeats along the road,
// NDT can slide from scan to scan with a stated standard deviation of a centimetre, and a filter that
// trusts it follows, feeding NDT its own drifted guess (site B's twin drive with the Laplace
// covariance: 1.6 cm stated while NDT slid 1 m in 2 s). The odometry cannot tell where the vehicle
// is, but over a second it tells how far it went within a few centimetres. So each NDT pose's chord
// from each pose one to two windows earlier is compared with the odometry's distance over the same
// stamps, laid along the odometry's own path between NDT's headings at the chord's ends (taken as a
// straight line along the chord's mean heading, chords into site C's corners at 15 m/s disagreed by
// up to 0.7 m, and 39 of 268 poses were widened where 13 are now); the median difference's
// part beyond the tolerance is what NDT's pose is worth no better than. A pose with no chord to
// compare (the first second after a start) is unverified: one bad match there, taken at its own
// sharp covariance, would hold the filter where the next good ones are gated away.
#include <deque>
#include <optional>
#include <Eigen/Core>

#include "coloc/core/time.hpp"
#include "odometry_integral.hpp"

namespace coloc::pipeline {

struct TravelCheckConfig {
  double window = 0.5;           ///< s: chords start at poses one to two windows old; 0 = off
  double tolerance = 0.03;       ///< m of disagreement NDT's and the odometry's noise explain
  double tolerance_per_metre = 0.005;  ///< and this much per metre of travel (the speed scale as learned)
  /// s: the longest window the check widens to for a slow pose stream (see TravelCheck::window).
  double max_window = 5.0;
  /// rad: NDT's heading change over each chord is held against the yaw rate's turn (where there are
  /// yaw rates); their median disagreement, where it is beyond this and turn_tolerance_per_second of
  /// the chord's time, is turnDisagreement. 0 = the turn not checked.
  double turn_tolerance = 0.0;
  double turn_tolerance_per_second = 0.002;  ///< rad/s: a gyro's bias not yet learned
};

class TravelCheck {
 public:
  explicit TravelCheck(TravelCheckConfig config = {});

  /// The odometry's speed as the filter takes it (its learned scale applied), m/s.
  void addSpeed(Stamp stamp, double speed);
  /// Its yaw rate (its learned bias taken out), rad/s. Without any, the path between two poses is the
  /// arc of constant curvature between their headings.
  void addYawRate(Stamp stamp, double yaw_rate);
  /// An NDT pose: how far its travel is off the odometry's beyond the tolerance (zero when within
  /// it, or when the check is off); nullopt when there is not enough to compare with yet (fewer than
  /// two poses one to two windows old, no odometry) or the pose is not finite. The pose is kept as later chords' start.
  std::optional<Eigen::Vector2d> check(Stamp stamp, const Eigen::Vector2d& position, double yaw);
  /// The last check's turn: how far NDT's heading change was off the yaw rate's, where beyond the
  /// tolerance (rad, >= 0; 0 when within it, unchecked, or with nothing to compare). A scan matched
  /// decimetres off is turned too (site C's twin drive: 31 cm and 12 mrad at once, where NDT's yaw
  /// noise is 0.3 mrad), and the travel alone widens its x and y only.
  double turnDisagreement() const { return turn_disagreement_; }
  void reset();
  /// The window in use: the configured one, or two of the poses' median interval if that is longer
  /// (at most max_window). Chords start at poses one to two windows old, and a LiDAR slower than
  /// 4 Hz, or an NDT that cannot keep up and drops scans, has fewer than two poses there: every pose
  /// would stay unverified.
  Duration window() const;

 private:
  struct Kept {
    Stamp stamp;
    Eigen::Vector2d position;
    double yaw;
  };
  /// The odometry's displacement from `from` to `to`, map frame, its heading at `from` NDT's.
  Eigen::Vector2d odometryChord(Stamp from, Stamp to, double from_yaw, double to_yaw) const;

  TravelCheckConfig config_;
  OdometryIntegral distance_;
  OdometryIntegral heading_;  ///< the yaw rate's integral
  std::deque<Kept> poses_;
  std::deque<Duration> intervals_;  ///< between the last poses taken, newest last
  double turn_disagreement_ = 0.0;
};

}  // namespace coloc::pipeline
