#pragma once
// coloc's configuration file, one for every use (`coloc fuse`, `coloc localize`, a linked pipeline):
// the filter (`fusion:`), scan matching (`ndt:`), roadside fixes (`rsu:`), the pipeline itself
// (`pipeline:`), how messages become measurements (`messages:`), what each topic is for (`inputs:`),
// offline replay (`replay:`) and the live node's topics (`live:`). Every key has a default, so an
// empty file (or none) is a valid configuration; the defaults live here and nowhere else.
#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "coloc/core/types.hpp"
#include "coloc/fusion/ekf_config.hpp"
#include "coloc/ndt/ndt_pose_source.hpp"
#include "coloc/rsu_client/link_emulator.hpp"
#include "coloc/rsu_client/rsu_fix.hpp"

namespace coloc::pipeline {

/// kStaticTransforms: a tf2_msgs/TFMessage topic whose transforms place the LiDAR on the vehicle
/// (a log's /tf_static), read when ndt.lidar_pose is not given.
enum class InputRole { kPose, kTwist, kGroundTruth, kScan, kRsuFix, kStaticTransforms, kIgnore };
const char* toString(InputRole role);

/// How one topic is used. Topics not listed are chosen by message type (see docs/fuse.md).
struct InputConfig {
  InputRole role = InputRole::kIgnore;
  std::string source;                      ///< name in the Localizer; default: the topic
  std::optional<Vector6d> covariance_diagonal;  ///< replaces the message's covariance (not for rsu_fix: the registry decides)
  double additional_delay = 0.0;           ///< s; the data was sensed this much before its stamp
  /// Replays the topic through an emulated radio link (delay, jitter, loss), as experiments do.
  std::optional<rsu_client::LinkConfig> link;
};

enum class ClockMode { kAuto, kSame, kSeparate };

/// How decoded messages become measurements, live and offline alike.
struct MessageConfig {
  /// ROS drivers write 0 for components they do not estimate (AMCL's z, roll, pitch); read as +inf.
  bool zero_variance_is_unmeasured = true;
  /// Used when a message carries no covariance at all (PoseStamped, or all zeros): Autoware's NDT value.
  Vector6d fallback_pose_variance = (Vector6d() << 0.0225, 0.0225, 0.0225, 0.000625, 0.000625, 0.000625).finished();
  /// Autoware's twist standard deviations 0.2 m/s and 0.1 rad/s; vy, vz, wx, wy are not used.
  Vector6d fallback_twist_variance = (Vector6d() << 0.04, kInfinity, kInfinity, kInfinity, kInfinity, 0.01).finished();
};

struct ReplayConfig {
  /// Whether header stamps and log (receive) times are on one clock. `separate` (a log recorded with
  /// simulation time) measures each message's delay relative to the least-delayed message.
  ClockMode clock = ClockMode::kAuto;
  /// Ground truth further than this from an output tick is not interpolated across.
  double ground_truth_max_gap = 0.2;  ///< s
  /// Each pose input is compared with the fused estimate at its stamps, over all of them and over the
  /// stretches of road this long where the input's mean error is below `input_accurate_below`.
  double input_stretch_length = 10.0;  ///< m
  double input_accurate_below = 0.02;  ///< m
  /// An input_error.csv that `coloc fuse` wrote for a reference drive over the same roads (relative to
  /// the config file): each input is also compared where it was accurate on that drive (cells of
  /// input_stretch_length, by the same input_accurate_below), which carries no luck of this drive.
  /// Empty: not.
  std::string input_reference;
};

/// Scan matching of a PointCloud2 topic against a map (`--map`).
struct NdtSection {
  ndt::NdtPoseSourceConfig source;
  double map_tile_size = 20.0;  ///< m; a single-file map is cut into squares of this size
  /// Whether source.lidar_pose was given (ndt.lidar_pose). Not given, a replayed log's /tf_static
  /// places the LiDAR (`base_frame` to the scans' frame) when it has the transforms; otherwise, and
  /// live, the LiDAR is at the vehicle's origin.
  bool lidar_pose_given = false;
  std::string base_frame = "base_link";  ///< the vehicle's frame in /tf_static, whose pose the filter estimates
  /// NDT's mean square error by place (NdtQualityMap's file, relative to the config file); each NDT
  /// pose's x/y variance at least its cell's. Empty: none.
  std::string quality_map;
  /// Where the filter's map-matching bias is loose (fusion.map_match_bias_sd), each NDT pose is floored
  /// at the map's scan-to-scan noise along the vehicle and across it (the file's noise_along and
  /// noise_across, where it has them) instead of at its one figure per axis. Off by default: measured
  /// on the twin it makes NDT's innovations across the road honest but not yet along it
  /// (docs/filter.md, *The odometry's slow errors*).
  bool quality_noise_by_direction = false;
  /// What the quality map makes of an NDT pose where nothing tells NDT's bias apart: "error", at least
  /// its place's whole mean square error (the bias counted with every scan), or "noise", at least its
  /// place's scan-to-scan noise along the vehicle, across it and in yaw and at most its place's error
  /// along and across (the bias followed as NDT follows it, and counted nowhere; NDT's score claims
  /// decimetres where the scene holds it only loosely). "noise" does the same where the bias is loose.
  /// "error" by default: the experiment's figures were measured so (docs/filter.md, *NDT at its noise*).
  std::string quality_floor = "error";
};

/// Roadside fixes: which RSUs are trusted and how fresh a fix must be.
struct RsuSection {
  /// RSU registry file (relative paths from the configuration file's folder); none: fix topics are
  /// plain pose inputs offline and there is nothing to subscribe to live.
  std::string registry;
  rsu_client::FixCheckConfig checks;
  /// Ticks over which each fix is applied; 0: fusion.pose_smoothing_steps, as every other pose.
  /// Autoware spreads every pose over five ticks so that NDT's pose does not jump; a centimetre fix
  /// need not be, and applied whole its information is in the estimate four ticks sooner. On the twin
  /// that changed nothing beyond the trials' spread (docs/experiment.md, *Network*), so fixes stay as Autoware's poses.
  int smoothing_steps = 0;
  /// This vehicle's own length and width (m): each fix addressed to it is moved back by half what its
  /// CAM's rounding of them to cam_size_step (ETSI: 0.1 m) made the RSU place its box off, on the side
  /// and end the RSU sees (coloc/pipeline/cam_size_correction.hpp). 0: fixes taken as sent.
  double vehicle_length = 0.0;
  double vehicle_width = 0.0;
  double cam_size_step = 0.1;  ///< m
  /// What this vehicle's CAMs send as its length and width, where its V2X stack does not round to the
  /// nearest step (ETSI gives the unit, not the rounding); 0: the size rounded to the nearest step.
  double cam_length = 0.0, cam_width = 0.0;  ///< m
};

struct PipelineSection {
  /// Starts the filter here (x, y, z [m], yaw [rad]) at the first input, for runs whose only pose
  /// source is NDT, which needs a first guess.
  std::optional<Eigen::Vector4d> initial_pose;
  /// A pose given by hand (initial_pose, /initialpose) is held against the map at the next scan (and
  /// every start_check_interval until an RSU's fix agrees): NDT
  /// also starts from rings of these radii around it (8 directions each), and a match better by
  /// start_check_margin in NVTL more than 1 m away makes the filter degraded until an RSU agrees.
  /// Empty: no check.
  std::vector<double> start_check_radii = {2.0, 4.0, 6.0};  ///< m
  double start_check_margin = 0.05;                          ///< NVTL
  /// The check is made again this often until an RSU's fix agrees with the filter: where the scene
  /// cannot tell (a corridor) at the start, it may later.
  double start_check_interval = 2.0;                         ///< s
  /// ... for this long after the start: a wrong start shows within seconds, while over a whole drive
  /// without an RSU, places where another stretch of road matches better would be found by chance
  /// (site C, NDT only: one at 18 s, 3.8 m away, NVTL 2.84 against 2.59).
  double start_check_duration = 10.0;                        ///< s
  /// Learn the odometry's speed scale from NDT's poses and correct twists by it before the filter.
  bool speed_scale_estimation = true;
  double speed_scale_memory = 500.0;  ///< m of travel over which old comparisons fade
  /// The learned scale is used from one chord (5 m) on: measured on the twin, waiting for three chords
  /// (15 m) left the filter ahead of NDT over the first 15 m of every drive (config/scenarios/
  /// uncalibrated_start.yaml: 3.8 cm fused against NDT's 1.0; from 5 m: 2.7), while one chord's scale, 0.6 % off on average at 2 cm of
  /// NDT noise (1.25 % at worst in eight drives, test SpeedScale.*), is better than none against the
  /// 0.5-2 % of real tyres (every site and speed of the experiment: the fused error equal or lower).
  double speed_scale_min_distance = 5.0;  ///< m
  /// Each twist's speed variance also holds the learned scale's doubt, (scaleSd vx)^2: 2 % before the
  /// scale is usable (the first chord), the chords' figure after. Off: the twist's covariance as given,
  /// which says nothing of the wheel's scale (docs/filter.md, *NDT at its noise*).
  bool speed_scale_uncertainty = false;
  /// Learn the odometry's yaw-rate bias (gyro) from NDT's heading changes and remove it before the
  /// filter. Off by default: it finds the twin's 0.002 rad/s within 0.0003, but with Autoware's loose
  /// yaw-rate covariance the filter gains nothing, and on site B's bend the corrected heading tipped
  /// NDT into following its own initial guess (2 cm -> 44 cm; docs/experiment.md, "The filter against its best input").
  bool yaw_rate_bias_estimation = false;
  double yaw_rate_bias_memory = 60.0;  ///< s over which old comparisons fade
  /// Learn the LiDAR's mounting yaw (NDT's heading minus the direction of travel) from NDT's own poses
  /// and correct NDT's poses by it before the filter. Off by default: the filter's yaw-bias state
  /// learns the same angle within about 10 s, and correcting it earlier changed the error by -1 to +18 %
  /// on the twin (docs/experiment.md); the learned angle is reported either way.
  bool mount_yaw_estimation = false;
  double mount_yaw_memory = 500.0;  ///< m of travel over which old comparisons fade
  /// Each NDT pose's chord from the pose travel_check_window earlier is held against the odometry's
  /// distance over the same stamps (pipeline/travel_check.hpp); what it is off beyond the tolerance
  /// is added to the pose's x/y covariance. NDT's covariance from its score says how sharply the scan
  /// fits, not whether the fit is the right place; where NDT slides (a map out of date, a street
  /// alike along its length) the odometry says so within a second.
  double travel_check_window = 0.5;                ///< s; 0 = off
  double travel_check_tolerance = 0.03;            ///< m
  double travel_check_tolerance_per_metre = 0.005; ///< m per m of travel
  /// rad: each chord's turn too, NDT's heading change against the yaw rate's; a disagreement beyond
  /// this (and 0.002 rad/s of the chord's time) added, whole, to the pose's yaw variance. 0 = off: with NDT's
  /// yaw at Autoware's 1.4 deg a mismatched scan's turn hides in it, not where NDT's yaw is taken at
  /// its noise (ndt.quality_floor: noise).
  double travel_check_turn_tolerance = 0.0;
  /// A pose with no chord to compare yet (the first window after a start) is taken at no better than
  /// this standard deviation in x and y (Autoware's fixed NDT covariance by default).
  double travel_check_unverified_sd = 0.15;        ///< m
  /// Each NDT pose is held against the fixes of the last fix_agreement_window seconds (those that
  /// passed the registry's checks, carried to its stamp by the odometry; pipeline/fix_agreement.hpp):
  /// their median disagreement beyond the tolerance is added to its x/y covariance. NDT's score
  /// vouches for NDT's own bias (a map off the world, an optimum off the truth); within an RSU's
  /// coverage the fixes show it. On by default with multi_ndt_score: without it a hand start one
  /// post off in a repeating street stays 11.5 cm off against fixes 2 cm from the truth.
  double fix_agreement_window = 2.0;               ///< s; 0 = off
  double fix_agreement_tolerance = 0.03;           ///< m
};

/// The Ceres smoother of recorded logs (coloc smooth, the experiment's smoother column). Its rate,
/// process noise and gate follow the filter's (fusion section); these are its own.
struct SmootherSection {
  /// Measure each source's noise on the drive instead of taking the messages' covariances as given.
  bool estimate_noise = true;
  /// Estimate each odometry's speed scale and yaw-rate bias with the trajectory (twists then enter
  /// as the log has them, not as the pipeline rescaled them).
  bool calibrate_odometry = true;
  double odometry_scale_sd = 0.05;          ///< prior standard deviation of the scale around 1
  double odometry_yaw_rate_bias_sd = 0.01;  ///< rad/s, prior standard deviation of the bias around 0
  /// When map-matching poses (NDT) carry a slowly varying bias of their own, estimated with the
  /// states: when calibrating RSUs (they are anchored by NDT, and their uncertainty must include
  /// NDT's bias), always, or never.
  enum class PoseBias { kWhenCalibrating, kAlways, kNever } pose_bias = PoseBias::kWhenCalibrating;
  double pose_bias_time = 2.0;  ///< s, the bias's correlation time
  /// Freedom the filter's motion model does not have, which a batch problem needs: a random walk of
  /// the position and of the yaw bias.
  double proc_stddev_position_c = 0.02;  ///< m/s
  double proc_stddev_yaw_bias_c = 1e-4;  ///< rad/s
};

/// The live node's topics (ROS 2 names; DDS adds "rt") and QoS.
struct LiveSection {
  std::string scan_topic = "/points";
  std::string twist_topic = "/vehicle/twist";
  std::string twist_type = "geometry_msgs/msg/TwistWithCovarianceStamped";  ///< or nav_msgs/msg/Odometry, sensor_msgs/msg/Imu
  std::string initial_pose_topic = "/initialpose";  ///< PoseWithCovarianceStamped, as RViz sends it
  std::string pose_topic = "/localization/pose_twist_fusion_filter/pose_with_covariance";
  std::string odometry_topic = "/localization/pose_twist_fusion_filter/kinematic_state";
  std::string frame_id = "map";
  std::string child_frame_id = "base_link";
  bool reliable = false;  ///< false: ROS 2 sensor-data QoS (best effort) on the inputs
  /// Every topic a writer on the domain publishes is planned by its type, as `coloc fuse` plans a log's
  /// (pose sources, twist sources, scans, fixes), besides the topics above and those `inputs:` names.
  /// Off by default: in a running system the topics of other localizers (and this node's republished
  /// outputs, as Autoware's stop filter's) would become inputs.
  bool discover_inputs = false;
  // Further outputs, where Autoware's ekf_localizer and ndt_scan_matcher publish them; empty: not published.
  std::string twist_out_topic = "/localization/pose_twist_fusion_filter/twist_with_covariance";          ///< TwistWithCovarianceStamped
  std::string biased_pose_topic = "/localization/pose_twist_fusion_filter/biased_pose_with_covariance";  ///< PoseWithCovarianceStamped, yaw without the yaw bias
  std::string pose_stamped_topic = "/localization/pose_twist_fusion_filter/pose";                        ///< PoseStamped
  std::string ndt_pose_topic = "/localization/pose_estimator/pose_with_covariance";                      ///< NDT's own poses
  bool tf = true;           ///< frame_id -> child_frame_id on /tf at every tick
  bool diagnostics = true;  ///< /diagnostics (diagnostic_msgs/DiagnosticArray)
  double diagnostics_frequency = 10.0;  ///< Hz, as ekf_localizer publishes them
  /// Whether outputs flow from the start. Autoware's nodes wait for their trigger_node service
  /// (pose_initializer's sequence); a node of its own starts at once.
  bool start_activated = true;
  // Services (std_srvs/SetBool: true activates, false deactivates and forgets the pose; NDT's alignment
  // around a pose); empty: not served.
  std::string ekf_trigger_service;
  std::string ndt_trigger_service;
  std::string align_service;
};

struct Config {
  fusion::EkfConfig fusion;
  NdtSection ndt;
  RsuSection rsu;
  PipelineSection pipeline;
  MessageConfig messages;
  std::map<std::string, InputConfig> inputs;  ///< by topic
  ReplayConfig replay;
  SmootherSection smoother;
  LiveSection live;
};

/// Loads and validates a YAML file. Unknown keys, wrong types and out-of-range values throw
/// coloc::Error naming the file, the key and the line. A relative rsu.registry is made relative to
/// the file's folder.
Config loadConfig(const std::string& path);
Config parseConfig(const std::string& yaml_text, const std::string& source_name);

/// The complete default configuration as YAML with a comment per key: `coloc config` prints it and
/// config/coloc.yaml is this text.
std::string defaultConfigYaml();
/// Any configuration as a file `loadConfig` reads back to the same values (every number to the bit),
/// inputs included, after `heading` (comment lines).
std::string configYaml(const Config& config, const std::string& heading = "");

/// The reference table (Markdown) of every key, as docs/configuration.md has it.
std::string configReferenceMarkdown();

}  // namespace coloc::pipeline
