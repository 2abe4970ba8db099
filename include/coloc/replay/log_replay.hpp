#pragma once
// Offline fusion of a recorded log through the vehicle pipeline, in stages a reader can follow:
//   1. topic plan   which topic feeds what (by the config, else by message type)      topic_plan.hpp
//   2. decode       every message of a used topic into a pipeline input
//   3. clock        arrival times on the stamp clock (fitted when the clocks differ)    clock_fit.hpp
//   4. link         topics replayed through an emulated radio link are delayed or lost
//   5. drive        the inputs pushed into a Pipeline in arrival order, its clock driven by log time
//   6. evaluation   the estimate at every tick against the log's ground truth          evaluation.hpp
// What the filter held at each tick is what a vehicle would have had at that moment, and the same
// log and config always give the same bytes.
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "coloc/fusion/localizer.hpp"
#include "coloc/io/trajectory_file.hpp"
#include "coloc/ndt/ndt_pose_source.hpp"
#include "coloc/pipeline/config.hpp"
#include "coloc/pipeline/pipeline.hpp"
#include "coloc/replay/clock_fit.hpp"
#include "coloc/replay/evaluation.hpp"
#include "coloc/replay/replay_cache.hpp"
#include "coloc/replay/topic_plan.hpp"
#include "coloc/rsu_client/rsu_registry.hpp"

namespace coloc::replay {

using pipeline::ClockMode;
using pipeline::InputRole;

struct ReplayResult {
  std::vector<TopicUse> topics;
  std::vector<fusion::SourceReport> sources;
  std::uint64_t unknown_source_inputs = 0;
  std::vector<io::TrajectoryPoint> fused;          ///< the estimate at every tick
  /// Beside fused: the standard deviations of x and y the estimate reported (its covariance as given
  /// out, the integrity's inflation included) and its localization state.
  std::vector<Eigen::Vector2d> fused_sd;
  std::vector<fusion::LocalizationState> fused_localization;
  /// The pipeline's report at the end: the localization state, how it started, recoveries, clock
  /// resets, and what the filter made of the fixes that passed the checks.
  pipeline::PipelineReport pipeline_report;
  std::vector<io::TrajectoryPoint> pose_inputs;    ///< every pose measurement fed (NDT, fixes, others), for plots
  std::vector<std::string> pose_input_sources;     ///< the source of each pose input
  std::vector<Eigen::Matrix2d> pose_input_covariances;  ///< the x/y covariance each pose input claimed (map frame)
  /// Each pose source's own measurements against ground truth at their stamps (NDT's per-scan error
  /// beside the fused error: a filter should never be worse than its best input).
  std::map<std::string, std::vector<ErrorSample>> input_errors;
  /// The fused output at the same stamps (interpolated between ticks), the filter's settled estimate
  /// for each of them (Pipeline::onPoseSettled), and the comparison of the three.
  std::map<std::string, std::vector<ErrorSample>> fused_at_inputs, settled_at_inputs;
  std::map<std::string, std::vector<io::TrajectoryPoint>> settled_poses;  ///< by source, as the pipeline gave them
  std::map<std::string, InputComparison> input_comparison;
  std::string input_reference;  ///< the reference drive's input_error.csv the comparison's places came from (replay.input_reference)
  std::vector<io::TrajectoryPoint> ground_truth;
  std::vector<ErrorSample> errors;                 ///< at ticks with ground truth
  ClockMode clock = ClockMode::kAuto;              ///< the mode used (never kAuto)
  ClockFit clock_fit;                              ///< log time -> stamp clock, when the clocks are separate
  Stamp first_stamp = 0, last_stamp = 0;           ///< span of the replay on the stamp clock
  double log_duration = 0.0;                       ///< s of log time
  double wall_seconds = 0.0;                       ///< replay time, decoding included
  std::uint64_t messages_read = 0;
  std::uint64_t inputs_after_until = 0;            ///< inputs not given to the filter: ReplayOptions::until
  /// Where NDT took the LiDAR to be on the vehicle (x, y, z, roll, pitch, yaw), and from what: the
  /// config's ndt.lidar_pose, the log's /tf_static, or the vehicle's origin and why (empty without scans).
  Vector6d lidar_pose = Vector6d::Zero();
  std::string lidar_pose_from;
  /// The log's files that were never closed, read up to their cut (ReplayOptions::recover).
  std::vector<io::RecoveredFile> recovered;
  std::vector<std::string> rejections;             ///< the first few rejection messages, for the summary
  bool ndt_used = false;
  ndt::NdtPoseSourceCounters ndt;                  ///< scan matching, when a map was given
  std::uint64_t scans_without_guess = 0;           ///< scans before the filter could predict their pose
  ndt::DynamicMapStats map;
  std::map<std::string, rsu_client::FixCounters> fixes;  ///< roadside fixes per RSU, when a registry was given
  /// With ReplayOptions::keep_filter_inputs: every pose and twist as the filter got them (after NDT,
  /// the fix checks and the speed scale), and the filter's state at every tick, for a smoother.
  std::vector<std::pair<std::string, PoseMeasurement>> filter_poses;
  /// The same poses as the filter weighed them (Pipeline::onPoseWeighed): NDT's at its noise where the
  /// filter models or follows its bias, where filter_poses has them on their own.
  std::vector<std::pair<std::string, PoseMeasurement>> weighed_poses;
  std::vector<std::pair<std::string, TwistMeasurement>> filter_twists;
  std::vector<std::pair<std::string, TwistMeasurement>> received_twists;  ///< the same twists as the log has them
  std::vector<std::pair<Stamp, Vector6d>> fused_states;
  std::vector<Matrix6d> fused_state_covariances;  ///< beside fused_states

