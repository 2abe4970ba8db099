#pragma once
// Offline fusion of a recorded log: decides which topics feed the filter, decodes them, measures each
// message's delay (receive time minus sensing time, on one clock), and replays them through a
// Localizer in arrival order, driving its clock with log time. What the filter held at each tick is
// what a vehicle would have had at that moment.
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "coloc/fusion/localizer.hpp"
#include "coloc/ndt/ndt_pose_source.hpp"
#include "coloc/io/trajectory_file.hpp"
#include "clock_fit.hpp"
#include "fuse_config.hpp"

namespace coloc::tools {

/// How one topic of the log was used.
struct TopicUse {
  std::string topic;
  std::string type;
  InputRole role = InputRole::kIgnore;
  std::string source;       ///< Localizer source name (pose / twist roles)
  bool from_config = false; ///< role set in the config rather than chosen by type
  std::string note;         ///< why a topic is skipped, or how its covariance was completed
  std::uint64_t messages = 0;
  std::uint64_t decode_errors = 0;
  std::uint64_t fallback_covariance = 0;  ///< messages that carried no covariance
  std::uint64_t link_dropped = 0;         ///< lost on the emulated link (inputs.TOPIC.link)
  std::string first_error;
  // Delay = arrival - stamp on the stamp clock, over the decoded messages.
  double delay_median = 0.0, delay_max = 0.0;  ///< s
};

struct ErrorSample {
  Stamp stamp;
  Eigen::Vector2d estimate, truth;
  double error;  ///< planar distance, m
};

struct ReplayResult {
  std::vector<TopicUse> topics;
  std::vector<fusion::SourceReport> sources;
  std::uint64_t unknown_source_inputs = 0;
  std::vector<io::TrajectoryPoint> fused;          ///< the estimate at every tick
  std::vector<io::TrajectoryPoint> pose_inputs;    ///< every decoded pose measurement, for plots
  std::vector<io::TrajectoryPoint> ground_truth;
  std::vector<ErrorSample> errors;                 ///< at ticks with ground truth
  ClockMode clock = ClockMode::kAuto;              ///< the mode used (never kAuto)
  ClockFit clock_fit;                              ///< log time -> stamp clock, when the clocks are separate
  Stamp first_stamp = 0, last_stamp = 0;           ///< span of the replay on the stamp clock
  double log_duration = 0.0;                       ///< s of log time
  double wall_seconds = 0.0;                       ///< replay time, decoding included
  std::uint64_t messages_read = 0;
  std::vector<std::string> rejections;             ///< the first few rejection messages, for the summary
  bool ndt_used = false;
  ndt::NdtPoseSourceCounters ndt;                  ///< scan matching, when a map was given
  std::uint64_t scans_without_guess = 0;           ///< scans before the filter could predict their pose
  ndt::DynamicMapStats map;
};

struct ReplayOptions {
  FuseConfig config;
  std::string map;  ///< PCD file or folder of tiles; with it, PointCloud2 topics feed NDT
  std::function<void(double fraction)> progress;  ///< called now and then with 0..1
};

/// Throws coloc::Error if the log cannot be read at all; bad messages inside it are counted, not fatal.
ReplayResult replayLog(const std::string& log_path, const ReplayOptions& options);

}  // namespace coloc::tools
