#include "coloc/io/mcap_writer.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include "coloc/io/bag_reader.hpp"
#include "coloc/io/bag_writer.hpp"
#include "coloc/io/ros_messages.hpp"
#include "io_test_support.hpp"

namespace coloc::io {
namespace {

using testing::errorMessage;
using testing::nav2Bag;
using testing::readAllMessages;
using testing::readBytes;
using testing::ScratchDir;

void expectSameTopics(const std::vector<TopicInfo>& a, const std::vector<TopicInfo>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].name, b[i].name);
    EXPECT_EQ(a[i].type, b[i].type);
    EXPECT_EQ(a[i].serialization_format, b[i].serialization_format);
    EXPECT_EQ(a[i].message_count, b[i].message_count) << a[i].name;
  }
}

void expectSameMessages(const std::vector<BagMessage>& a, const std::vector<BagMessage>& b, bool publish_times) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].topic, b[i].topic) << i;
    ASSERT_EQ(a[i].log_time, b[i].log_time) << i;
    ASSERT_EQ(a[i].data, b[i].data) << i;
    if (publish_times) {
      ASSERT_EQ(a[i].publish_time, b[i].publish_time) << i;
    }
  }
}

class McapRoundTrip : public ::testing::TestWithParam<McapCompression> {};

TEST_P(McapRoundTrip, ConvertedRecordingReadsBackIdentical) {
  ScratchDir dir;
  const std::string out = dir / "copy.mcap";
  ConvertOptions options;
  options.mcap.compression = GetParam();
  options.mcap.chunk_size = 64 * 1024;  // several chunks
  const ConvertSummary summary = convert(nav2Bag(), out, options);
  EXPECT_EQ(summary.message_count, 8197u);

  const BagReader original = BagReader::open(nav2Bag());
  const BagReader copy = BagReader::open(out);
  expectSameTopics(original.topics(), copy.topics());
  for (std::size_t i = 0; i < copy.topics().size(); ++i) {
    EXPECT_EQ(copy.topics()[i].offered_qos_profiles, original.topics()[i].offered_qos_profiles);
    EXPECT_EQ(copy.topics()[i].message_definition, original.topics()[i].message_definition);
  }
  expectSameMessages(readAllMessages(nav2Bag()), readAllMessages(out), true);
}

INSTANTIATE_TEST_SUITE_P(Compressions, McapRoundTrip,
                         ::testing::Values(McapCompression::kNone, McapCompression::kLz4, McapCompression::kZstd),
                         [](const auto& info) {
                           switch (info.param) {
                             case McapCompression::kNone: return std::string("None");
                             case McapCompression::kLz4: return std::string("Lz4");
                             case McapCompression::kZstd: return std::string("Zstd");
                           }
                           return std::string("Unknown");
                         });

TEST(McapWriter, FileWithoutSummaryOrIndexesIsCountedByScanning) {
  ScratchDir dir;
  ConvertOptions options;
  options.mcap.write_summary = false;
  options.mcap.write_message_indexes = false;
  options.mcap.write_crcs = false;
  options.mcap.chunk_size = 4096;
  convert(nav2Bag(), dir / "bare.mcap", options);
  const BagReader copy = BagReader::open(dir / "bare.mcap");
  expectSameTopics(BagReader::open(nav2Bag()).topics(), copy.topics());
  expectSameMessages(readAllMessages(nav2Bag()), readAllMessages(dir / "bare.mcap"), true);
}

TEST(McapWriter, SameInputGivesTheSameBytes) {
  ScratchDir dir;
  convert(nav2Bag(), dir / "a.mcap");
  convert(nav2Bag(), dir / "b.mcap");
  EXPECT_EQ(readBytes(dir / "a.mcap"), readBytes(dir / "b.mcap"));
}

TEST(McapWriter, KnownTypesGetColocsSchemaAndMessagesKeepTheirBytes) {
  ScratchDir dir;
  const std::string path = dir / "twin.mcap";
  StampedPose pose;
  pose.header = {fromRosTime(10, 0), "map"};
  const Bytes bytes = encodePoseWithCovarianceStamped(pose);
  {
    McapWriter writer = McapWriter::create(path);
    writer.addTopic({"/rsu/pose", "geometry_msgs/msg/PoseWithCovarianceStamped", "cdr", "", "", "", 0, {}});
    writer.addTopic({"/blob", "", "cdr", "", "", "", 0, {}});  // no type: no schema
    writer.write("/rsu/pose", 5, 4, bytes.data(), bytes.size());
    writer.write("/blob", 6, 6, bytes.data(), 4);
    writer.close();
  }
  BagReader reader = BagReader::open(path);
  ASSERT_EQ(reader.topics().size(), 2u);
  EXPECT_EQ(reader.topics()[0].message_definition, rosMessageDefinition("geometry_msgs/msg/PoseWithCovarianceStamped"));
  EXPECT_EQ(reader.topics()[0].message_definition_encoding, "ros2msg");
  EXPECT_EQ(reader.topics()[1].type, "");
  BagMessage message;
  ASSERT_TRUE(reader.next(message));
  EXPECT_EQ(message.data, bytes);
  EXPECT_EQ(message.log_time, 5);
  EXPECT_EQ(message.publish_time, 4);
  ASSERT_TRUE(reader.next(message));
  EXPECT_EQ(message.topic, "/blob");
  EXPECT_EQ(message.data.size(), 4u);
}

