#pragma once
// The integral of an odometry rate (speed, yaw rate) over the last seconds, at any stamp: trapezoids
// between the twists, interpolated between them and extrapolated at the ends with the nearest rate.
// NDT's poses arrive a sweep and a match after their stamp, so the odometry they are compared with is
// taken at that stamp, not at the latest twist. Used by the online calibrations against NDT.
#include <deque>

#include "coloc/core/time.hpp"

namespace coloc::pipeline {

class OdometryIntegral {
 public:
  /// Keeps the rates of the last `span` (enough to reach a pose stamped a sweep and a match ago).
  explicit OdometryIntegral(Duration span = 2 * kNanosPerSecond) : span_(span) {}
  /// A rate at `stamp`. Non-finite rates and stamps not after the last are ignored: the integral keeps
  /// its course.
  void add(Stamp stamp, double rate);
  /// The integral at `stamp` (0 at the first rate kept). Call only when !empty().
  double at(Stamp stamp) const;
  bool empty() const { return marks_.empty(); }

 private:
  struct Mark {
    Stamp stamp;
    double rate, integral;
  };
  Duration span_;
  std::deque<Mark> marks_;
};

}  // namespace coloc::pipeline
