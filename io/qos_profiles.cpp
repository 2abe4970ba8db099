#include "qos_profiles.hpp"

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <map>
#include <optional>

namespace coloc::io::detail {
namespace {

// rmw/types.h enumerators and rmw/qos_string_conversions names.
const std::map<std::string, int> kHistory{{"system_default", 0}, {"keep_last", 1}, {"keep_all", 2}, {"unknown", 3}};
const std::map<std::string, int> kReliability{
    {"system_default", 0}, {"reliable", 1}, {"best_effort", 2}, {"unknown", 3}, {"best_available", 4}};
const std::map<std::string, int> kDurability{
    {"system_default", 0}, {"transient_local", 1}, {"volatile", 2}, {"unknown", 3}, {"best_available", 4}};
const std::map<std::string, int> kLiveliness{{"system_default", 0}, {"automatic", 1}, {"manual_by_node", 2},
                                             {"manual_by_topic", 3}, {"unknown", 4}, {"best_available", 5}};

// RMW_DURATION_INFINITE as rosbag2 writes it.
constexpr std::uint64_t kInfiniteSec = 9223372036ull;
constexpr std::uint64_t kInfiniteNsec = 854775807ull;

struct Duration {
  std::uint64_t sec = kInfiniteSec;
  std::uint64_t nsec = kInfiniteNsec;
};

struct Profile {
  int history = 1;
  int depth = 10;
  int reliability = 1;
  int durability = 2;
  Duration deadline, lifespan;
  int liveliness = 1;
  Duration liveliness_lease_duration;
  bool avoid_ros_namespace_conventions = false;
};

std::optional<int> enumValue(const YAML::Node& node, const std::map<std::string, int>& names) {
  if (!node || !node.IsScalar()) return std::nullopt;
  int number = 0;
  if (YAML::convert<int>::decode(node, number)) return number;
  const auto found = names.find(node.Scalar());
  if (found == names.end()) return std::nullopt;
  return found->second;
}

void readEnum(const YAML::Node& node, const std::map<std::string, int>& names, int& value) {
  if (const auto parsed = enumValue(node, names)) value = *parsed;
}

void readDuration(const YAML::Node& node, Duration& value) {
  if (!node || !node.IsMap()) return;
  std::uint64_t sec = 0, nsec = 0;
  if (YAML::convert<std::uint64_t>::decode(node["sec"], sec) && YAML::convert<std::uint64_t>::decode(node["nsec"], nsec)) {
    value = {sec, nsec};
  }
}

Profile readProfile(const YAML::Node& node) {
  Profile p;
  readEnum(node["history"], kHistory, p.history);
  if (node["depth"]) YAML::convert<int>::decode(node["depth"], p.depth);
  readEnum(node["reliability"], kReliability, p.reliability);
  readEnum(node["durability"], kDurability, p.durability);
  readDuration(node["deadline"], p.deadline);
  readDuration(node["lifespan"], p.lifespan);
  readEnum(node["liveliness"], kLiveliness, p.liveliness);
  readDuration(node["liveliness_lease_duration"], p.liveliness_lease_duration);
  if (node["avoid_ros_namespace_conventions"]) {
    YAML::convert<bool>::decode(node["avoid_ros_namespace_conventions"], p.avoid_ros_namespace_conventions);
  }
  return p;
}

void emitDuration(YAML::Emitter& out, const char* key, const Duration& d) {
  out << YAML::Key << key << YAML::Value << YAML::BeginMap << YAML::Key << "sec" << YAML::Value << d.sec
      << YAML::Key << "nsec" << YAML::Value << d.nsec << YAML::EndMap;
}

void emitProfile(YAML::Emitter& out, const Profile& p) {
  out << YAML::BeginMap;
  out << YAML::Key << "history" << YAML::Value << p.history;
  out << YAML::Key << "depth" << YAML::Value << p.depth;
  out << YAML::Key << "reliability" << YAML::Value << p.reliability;
  out << YAML::Key << "durability" << YAML::Value << p.durability;
  emitDuration(out, "deadline", p.deadline);
  emitDuration(out, "lifespan", p.lifespan);
  out << YAML::Key << "liveliness" << YAML::Value << p.liveliness;
  emitDuration(out, "liveliness_lease_duration", p.liveliness_lease_duration);
  out << YAML::Key << "avoid_ros_namespace_conventions" << YAML::Value << p.avoid_ros_namespace_conventions;
  out << YAML::EndMap;
}

std::vector<Profile> parseProfiles(const std::string& recorded) {
  std::vector<Profile> profiles;
  try {
    const YAML::Node node = YAML::Load(recorded);
    if (!node.IsSequence()) return {};
    for (const auto& entry : node) {
      if (entry.IsMap()) profiles.push_back(readProfile(entry));
    }
  } catch (const YAML::Exception&) {
    return {};  // unreadable profiles are replaced by the default, as rosbag2 does for missing ones
  }
  return profiles;
}

}  // namespace

std::string qosProfilesWithNumericEnums(const std::string& recorded) {
  std::vector<Profile> profiles = parseProfiles(recorded);
  if (profiles.empty()) profiles.emplace_back();
  YAML::Emitter out;
  out << YAML::BeginSeq;
  for (const auto& p : profiles) emitProfile(out, p);
  out << YAML::EndSeq;
  return out.c_str();
}

}  // namespace coloc::io::detail
