#pragma once
// What a topic is for, the same way offline (a log's topics) and live (the topics DDS discovers): the
// config names a role; otherwise the message type decides (poses are pose sources, twists and odometry
// twist sources, "ground_truth" in a name marks the truth, point clouds feed NDT when there is a map,
// an RSU's fix topics are roadside fixes when the registry has it, /tf_static places the LiDAR).
#include <optional>
#include <string>

#include "coloc/io/ros_messages.hpp"
#include "coloc/pipeline/config.hpp"
#include "coloc/rsu_client/rsu_registry.hpp"

namespace coloc::pipeline {

struct InputPlan {
  InputRole role = InputRole::kIgnore;
  std::optional<io::MessageKind> kind;
  std::string source;        ///< Localizer source name (pose / twist roles; "ndt" for scans; the RSU's source for fixes)
  std::string rsu_id;        ///< rsu_fix role: whose fixes
  bool from_config = false;  ///< role set in the config rather than chosen by type
  std::string note;          ///< why a topic is not used
};

/// Whether a message of this kind can serve in this role.
bool canServe(InputRole role, io::MessageKind kind);

/// The RSU whose fix topic (/rsu/<id>/fix or /rsu/<id>/addressed_fix) this is, if the registry has it.
std::optional<std::string> rsuOfTopic(const std::string& topic, const rsu_client::RsuRegistry* registry);

/// How a topic of this ROS type is used. Throws coloc::Error when the config gives it a role its type
/// cannot serve, or rsu_fix without an RSU whose topic it is.
InputPlan planInput(const std::string& topic, const std::string& ros_type, const Config& config, bool have_map,
                    const rsu_client::RsuRegistry* registry);

}  // namespace coloc::pipeline
