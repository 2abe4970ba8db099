#include "coloc/replay/topic_plan.hpp"

#include <set>

#include "coloc/core/error.hpp"
#include "coloc/pipeline/input_roles.hpp"

namespace coloc::replay {

using pipeline::InputRole;

std::optional<std::string> rsuOfTopic(const std::string& topic, const rsu_client::RsuRegistry* registry) {
  return pipeline::rsuOfTopic(topic, registry);
}

std::vector<TopicUse> planTopics(const std::vector<io::TopicInfo>& topics, const pipeline::Config& config, bool have_map,
                                 const rsu_client::RsuRegistry* registry, std::vector<std::string>& notes) {
  std::vector<TopicUse> plan;
  std::set<std::string> names;
  for (const io::TopicInfo& t : topics) {
    TopicUse use;
    use.topic = t.name;
    use.type = t.type;
    const pipeline::InputPlan p = pipeline::planInput(t.name, t.type, config, have_map, registry);
    use.kind = p.kind;
    use.role = p.role;
    use.source = p.source;
    use.rsu_id = p.rsu_id;
    use.from_config = p.from_config;
    use.note = p.note;
    if (use.role != InputRole::kIgnore && t.serialization_format != "cdr") {
      use.note = "serialization format '" + t.serialization_format + "' is not CDR";
      use.role = InputRole::kIgnore;
    }
    names.insert(t.name);
    plan.push_back(use);
  }
  for (const auto& [topic, input] : config.inputs)
    if (!names.count(topic)) notes.push_back("config names topic " + topic + ", which the log does not have");
  return plan;
}

std::string describeTopics(const std::vector<TopicUse>& topics) {
  if (topics.empty()) return "  (no topics)\n";
  std::string out;
  for (const TopicUse& t : topics) {
    out += "  " + t.topic + " (" + (t.type.empty() ? std::string("type unknown") : t.type) + "), " + std::to_string(t.messages) + " messages: ";
    out += t.role == InputRole::kIgnore ? "not used" + (t.note.empty() ? std::string() : " (" + t.note + ")") : std::string("role ") + toString(t.role);
    if (t.decode_errors) out += "; " + std::to_string(t.decode_errors) + " undecodable, first: " + t.first_error;
    out += "\n";
  }
  return out;
}

}  // namespace coloc::replay
