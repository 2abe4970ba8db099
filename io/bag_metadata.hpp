#pragma once
// rosbag2's metadata.yaml: read (versions 1 to 9) and written (version 5, what Humble writes and
// every later release reads).
#include <cstdint>
#include <string>
#include <vector>

#include "coloc/io/bag_message.hpp"

namespace coloc::io::detail {

struct BagFileMetadata {
  std::string path;
  Stamp starting_time = 0;
  Duration duration = 0;
  std::uint64_t message_count = 0;
};

struct BagMetadata {
  int version = 5;
  std::string storage_identifier;
  std::vector<std::string> relative_file_paths;
  Stamp starting_time = 0;
  Duration duration = 0;
  std::uint64_t message_count = 0;
  /// offered_qos_profiles as YAML text whatever the version stored (v9 lists are dumped back to text).
  std::vector<TopicInfo> topics;
  std::string compression_format;
  std::string compression_mode;
  std::vector<BagFileMetadata> files;
};

constexpr int kNewestMetadataVersion = 9;

/// Throws coloc::Error naming the file and the key that is missing or malformed.
BagMetadata readBagMetadata(const std::string& path);

/// The version-5 document; `with_root` wraps it in rosbag2_bagfile_information as metadata.yaml does
/// (the sqlite3 metadata table holds it without).
std::string bagMetadataYaml(const BagMetadata& metadata, bool with_root);

}  // namespace coloc::io::detail
