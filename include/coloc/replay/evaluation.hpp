#pragma once
// Stage 6 of a replay: the estimate against ground truth, interpolated to the filter's ticks.
#include <optional>
#include <vector>

#include "coloc/core/types.hpp"
#include "coloc/io/trajectory_file.hpp"

namespace coloc::replay {

struct ErrorSample {
  Stamp stamp;
  Eigen::Vector2d estimate, truth;
  double error;  ///< planar distance, m
  /// The error split along the true heading (+: the estimate is ahead) and across it (+: to the left), m.
  /// A time-reference error shows as an along-track bias in proportion to speed; a map that does not
  /// constrain a direction, as spread in that direction.
  double along = 0.0, across = 0.0;
};

struct ErrorStats {
  double mean = 0.0, rmse = 0.0, max = 0.0;  ///< m, planar
  double along_mean = 0.0, across_mean = 0.0;  ///< m, signed: biases
};

struct TruthSample {
  Eigen::Vector2d position;
  double heading;  ///< rad, the true yaw
};

/// Linear interpolation of the planar ground truth at `t` (sorted by stamp), if samples bracket it
/// no further apart than `max_gap`.
std::optional<TruthSample> truthAt(const std::vector<io::TrajectoryPoint>& truth, Stamp t, Duration max_gap);

/// The error at every estimate that ground truth covers.
std::vector<ErrorSample> evaluate(const std::vector<io::TrajectoryPoint>& estimates, const std::vector<io::TrajectoryPoint>& truth,
                                  Duration max_gap);

ErrorStats errorStats(const std::vector<ErrorSample>& errors);

}  // namespace coloc::replay
