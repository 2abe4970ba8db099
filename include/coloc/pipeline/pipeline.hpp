#pragma once
// The vehicle loop, as one object a vehicle stack links: scans go to NDT with the filter's prediction
// for their stamp as the initial guess, roadside fixes pass the registry's checks, twists and other
// poses go straight in, and the estimate comes out at every filter tick.
//
// Inputs may be pushed from any thread (DDS or driver callbacks): they only enter a thread-safe inbox,
// as Autoware's EKF node only queues what its callbacks receive. The inbox is drained in arrival order
// at the filter's ticks, either by `runUntil` on the caller's clock (offline: log time, so that a run
// repeats exactly) or by the pipeline's own thread on the system clock (`start`, live). Live, NDT runs
// on a thread of its own so that ticks keep their pace; its pose enters the inbox when it is done and
// the filter compensates the matching time like any other delay.
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "coloc/core/types.hpp"
#include "coloc/fusion/localizer.hpp"
#include "coloc/ndt/ndt_pose_source.hpp"
#include "coloc/ndt/point_cloud.hpp"
#include "coloc/pipeline/config.hpp"
#include "coloc/rsu_client/rsu_fix.hpp"
#include "coloc/rsu_client/rsu_registry.hpp"

namespace coloc::pipeline {

struct PipelineOptions {
  /// The map NDT matches scans against; none: scans are counted and dropped.
  std::optional<ndt::TileMap> map;
  /// The RSUs whose fixes are accepted; none: fixes are counted as unknown_rsu.
  std::optional<rsu_client::RsuRegistry> registry;
  /// Live: NDT on its own thread (a scan that arrives while one is matched replaces the waiting one,
  /// counted). Offline: inline, so that the same log gives the same bytes.
  bool ndt_thread = false;
  /// Live: the clock the pipeline's thread runs on and NDT's results arrive by; unset: the system
  /// clock. A node on a recorded log's time (ROS 2's use_sim_time) gives the /clock it receives.
  std::function<Stamp()> clock;
  /// NDT targets shared with other pipelines on the same map (replays of one drive side by side).
  std::shared_ptr<ndt::TargetCache> targets;
  /// NDT's outcomes shared with other pipelines asked the same (replays of one log that differ only in
  /// their fixes): see ndt/alignment_memo.hpp. Used for scans pushed as shared pointers.
  std::shared_ptr<ndt::AlignmentMemo> alignments;
};

/// What the pipeline has done so far: per-source filter counters, NDT, fixes, rejections.
struct PipelineReport {
  std::vector<fusion::SourceReport> sources;
  std::uint64_t unknown_source_inputs = 0;
  std::uint64_t ticks = 0;                   ///< estimates given out
  bool ndt_used = false;
  ndt::NdtPoseSourceCounters ndt;
  ndt::DynamicMapStats map;
  std::uint64_t scans_without_guess = 0;     ///< before the filter could predict their pose
  std::uint64_t scans_without_map = 0;       ///< no map given
  std::uint64_t scans_superseded = 0;        ///< live: replaced by a newer scan while NDT was busy
  std::map<std::string, rsu_client::FixCounters> fixes;  ///< per RSU id: received, refused by the checks, passed
  /// Per RSU id, what the filter made of the fixes that passed the checks: applied, gated, not
  /// initialised (before the filter started), too old, ...
  std::map<std::string, fusion::SourceCounters> filter_of_fixes;
  /// Whether to believe the estimate (integrity.hpp), and why; while initialising, what it waits for.
  fusion::LocalizationState state = fusion::LocalizationState::kInitialising;
  std::string state_reason;
  std::string started_how;                   ///< how the filter last started ("initial pose", "position from ..., heading ...")
  std::uint64_t starts = 0;                  ///< starts without a loss before (initial poses, starts from the sources)
  std::uint64_t recoveries = 0;              ///< restarts of a lost filter from the sources that agree
  std::vector<std::string> recovery_reasons; ///< the first few
  std::uint64_t degradations = 0, losses = 0;
  std::uint64_t clock_resets = 0;            ///< the clock went back and the filter started again
  std::uint64_t start_checks = 0;            ///< poses given by hand held against the map (pipeline.start_check_radii)
  std::uint64_t inputs_dropped_by_reset = 0; ///< inputs that arrived before a jump back, dropped by it
  std::uint64_t events = 0;                  ///< starts, recoveries, state changes, clock resets
  std::vector<std::string> first_events;     ///< the first few, as one line each
  double speed_scale = 1.0;                  ///< true speed per odometry speed, as learned from NDT (1 until known)
  double speed_scale_distance = 0.0;         ///< m of travel compared so far
  double yaw_rate_bias = 0.0;                ///< rad/s, odometry minus true yaw rate, as learned from NDT (0 until known)
  double yaw_rate_bias_time = 0.0;           ///< s compared so far
  double mount_yaw = 0.0;                    ///< rad, NDT's heading minus the direction of travel (0 until known)
  double mount_yaw_distance = 0.0;           ///< m compared so far
  /// The filter's own estimate of the odometry's slow errors at its latest tick (fusion.odometry_scale_sd,
  /// odometry_yaw_rate_bias_sd; false and zero where not modelled): the share by which its speed reads
  /// high and its gyro's bias (rad/s), each with its sd.
  bool filter_odometry_modelled = false;
  double filter_odometry_scale_error = 0.0, filter_odometry_scale_sd = 0.0;
  double filter_yaw_rate_bias = 0.0, filter_yaw_rate_bias_sd = 0.0;
  /// NDT poses whose travel over pipeline.travel_check_window disagreed with the odometry's beyond the
  /// tolerance (their covariance widened by the excess), and the largest excess, m.
  std::uint64_t ndt_travel_disagreements = 0;
  double ndt_travel_max_excess = 0.0;
  std::uint64_t ndt_travel_unverified = 0;   ///< with no chord to compare yet, taken at travel_check_unverified_sd
  /// NDT poses whose turn disagreed with the yaw rate's beyond pipeline.travel_check_turn_tolerance
  /// (their yaw variance widened by the whole disagreement), and the largest such, rad.
  std::uint64_t ndt_turn_disagreements = 0;
  double ndt_turn_max_disagreement = 0.0;
  /// NDT poses the roadside's fixes disagreed with beyond pipeline.fix_agreement_tolerance (their
  /// covariance widened by the excess), and the largest excess, m.
  std::uint64_t ndt_fix_disagreements = 0;
  double ndt_fix_max_excess = 0.0;
  /// NDT poses whose x/y variance ndt.quality_map raised to their place's figure.
  std::uint64_t ndt_quality_raised = 0;
  /// NDT poses whose covariance was taken down to their place's error by direction (ndt.quality_floor: noise).
  std::uint64_t ndt_quality_lowered = 0;
  std::uint64_t rejections = 0;              ///< every refusal, of any kind
  std::vector<std::string> first_rejections; ///< the first few, as one line each
};

/// What an alignment asked of NDT gave (Pipeline::align).
struct AlignOutcome {
  bool success = false;   ///< NDT produced a pose
  bool reliable = false;  ///< its score (NVTL) passed ndt.nvtl_threshold
  PoseMeasurement pose;   ///< stamped with the scan's stamp
  double nvtl = 0.0;
  int starts = 0;         ///< starting poses tried
  std::string why;        ///< when it did not succeed
};

/// The name under which the filter counts NDT's poses.
inline constexpr const char* kNdtSource = "ndt";

class Pipeline {
 public:
  /// Throws coloc::Error naming the key for an invalid configuration.
  Pipeline(const Config& config, PipelineOptions options);
  ~Pipeline();
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  /// Registers an input source by name (a topic, say); call before feeding it. The RSUs of the
  /// registry and NDT ("ndt") are registered by the pipeline. Thread-safe.
  fusion::SourceId addPoseSource(const std::string& name);
  fusion::SourceId addTwistSource(const std::string& name);
  /// The filter's source of an RSU's fixes (its fix topic), if the registry has it.
  std::optional<fusion::SourceId> fixSource(const std::string& rsu_id) const;

