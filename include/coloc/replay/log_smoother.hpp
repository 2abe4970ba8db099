#pragma once
// A recorded log smoothed: replayed through the vehicle pipeline first (NDT from the filter's
// prediction, the fix checks, the speed scale: the smoother gets exactly what the filter got, and
// the filter's states as its first guess), then every pose and twist solved for at once by the Ceres
// smoother, and both trajectories scored against the log's ground truth.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "coloc/replay/log_replay.hpp"
#include "coloc/smoother/smoother.hpp"

namespace coloc::replay {

struct SmoothOptions {
  ReplayOptions replay;
  /// The smoother's settings, as `smootherOptionsFor` makes them from the configuration
  /// (replay.config), unless changed after.
  smoother::SmootherOptions smoother;
  /// Estimate each registered RSU's survey and clock offsets with the trajectory (its fixes must be
  /// anchored by NDT or another pose source).
  bool calibrate_rsus = false;
  /// Fixed-lag mode: a window of this many seconds slides behind the filter, `window_step` at a time,
  /// starting from the filter's state and covariance at its start, and gives the states of its newest
  /// step: what a vehicle running it behind the filter would have. 0: one batch over the whole log.
  double window = 0.0;
  double window_step = 0.5;
};

/// What the fixed-lag mode cost: how long each window took to solve (the latency it adds).
struct FixedLagReport {
  double window = 0.0, step = 0.0;
  int windows = 0;
  double mean_solve_seconds = 0.0, max_solve_seconds = 0.0;
};

/// The smoother's settings of a configuration: the filter's tick rate, process noise, yaw-bias prior
/// and gate's alpha (0, no gate, turns the robust loss off), and the smoother section's own.
smoother::SmootherOptions smootherOptionsFor(const pipeline::Config& config, bool calibrating_rsus = false);

struct SmoothResult {
  ReplayResult filter;                         ///< the replay, with the filter's own errors
  std::vector<io::TrajectoryPoint> smoothed;   ///< every state
  std::vector<smoother::SmoothedState> states;
  std::vector<ErrorSample> errors;             ///< the smoothed pose against ground truth
  smoother::SmootherSummary summary;
  double wall_seconds = 0.0;                   ///< the smoothing alone
  /// Per RSU id, with calibrate_rsus. Observable ones can go into the next drives' registry.
  std::map<std::string, smoother::RsuCalibration> calibrations;
  std::vector<smoother::OdometryCalibration> odometry;  ///< per twist source, when estimated
  std::optional<FixedLagReport> fixed_lag;     ///< in fixed-lag mode
  std::vector<ErrorSample> filter_errors_matched;  ///< the filter's errors at the stamps the smoother gave
  rsu_client::RsuRegistry registry;            ///< the registry used; `calibratedRegistry` adds the findings

  /// The registry with each observable calibration as the RSU's `calibration` entry, added to what it
  /// had (a previous calibration is composed with the new one).
  rsu_client::RsuRegistry calibratedRegistry() const;

  /// summary.json of `coloc smooth`: position_error as `coloc fuse` reports it, the filter's beside it,
  /// the solver's summary and what the robust loss down-weighted.
  std::string summaryJson(const std::string& log) const;
};

/// Throws coloc::Error if the log cannot be read or holds nothing to smooth.
SmoothResult smoothLog(const std::string& log_path, SmoothOptions options);

}  // namespace coloc::replay
