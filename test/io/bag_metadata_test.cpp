// rosbag2 directories described by metadata.yaml, in the versions rosbag2 has written (4 to 9), and
// metadata files that are damaged.
#include <gtest/gtest.h>

#include "coloc/io/bag_reader.hpp"
#include "coloc/io/bag_writer.hpp"
#include "io_test_support.hpp"

namespace coloc::io {
namespace {

namespace fs = std::filesystem;
using testing::errorMessage;
using testing::nav2Bag;
using testing::readAllMessages;
using testing::ScratchDir;
using testing::writeText;

/// metadata.yaml of a one-file bag in `version`, with the QoS in the form that version uses.
std::string metadataYaml(int version, const std::string& storage, const std::string& file) {
  const std::string qos = version >= 9 ? "\n          - history: keep_last\n            depth: 10\n"
                                         "            reliability: reliable\n            durability: volatile\n"
                                       : " \"- history: 1\\n  depth: 10\\n  reliability: 1\\n  durability: 2\"\n";
  return "rosbag2_bagfile_information:\n"
         "  version: " + std::to_string(version) + "\n"
         "  storage_identifier: " + storage + "\n"
         "  duration:\n    nanoseconds: 97355296000\n"
         "  starting_time:\n    nanoseconds_since_epoch: 1778234353382747000\n"
         "  message_count: 8197\n"
         "  topics_with_message_count:\n"
         "    - topic_metadata:\n"
         "        name: /odom\n"
         "        type: nav_msgs/msg/Odometry\n"
         "        serialization_format: cdr\n"
         "        offered_qos_profiles:" + qos +
         (version >= 7 ? "        type_description_hash: RIHS01_00\n" : "") +
         "      message_count: 2639\n"
         "  compression_format: \"\"\n"
         "  compression_mode: \"\"\n"
         "  relative_file_paths:\n"
         "    - " + file + "\n" +
         (version >= 5 ? "  files:\n    - path: " + file + "\n      starting_time:\n        nanoseconds_since_epoch: 0\n"
                         "      duration:\n        nanoseconds: 0\n      message_count: 8197\n"
                       : "") +
         (version >= 6 ? "  custom_data: ~\n" : "") + (version >= 8 ? "  ros_distro: jazzy\n" : "");
}

/// A directory holding a copy of the real recording and metadata.yaml of `version`.
std::string mcapBagDirectory(const ScratchDir& dir, int version) {
  const fs::path bag = dir.path() / ("v" + std::to_string(version));
  fs::create_directories(bag);
  fs::copy_file(nav2Bag(), bag / "v_0.mcap");
  writeText((bag / "metadata.yaml").string(), metadataYaml(version, "mcap", "v_0.mcap"));
  return bag.string();
}

TEST(BagMetadata, DirectoriesOfEveryMetadataVersionFromFourToNineAreRead) {
  ScratchDir dir;
  for (int version = 4; version <= 9; ++version) {
    const BagReader reader = BagReader::open(mcapBagDirectory(dir, version));
    EXPECT_EQ(reader.storageIdentifier(), "mcap") << version;
    EXPECT_EQ(reader.messageCount(), 8197u) << version;
    EXPECT_EQ(reader.files().size(), 1u);
  }
}

TEST(BagMetadata, MetadataFileItselfCanBeGivenAsThePath) {
  ScratchDir dir;
  const std::string bag = mcapBagDirectory(dir, 9);
  EXPECT_EQ(BagReader::open(bag + "/metadata.yaml").messageCount(), 8197u);
}

TEST(BagMetadata, SeveralFilesAreReadInListedOrder) {
  ScratchDir dir;
  convert(nav2Bag(), dir / "one");
  convert(nav2Bag(), dir / "two");
  const fs::path bag = dir.path() / "both";
  fs::create_directories(bag);
  fs::copy_file(dir.path() / "one/one_0.db3", bag / "both_0.db3");
  fs::copy_file(dir.path() / "two/two_0.db3", bag / "both_1.db3");
  std::string yaml = metadataYaml(5, "sqlite3", "both_0.db3");
  yaml.replace(yaml.find("  files:"), std::string::npos, "    - both_1.db3\n");
  writeText((bag / "metadata.yaml").string(), yaml);
  const BagReader reader = BagReader::open(bag.string());
  EXPECT_EQ(reader.files().size(), 2u);
  EXPECT_EQ(reader.messageCount(), 2 * 8197u);
  EXPECT_EQ(readAllMessages(bag.string()).size(), 2 * 8197u);
}

TEST(BagMetadata, PathsRelativeToTheParentDirectoryAreFound) {
  // rosbag2 before metadata version 4 listed files as "<bag>/<bag>_0.db3".
  ScratchDir dir;
  convert(nav2Bag(), dir / "old");
  writeText(dir / "old/metadata.yaml", metadataYaml(4, "sqlite3", "old/old_0.db3"));
  EXPECT_EQ(BagReader::open(dir / "old").messageCount(), 8197u);
}

struct BrokenMetadata {
  const char* name;
  std::string yaml;
  const char* reason;
};

TEST(BagMetadata, DamagedMetadataIsReportedWithTheFileAndTheReason) {
  const std::string good = metadataYaml(5, "mcap", "v_0.mcap");
  auto replaced = [&](const std::string& from, const std::string& to) {
    std::string yaml = good;
    yaml.replace(yaml.find(from), from.size(), to);
    return yaml;
  };
  const std::vector<BrokenMetadata> cases{
      {"binary junk", std::string("\x89\x01\xff{[:: :", 10), "not valid YAML"},
      {"empty", "", "no 'rosbag2_bagfile_information' mapping"},
      {"another document", "name: robot\nversion: 1\n", "no 'rosbag2_bagfile_information' mapping"},
      {"version missing", replaced("  version: 5\n", ""), "missing key 'version'"},
      {"version text", replaced("version: 5", "version: five"), "key 'version' must be an integer"},
      {"version too new", replaced("version: 5", "version: 42"), "metadata version 42 is not supported"},
      {"storage unknown", replaced("storage_identifier: mcap", "storage_identifier: leveldb"),
       "storage_identifier 'leveldb' is not supported"},
      {"files not a list", replaced("relative_file_paths:\n    - v_0.mcap", "relative_file_paths: v_0.mcap"),
       "key 'relative_file_paths' must be a list"},
      {"no files", replaced("relative_file_paths:\n    - v_0.mcap", "relative_file_paths: []"),
       "relative_file_paths lists no storage file"},
      {"compressed with lz4", replaced("compression_format: \"\"", "compression_format: lz4"),
       "compression_format 'lz4' is not supported (zstd)"},
      {"compressed in another mode", replaced("compression_format: \"\"\n  compression_mode: \"\"", "compression_format: zstd\n  compression_mode: CHUNK"),
       "compression_mode 'CHUNK' is not supported (FILE, MESSAGE)"},
      {"topic without name", replaced("        name: /odom\n", ""),
       "missing key 'topics_with_message_count[0].topic_metadata.name'"},
      {"negative count", replaced("message_count: 2639", "message_count: -4"),
       "key 'topics_with_message_count[0].message_count' must be an integer"},
  };
  ScratchDir dir;
  for (const auto& broken : cases) {
    const fs::path bag = dir.path() / "bag";
    fs::remove_all(bag);
    fs::create_directories(bag);
    fs::copy_file(nav2Bag(), bag / "v_0.mcap");
    writeText((bag / "metadata.yaml").string(), broken.yaml);
    const std::string message = errorMessage([&] { BagReader::open(bag.string()); });
    EXPECT_EQ(message.rfind((bag / "metadata.yaml").string() + ": ", 0), 0u) << broken.name << ": " << message;
    EXPECT_NE(message.find(broken.reason), std::string::npos) << broken.name << ": " << message;
  }
}

TEST(BagMetadata, DirectoryWithNoBagIsReported) {
  ScratchDir dir;
  fs::create_directories(dir / "nothing");
  EXPECT_NE(errorMessage([&] { BagReader::open(dir / "nothing"); }).find("no metadata.yaml, and no .db3 or .mcap file"),
            std::string::npos);
}

}  // namespace
}  // namespace coloc::io
