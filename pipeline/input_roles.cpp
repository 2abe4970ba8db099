#include "coloc/pipeline/input_roles.hpp"

#include "coloc/core/error.hpp"
#include "coloc/rsu_client/dds_transport.hpp"

namespace coloc::pipeline {

namespace {

using io::MessageKind;

// The role a topic gets when the config does not name it.
InputRole defaultRole(const std::string& topic, MessageKind kind, bool have_map, bool rsu_topic, std::string& note) {
  const bool truth_name = topic.find("ground_truth") != std::string::npos || topic.find("groundtruth") != std::string::npos;
  switch (kind) {
    case MessageKind::kPoseWithCovarianceStamped:
      if (truth_name) return InputRole::kGroundTruth;
      return rsu_topic ? InputRole::kRsuFix : InputRole::kPose;
    case MessageKind::kOdometry:
      if (truth_name) return InputRole::kGroundTruth;
      return rsu_topic ? InputRole::kRsuFix : InputRole::kTwist;
    case MessageKind::kTwistWithCovarianceStamped:
    case MessageKind::kImu: return InputRole::kTwist;
    case MessageKind::kPoseStamped:
      if (truth_name) return InputRole::kGroundTruth;
      note = "PoseStamped carries no covariance: give it a role in the config to use it";
      return InputRole::kIgnore;
    case MessageKind::kTwistStamped:
      note = "TwistStamped carries no covariance: give it a role in the config to use it";
      return InputRole::kIgnore;
    case MessageKind::kPointCloud2:
      if (have_map) return InputRole::kScan;
      note = "point clouds feed NDT, which needs a map (--map)";
      return InputRole::kIgnore;
    case MessageKind::kTFMessage:
      if (topic == "/tf_static") return InputRole::kStaticTransforms;
      note = "moving frames are not used; the LiDAR's mounting is read from /tf_static";
      return InputRole::kIgnore;
  }
  return InputRole::kIgnore;
}

}  // namespace

bool canServe(InputRole role, MessageKind kind) {
  switch (role) {
    case InputRole::kScan:
      return kind == MessageKind::kPointCloud2;
    case InputRole::kRsuFix:
      return kind == MessageKind::kPoseWithCovarianceStamped || kind == MessageKind::kOdometry;
    case InputRole::kPose:
    case InputRole::kGroundTruth:
      return kind == MessageKind::kPoseWithCovarianceStamped || kind == MessageKind::kPoseStamped || kind == MessageKind::kOdometry;
    case InputRole::kTwist:
      return kind == MessageKind::kTwistWithCovarianceStamped || kind == MessageKind::kTwistStamped || kind == MessageKind::kOdometry ||
             kind == MessageKind::kImu;
    case InputRole::kStaticTransforms:
      return kind == MessageKind::kTFMessage;
    case InputRole::kIgnore:
      return true;
  }
  return false;
}

std::optional<std::string> rsuOfTopic(const std::string& topic, const rsu_client::RsuRegistry* registry) {
  if (!registry) return std::nullopt;
  for (const rsu_client::RsuInfo& rsu : registry->rsus())
    if (rsu_client::fixTopic(rsu.id) == topic || rsu_client::addressedFixTopic(rsu.id) == topic) return rsu.id;
  return std::nullopt;
}

InputPlan planInput(const std::string& topic, const std::string& ros_type, const Config& config, bool have_map,
                    const rsu_client::RsuRegistry* registry) {
  InputPlan use;
  use.kind = io::messageKindOf(ros_type);
  const std::optional<std::string> rsu = rsuOfTopic(topic, registry);
  const auto configured = config.inputs.find(topic);
  if (configured != config.inputs.end()) {
    use.role = configured->second.role;
    use.source = configured->second.source;
    use.from_config = true;
    if (use.role != InputRole::kIgnore && (!use.kind || !canServe(use.role, *use.kind)))
      throw Error("config: inputs." + topic + ".role: a " + (ros_type.empty() ? std::string("message of unknown type") : ros_type) +
                  " cannot serve as " + toString(use.role));
    if (use.role == InputRole::kRsuFix && !rsu)
      throw Error("config: inputs." + topic + ".role: rsu_fix needs an RSU registry (rsu.registry) with an RSU whose fix topic this is");
  } else if (!use.kind) {
    use.note = "type not decoded by coloc";
  } else {
    use.role = defaultRole(topic, *use.kind, have_map, rsu.has_value(), use.note);
    if (registry && *use.kind == io::MessageKind::kPointCloud2)
      for (const rsu_client::RsuInfo& r : registry->rsus())
        if (topic == rsu_client::roadsidePointsTopic(r.id)) {
          use.role = InputRole::kIgnore;
          use.note = "RSU " + r.id + "'s own LiDAR frames: coloc rsu-node's input, not the vehicle's scans";
        }
    use.source = use.role == InputRole::kScan ? "ndt" : topic;
  }
  if (use.role == InputRole::kRsuFix) {
    use.rsu_id = *rsu;
    use.source = rsu_client::fixTopic(*rsu);  // the pipeline's source of this RSU
  }
  return use;
}

}  // namespace coloc::pipeline
