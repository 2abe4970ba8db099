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
};

struct ErrorStats {
  double mean = 0.0, rmse = 0.0, max = 0.0;  ///< m
};

/// Linear interpolation of the planar ground truth at `t` (sorted by stamp), if samples bracket it
/// no further apart than `max_gap`.
std::optional<Eigen::Vector2d> truthAt(const std::vector<io::TrajectoryPoint>& truth, Stamp t, Duration max_gap);

/// The error at every estimate that ground truth covers.
std::vector<ErrorSample> evaluate(const std::vector<io::TrajectoryPoint>& estimates, const std::vector<io::TrajectoryPoint>& truth,
                                  Duration max_gap);

ErrorStats errorStats(const std::vector<ErrorSample>& errors);

}  // namespace coloc::replay
