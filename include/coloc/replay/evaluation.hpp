#pragma once
// Stage 6 of a replay: the estimate against ground truth, interpolated to the filter's ticks.
#include <optional>
#include <vector>

#include "coloc/core/types.hpp"
#include "coloc/io/trajectory_file.hpp"
#include "coloc/pipeline/ndt_quality_map.hpp"

namespace coloc::replay {

struct ErrorSample {
  Stamp stamp;
  Eigen::Vector2d estimate = Eigen::Vector2d::Zero(), truth = Eigen::Vector2d::Zero();
  double error;  ///< planar distance, m
  /// The error split along the true heading (+: the estimate is ahead) and across it (+: to the left), m.
  /// A time-reference error shows as an along-track bias in proportion to speed; a map that does not
  /// constrain a direction, as spread in that direction.
  double along = 0.0, across = 0.0;
  double heading_error = 0.0;  ///< rad, the estimate's yaw minus the true yaw, wrapped
  double truth_heading = 0.0;  ///< rad, the true yaw at the stamp (the direction "along" refers to)
};

/// The standard deviations an x/y covariance claims along a heading and across it; inf for both if an
/// axis is not measured (it leaks into every direction but the exact axes).
Eigen::Vector2d alongAcrossDeviation(const Eigen::Matrix2d& covariance, double heading);

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

/// The error of `estimates` (sorted by stamp, e.g. the filter's ticks) interpolated to each of
/// `stamps`, where both the estimates and ground truth bracket it within `max_gap`.
std::vector<ErrorSample> evaluateAt(const std::vector<io::TrajectoryPoint>& estimates, const std::vector<Stamp>& stamps,
                                    const std::vector<io::TrajectoryPoint>& truth, Duration max_gap);

/// A pose source beside the filter at the source's own stamps: is the filter ever worse than its
/// input? Two figures of the filter: its output as given out in real time at the stamp (which cannot
/// know that pose yet: a scan's pose comes a sweep and a match later), and its estimate for the stamp
/// once that pose is in ("settled": the same information the input has, and what came before it).
/// "Where accurate" is judged by stretches of road, not scan by scan: choosing scans by their own
/// error would favour the input by its luck on those scans.
struct InputComparison {
  std::size_t samples = 0;                ///< input poses with all three errors
  double input_mean = 0.0, fused_mean = 0.0, settled_mean = 0.0;  ///< m, planar, over those
  double stretch_length = 0.0;            ///< m of road per stretch
  double accurate_below = 0.0;            ///< m: a stretch where the input's mean error is below this is "accurate"
  std::size_t accurate_samples = 0;       ///< input poses in such stretches
  double accurate_input_mean = 0.0, accurate_fused_mean = 0.0, accurate_settled_mean = 0.0;  ///< m, over those
  /// The same where the source was accurate on a reference drive (AccuratePlaces, by true position;
  /// 0 when none was given).
  bool places_given = false;
  std::size_t place_samples = 0;
  double place_input_mean = 0.0, place_fused_mean = 0.0, place_settled_mean = 0.0;  ///< m
  /// The input's error per axis, what a reference drive measures for a source's fixed covariance: the
  /// mean square of x and y (m^2, pooled; biases included: a map's error is the source's error) and
  /// the variance of yaw about its mean (rad^2; the mean is the LiDAR's mounting yaw, which the
  /// pipeline learns and removes).
  double mean_square_xy = 0.0, yaw_variance = 0.0;
  double yaw_mean = 0.0;  ///< rad
};

/// NDT's error by place from its poses on a drive with ground truth (each at NDT's own position, as a
/// vehicle looks it up, with its x/y error): cells of `cell` m holding at least `min_poses` poses, and
/// elsewhere the drive's own mean square (x and y pooled). What ndt.quality_map reads.
pipeline::NdtQualityMap ndtQualityMap(const std::vector<ErrorSample>& ndt, double cell = 10.0, std::size_t min_poses = 5);

class AccuratePlaces;

/// The three pair by stamp (a stamp missing from any of them is left out). With `places`, the
/// place_* figures too.
InputComparison compareWithInput(const std::vector<ErrorSample>& input, const std::vector<ErrorSample>& fused_at_input,
                                 const std::vector<ErrorSample>& settled_at_input, double stretch_length, double accurate_below,
                                 const AccuratePlaces* places = nullptr);

}  // namespace coloc::replay