  /// Everything that follows from the log and the config, as JSON (summary.json of `coloc fuse`): the
  /// same log and config give the same bytes. `log` is the name to print for the recording.
  std::string summaryJson(const std::string& log) const;
  /// error.csv: the planar error at every tick with ground truth, split along and across the heading,
  /// with the standard deviations of x and y the filter reported then and its localization state.
  void writeErrorCsv(const std::string& path) const;
  /// input_error.csv: every pose input's error against ground truth at its stamp, by source.
  void writeInputErrorCsv(const std::string& path) const;
  /// The x/y covariance each pose input claimed, by source and stamp (the first at a stamp).
  std::map<std::pair<std::string, Stamp>, Eigen::Matrix2d> claimedCovariances() const;
  ErrorStats errorStats() const { return replay::errorStats(errors); }
};

struct ReplayOptions {
  pipeline::Config config;
  std::string map;  ///< PCD file or folder of tiles; with it, PointCloud2 topics feed NDT
  /// The RSUs whose fixes are trusted; unset: the one config.rsu.registry names, if any.
  std::optional<rsu_client::RsuRegistry> registry;
  std::function<void(double fraction)> progress;  ///< called now and then with 0..1
  bool keep_filter_inputs = false;  ///< fill filter_poses, filter_twists and fused_states
  /// Shared with other replays of the same log or map: read, decode and build once (same results).
  std::shared_ptr<ReplayCache> cache;
  /// Read a log that was never closed (an MCAP file without its footer) up to where it stops, instead
  /// of refusing it; ReplayResult::recovered says what was read.
  bool recover = false;
  /// Where the replay ends, on the stamp clock (0: at the log's end). Inputs that arrive later (after
  /// the emulated link's delay) are not given to the filter, so what it gave out up to then is what a
  /// replay of the whole log gives; what counts the log (messages read, link drops) covers all of it.
  /// For a run whose results all lie before some instant: the rest of the drive is not computed.
  Stamp until = 0;
};

/// Throws coloc::Error if the log cannot be read at all; bad messages inside it are counted, not fatal.
ReplayResult replayLog(const std::string& log_path, const ReplayOptions& options);

}  // namespace coloc::replay