TEST(McapWriter, ATypeColocCannotDefineGetsAnEmptySchemaEncodingAsRosbag2Writes) {
  ScratchDir dir;
  const std::string path = dir / "image.mcap";
  {
    McapWriter writer = McapWriter::create(path);
    writer.addTopic({"/camera", "sensor_msgs/msg/Image", "cdr", "", "", "", 0, {}});
    writer.close();
  }
  BagReader reader = BagReader::open(path);
  ASSERT_EQ(reader.topics().size(), 1u);
  EXPECT_EQ(reader.topics()[0].type, "sensor_msgs/msg/Image");
  // "ros2msg" with no text would say the type has no fields: readers would decode every image to {}.
  EXPECT_EQ(reader.topics()[0].message_definition_encoding, "");
  EXPECT_EQ(reader.topics()[0].message_definition, "");
}

TEST(McapWriter, ChannelMetadataAttachmentsAndMetadataRecordsSurviveMcapToMcap) {
  ScratchDir dir;
  const std::string first = dir / "first.mcap", second = dir / "second.mcap";
  TopicInfo topic{"/chatter", "std_msgs/msg/String", "cdr", "", "string data", "ros2msg", 0, {}};
  topic.metadata = {{"topic_type_hash", "RIHS01_5e1b"}, {"site", "A"}};
  BagAttachment attachment{5, 4, "calibration.yaml", "application/yaml", {'x', ':', ' ', '1'}};
  BagMetadataRecord record{"recording", {{"vehicle", "ego"}, {"weather", "dry"}}};
  {
    McapWriter writer = McapWriter::create(first);
    writer.addTopic(topic);
    const std::uint8_t payload[] = {0, 1, 0, 0, 3, 0, 0, 0, 'h', 'i', 0, 0};
    writer.write("/chatter", 10, 10, payload, sizeof payload);
    writer.writeAttachment(attachment);
    writer.writeMetadata(record);
    writer.close();
  }
  const ConvertSummary summary = convert(first, second);
  EXPECT_EQ(summary.attachments, 1u);
  EXPECT_EQ(summary.metadata_records, 1u);
  BagReader reader = BagReader::open(second);
  reader.keepAttachments(true);
  ASSERT_EQ(reader.topics().size(), 1u);
  EXPECT_EQ(reader.topics()[0].metadata, topic.metadata);
  BagMessage m;
  while (reader.next(m)) {
  }
  ASSERT_EQ(reader.attachments().size(), 1u);
  const BagAttachment& a = reader.attachments()[0];
  EXPECT_EQ(a.name, attachment.name);
  EXPECT_EQ(a.media_type, attachment.media_type);
  EXPECT_EQ(a.log_time, attachment.log_time);
  EXPECT_EQ(a.create_time, attachment.create_time);
  EXPECT_EQ(a.data, attachment.data);
  ASSERT_EQ(reader.metadataRecords().size(), 1u);
  EXPECT_EQ(reader.metadataRecords()[0].name, record.name);
  EXPECT_EQ(reader.metadataRecords()[0].entries, record.entries);
  // A damaged attachment is refused by its CRC, naming it.
  std::vector<std::uint8_t> bytes = testing::readBytes(second);
  const auto at = std::search(bytes.begin(), bytes.end(), attachment.data.begin(), attachment.data.end());
  ASSERT_NE(at, bytes.end());
  *at ^= 0x01;
  testing::writeBytes(dir / "damaged.mcap", bytes);
  const std::string error = testing::errorMessage([&] {
    BagReader damaged = BagReader::open(dir / "damaged.mcap");
    damaged.keepAttachments(true);
    BagMessage m;
    while (damaged.next(m)) {
    }
  });
  EXPECT_NE(error.find("attachment 'calibration.yaml' CRC mismatch"), std::string::npos) << error;
  // A reader that does not keep attachments skips them unread: the messages are all there.
  EXPECT_EQ(testing::readAllMessages(dir / "damaged.mcap").size(), 1u);
}

TEST(McapWriter, EmptyFileIsValid) {
  ScratchDir dir;
  McapWriter::create(dir / "empty.mcap").close();
  const BagReader reader = BagReader::open(dir / "empty.mcap");
  EXPECT_TRUE(reader.topics().empty());
  EXPECT_TRUE(readAllMessages(dir / "empty.mcap").empty());
}

TEST(McapWriter, RefusesToOverwriteAnExistingFile) {
  ScratchDir dir;
  testing::writeText(dir / "taken.mcap", "x");
  const std::string message = errorMessage([&] { McapWriter::create(dir / "taken.mcap"); });
  EXPECT_NE(message.find("taken.mcap: already exists"), std::string::npos) << message;
  EXPECT_EQ(readBytes(dir / "taken.mcap").size(), 1u);
}

TEST(McapWriter, UndeclaredTopicsAndNegativeTimesAreErrors) {
  ScratchDir dir;
  McapWriter writer = McapWriter::create(dir / "w.mcap");
  const std::uint8_t byte = 0;
  EXPECT_NE(errorMessage([&] { writer.write("/nope", 1, 1, &byte, 1); }).find("/nope was not declared"),
            std::string::npos);
  writer.addTopic({"/a", "std_msgs/msg/String", "cdr", "", "", "", 0, {}});
  EXPECT_NE(errorMessage([&] { writer.addTopic({"/a", "x/msg/Y", "cdr", "", "", "", 0, {}}); }).find("declared twice"),
            std::string::npos);
  EXPECT_NE(errorMessage([&] { writer.write("/a", -1, 0, &byte, 1); }).find("negative time stamp"),
            std::string::npos);
  writer.close();
  EXPECT_NE(errorMessage([&] { writer.write("/a", 1, 1, &byte, 1); }).find("write after close"), std::string::npos);
}

}  // namespace
}  // namespace coloc::io
