#pragma once
// offered_qos_profiles as rosbag2 stores them: a YAML list of rmw QoS profiles. Metadata versions up
// to 8 (and Humble's player) expect numeric enums ("reliability: 1"); version 9 (Jazzy) writes names
// ("reliability: reliable"). Bags coloc writes use the numeric form so that Humble can play them.
#include <string>

namespace coloc::io::detail {

/// The recorded profiles rewritten with numeric enums; the default profile (KEEP_LAST 10, RELIABLE,
/// VOLATILE, infinite durations) when `recorded` is empty or not a list of profiles.
std::string qosProfilesWithNumericEnums(const std::string& recorded);

}  // namespace coloc::io::detail