  // Inputs, from any thread. `arrival` is when the input reached the vehicle, on the clock the
  // pipeline runs on (the system clock live, log time offline).
  void pushScan(ndt::PointCloud scan, Stamp stamp, Stamp arrival);
  /// A scan shared with others (a log held in memory): not copied.
  void pushScan(std::shared_ptr<const ndt::PointCloud> scan, Stamp stamp, Stamp arrival);
  void pushTwist(fusion::SourceId source, const TwistMeasurement& twist, Stamp arrival);
  void pushPose(fusion::SourceId source, const PoseMeasurement& pose, Stamp arrival);
  void pushFix(const rsu_client::RsuFix& fix, Stamp arrival);
  /// Starts (or restarts) the filter at this pose, in arrival order with the other inputs.
  void pushInitialPose(const PoseMeasurement& pose, Stamp arrival);

  // Outputs. Set them before the first input; they are called on the thread that drains the inbox.
  /// Every new estimate: each filter tick, and the first estimate after a pose starts the filter.
  void onEstimate(std::function<void(const fusion::Estimate&)> callback);
  /// Every pose measurement handed to the filter (NDT results, fixes, other sources), for plots, the
  /// smoother and NDT's own topic: each with the covariance it has on its own (where the filter models
  /// NDT's bias, NDT's pose at its place's whole error, not the noise the filter takes it at).
  void onPoseInput(std::function<void(const std::string& source, const PoseMeasurement&)> callback);
  /// The same poses as the filter weighs them: NDT's at what ndt.quality_map and the checks made of
  /// it for the filter (its noise where the bias is loose or followed), the others as onPoseInput's.
  void onPoseWeighed(std::function<void(const std::string& source, const PoseMeasurement&)> callback);
  /// For every pose the filter took, once its smoothing is over: the filter's estimate for the pose's
  /// stamp from everything stamped up to it (the same information the source's own pose has), for
  /// comparing the filter with each of its inputs.
  void onPoseSettled(std::function<void(const std::string& source, const fusion::Estimate& at_stamp)> callback);
  /// Every twist handed to the filter, as handed (its speed scaled by what NDT taught so far) and as
  /// received, for smoothers.
  void onTwistInput(std::function<void(const std::string& source, const TwistMeasurement& handed, const TwistMeasurement& received)> callback);
  /// Every rejection, as one line naming the input and the reason.
  void onRejection(std::function<void(const std::string& line)> callback);
  /// Starts, recoveries, changes of the localization state and clock resets, one line each.
  void onEvent(std::function<void(const std::string& line)> callback);

  /// Offline: processes every input that arrived by `now` in arrival order (ties in push order),
  /// running the filter's ticks up to each input's arrival, then up to `now`.
  void runUntil(Stamp now);

  /// Live: a thread that drains the inbox at the filter's rate on the system clock. `stop` drains
  /// what has arrived and joins the threads; the destructor stops too.
  void start();
  void stop();

  /// NDT's search around a pose (Autoware's ndt_align_srv, a start or restart from a rough pose):
  /// the newest scan matched from the pose turned by 0, +-15 and +-30 deg, then from rings of 1.5 and
  /// 3 m around the best, the best accepted match kept. Called from any thread; it takes turns with
  /// the NDT thread. Without a map or before any scan it says why.
  AlignOutcome align(const Pose& around);

  /// A snapshot; thread-safe.
  PipelineReport report() const;
  /// The newest estimate; thread-safe.
  std::optional<fusion::Estimate> estimate() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace coloc::pipeline
