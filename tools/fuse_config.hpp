#pragma once
// The configuration of `coloc fuse`: the filter's keys (section `fusion:`), how each log topic feeds the
// filter (section `inputs:`), and how the log is replayed (section `replay:`). Every key has a default,
// so an empty file (or none) is a valid configuration.
#include <array>
#include <map>
#include <optional>
#include <string>

#include "coloc/core/types.hpp"
#include "coloc/fusion/ekf_config.hpp"
#include "coloc/ndt/ndt_pose_source.hpp"
#include "coloc/rsu_client/link_emulator.hpp"

namespace coloc::tools {

enum class InputRole { kPose, kTwist, kGroundTruth, kScan, kIgnore };
const char* toString(InputRole role);

/// How one topic is used. Topics not listed are chosen by message type (see README).
struct InputConfig {
  InputRole role = InputRole::kIgnore;
  std::string source;                      ///< name in the Localizer; default: the topic
  std::optional<Vector6d> covariance_diagonal;  ///< replaces the message's covariance
  double additional_delay = 0.0;           ///< s; the data was sensed this much before its stamp
  /// Replays the topic through an emulated radio link (delay, jitter, loss), as experiments do.
  std::optional<rsu_client::LinkConfig> link;
};

enum class ClockMode { kAuto, kSame, kSeparate };

struct ReplayConfig {
  /// Whether header stamps and log (receive) times are on one clock. `separate` (a log recorded with
  /// simulation time) measures each message's delay relative to the least-delayed message.
  ClockMode clock = ClockMode::kAuto;
  /// ROS drivers write 0 for components they do not estimate (AMCL's z, roll, pitch); read as +inf.
  bool zero_variance_is_unmeasured = true;
  /// Used when a message carries no covariance at all (PoseStamped, or all zeros): Autoware's NDT value.
  Vector6d fallback_pose_variance = (Vector6d() << 0.0225, 0.0225, 0.0225, 0.000625, 0.000625, 0.000625).finished();
  /// Autoware's twist standard deviations 0.2 m/s and 0.1 rad/s; vy, vz, wx, wy are not used.
  Vector6d fallback_twist_variance = (Vector6d() << 0.04, kInfinity, kInfinity, kInfinity, kInfinity, 0.01).finished();
  /// Ground truth further than this from an output tick is not interpolated across.
  double ground_truth_max_gap = 0.2;  ///< s
  /// Starts the filter here (x, y, z [m], yaw [rad]) at the first message, for logs whose only pose
  /// source is NDT, which needs a first guess.
  std::optional<Eigen::Vector4d> initial_pose;
};

/// Scan matching of the log's PointCloud2 topic against a map (`coloc fuse --map`).
struct NdtSection {
  ndt::NdtPoseSourceConfig source;
  double map_tile_size = 20.0;  ///< m; a single-file map is cut into squares of this size
};

struct FuseConfig {
  fusion::EkfConfig fusion;
  NdtSection ndt;
  std::map<std::string, InputConfig> inputs;  ///< by topic
  ReplayConfig replay;
};

/// Loads and validates a YAML file. Unknown keys, wrong types and out-of-range values throw
/// coloc::Error naming the file, the key and the line.
FuseConfig loadFuseConfig(const std::string& path);
FuseConfig parseFuseConfig(const std::string& yaml_text, const std::string& source_name);

/// The complete default configuration as YAML with a comment per key: `coloc config` prints it and
/// config/coloc.yaml is this text.
std::string defaultConfigYaml();

/// The README's reference table (Markdown) of every key.
std::string configReferenceMarkdown();

}  // namespace coloc::tools
