#pragma once
// Stage 1 of a replay: what each topic of the log is for. The config names a role; otherwise the
// message type decides (poses are pose sources, twists and odometry twist sources, "ground_truth" in a
// name marks the truth, point clouds feed NDT when there is a map, /rsu/<id>/fix topics are roadside
// fixes when there is an RSU registry, and /tf_static places the LiDAR on the vehicle).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "coloc/io/bag_reader.hpp"
#include "coloc/io/ros_messages.hpp"
#include "coloc/pipeline/config.hpp"
#include "coloc/rsu_client/rsu_registry.hpp"

namespace coloc::replay {

/// How one topic of the log was used.
struct TopicUse {
  std::string topic;
  std::string type;
  pipeline::InputRole role = pipeline::InputRole::kIgnore;
  std::optional<io::MessageKind> kind;
  std::string source;       ///< Localizer source name (pose / twist roles)
  std::string rsu_id;       ///< rsu_fix role: whose fixes
  std::string frame_id;     ///< scan role: the frame of its first scan (where the LiDAR is)
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

/// The RSU whose fix topic this is (/rsu/<id>/fix), if the registry has it.
std::optional<std::string> rsuOfTopic(const std::string& topic, const rsu_client::RsuRegistry* registry);

/// One TopicUse per topic of the log. Throws coloc::Error when the config gives a topic a role its type
/// cannot serve; config entries naming topics the log lacks are added to `notes`.
std::vector<TopicUse> planTopics(const std::vector<io::TopicInfo>& topics, const pipeline::Config& config, bool have_map,
                                 const rsu_client::RsuRegistry* registry, std::vector<std::string>& notes);

/// What a log holds, a line per topic (name, type, messages, role or why it is skipped, decode errors):
/// what an error says when a log gives the filter nothing to fuse.
std::string describeTopics(const std::vector<TopicUse>& topics);

}  // namespace coloc::replay
