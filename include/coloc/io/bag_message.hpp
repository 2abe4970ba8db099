#pragma once
// What a ROS 2 recording holds, independent of its storage (sqlite3 .db3 or MCAP): topics and
// serialized messages stamped with the time they were logged.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "coloc/core/time.hpp"

namespace coloc::io {

/// One topic of a bag.
struct TopicInfo {
  std::string name;                           ///< "/amcl_pose"
  std::string type;                           ///< "geometry_msgs/msg/PoseWithCovarianceStamped"; empty if unknown
  std::string serialization_format = "cdr";   ///< MCAP message_encoding / rosbag2 serialization_format
  std::string offered_qos_profiles;           ///< YAML text as stored by the recorder; may be empty
  std::string message_definition;             ///< schema text if the bag carries one (MCAP schema, sqlite3 schema 4)
  std::string message_definition_encoding;    ///< "ros2msg", "ros2idl" or empty
  std::uint64_t message_count = 0;
  /// MCAP channel metadata besides offered_qos_profiles (topic_type_hash, user keys), kept by conversion.
  std::map<std::string, std::string> metadata;
};

/// A file stored beside the messages (MCAP Attachment record: a calibration, a map, a note).
struct BagAttachment {
  Stamp log_time = 0, create_time = 0;
  std::string name, media_type;
  std::vector<std::uint8_t> data;
};

/// Named key-value pairs stored beside the messages (MCAP Metadata record: the recording's conditions).
struct BagMetadataRecord {
  std::string name;
  std::map<std::string, std::string> entries;
};

/// One recorded message.
struct BagMessage {
  std::string topic;
  Stamp log_time = 0;                  ///< when the recorder received it (rosbag2 "timestamp", MCAP log_time)
  std::optional<Stamp> publish_time;   ///< MCAP only
  std::vector<std::uint8_t> data;      ///< serialized bytes, encapsulation header included
  std::uint64_t index = 0;             ///< 0-based position in the bag's iteration order
};

}  // namespace coloc::io
