// The real Nav2 TurtleBot recording (zstd MCAP, profile ros2) read end to end.
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "coloc/io/bag_reader.hpp"
#include "coloc/io/mcap_writer.hpp"
#include "coloc/io/ros_messages.hpp"
#include "io_test_support.hpp"

namespace coloc::io {
namespace {

using testing::nav2Bag;

const TopicInfo* findTopic(const BagReader& reader, const std::string& name) {
  for (const auto& topic : reader.topics()) {
    if (topic.name == name) return &topic;
  }
  return nullptr;
}

TEST(McapReader, ListsTheTopicsAndCountsOfTheNav2Recording) {
  const BagReader reader = BagReader::open(nav2Bag());
  EXPECT_EQ(reader.storageIdentifier(), "mcap");
  ASSERT_EQ(reader.topics().size(), 4u);
  const TopicInfo* amcl = findTopic(reader, "/amcl_pose");
  const TopicInfo* odom = findTopic(reader, "/odom");
  ASSERT_TRUE(amcl && odom && findTopic(reader, "/tf") && findTopic(reader, "/tf_static"));
  EXPECT_EQ(amcl->message_count, 135u);
  EXPECT_EQ(amcl->type, "geometry_msgs/msg/PoseWithCovarianceStamped");
  EXPECT_EQ(amcl->serialization_format, "cdr");
  EXPECT_EQ(amcl->message_definition_encoding, "ros2msg");
  EXPECT_NE(amcl->message_definition.find("MSG: geometry_msgs/PoseWithCovariance"), std::string::npos);
  EXPECT_NE(amcl->offered_qos_profiles.find("durability: transient_local"), std::string::npos);
  EXPECT_EQ(odom->message_count, 2639u);
  EXPECT_EQ(odom->type, "nav_msgs/msg/Odometry");
  EXPECT_EQ(findTopic(reader, "/tf")->message_count, 5422u);
  EXPECT_EQ(findTopic(reader, "/tf_static")->message_count, 1u);
  EXPECT_EQ(reader.messageCount(), 8197u);
}

TEST(McapReader, IteratesEveryCountedMessageWithLogAndPublishTimes) {
  BagReader reader = BagReader::open(nav2Bag());
  std::map<std::string, std::uint64_t> counts;
  BagMessage message;
  std::uint64_t expected_index = 0;
  Stamp first = 0, last = 0;
  while (reader.next(message)) {
    ASSERT_EQ(message.index, expected_index++);
    ASSERT_TRUE(message.publish_time.has_value());
    ASSERT_GE(message.data.size(), 4u);
    if (message.index == 0) first = message.log_time;
    last = message.log_time;
    ++counts[message.topic];
  }
  EXPECT_EQ(expected_index, 8197u);
  EXPECT_EQ(counts["/amcl_pose"], 135u);
  EXPECT_EQ(counts["/odom"], 2639u);
  // Wall-clock log times: 1778234353.38 s to 1778234450.74 s.
  EXPECT_EQ(first, 1778234353382747000LL);
  EXPECT_EQ(last, 1778234450738043000LL);
  EXPECT_FALSE(reader.next(message));  // stays at the end
}

TEST(McapReader, FirstAmclPoseDecodesToTheRecordedPose) {
  BagReader reader = BagReader::open(nav2Bag());
  BagMessage message;
  while (reader.next(message) && message.topic != "/amcl_pose") {
  }
  ASSERT_EQ(message.topic, "/amcl_pose");
  const StampedPose pose = decodePoseWithCovarianceStamped(message.data);
  EXPECT_EQ(pose.header.frame_id, "map");
  // Header stamps are simulation time, unlike the wall-clock log time.
  EXPECT_NEAR(toSeconds(pose.header.stamp), 924.102, 5e-4);
  EXPECT_EQ(pose.measurement.stamp, pose.header.stamp);
  // The recorded values: x 4.365196654, y 7.579351696, yaw 0.179605751 rad, cov_xx 0.028234069 m^2,
  // cov_xy 0.007358 m^2. Decoding is exact, so the tolerances only absorb the nine printed decimals.
  EXPECT_NEAR(pose.measurement.pose.position.x(), 4.365196654, 1e-9);
  EXPECT_NEAR(pose.measurement.pose.position.y(), 7.579351696, 1e-9);
  EXPECT_NEAR(rollPitchYaw(pose.measurement.pose.orientation).z(), 0.179605751, 1e-9);
  EXPECT_NEAR(pose.measurement.covariance(0, 0), 0.028234069, 1e-9);
  EXPECT_NEAR(pose.measurement.covariance(0, 1), 0.007358, 1e-6);
  // What a log summary rounds them to.
  EXPECT_NEAR(pose.measurement.pose.position.x(), 4.3652, 5e-5);
  EXPECT_NEAR(pose.measurement.pose.position.y(), 7.5794, 5e-5);
  EXPECT_NEAR(rollPitchYaw(pose.measurement.pose.orientation).z(), 0.1796, 5e-5);
  EXPECT_NEAR(pose.measurement.covariance(0, 0), 0.02823, 5e-6);
  // AMCL estimates x, y, yaw only: z, roll and pitch have zero variance in the message.
  EXPECT_EQ(pose.measurement.covariance(2, 2), 0.0);
  EXPECT_NEAR(pose.measurement.pose.orientation.norm(), 1.0, 1e-9);
  EXPECT_EQ(pose.measurement.covariance, pose.measurement.covariance.transpose());
}

TEST(McapReader, EveryOdometryAndAmclPoseMessageDecodes) {
  BagReader reader = BagReader::open(nav2Bag());
  BagMessage message;
  std::size_t odometry = 0, poses = 0;
  Stamp previous_odometry_stamp = 0;
  while (reader.next(message)) {
    if (message.topic == "/odom") {
      const Odometry decoded = decodeOdometry(message.data);
      EXPECT_EQ(decoded.header.frame_id, "odom");
      EXPECT_EQ(decoded.child_frame_id, "base_link");
      EXPECT_GE(decoded.header.stamp, previous_odometry_stamp);
      previous_odometry_stamp = decoded.header.stamp;
      ++odometry;
    } else if (message.topic == "/amcl_pose") {
      EXPECT_EQ(decodePoseWithCovarianceStamped(message.data).header.frame_id, "map");
      ++poses;
    }
  }
  EXPECT_EQ(odometry, 2639u);
  EXPECT_EQ(poses, 135u);
  EXPECT_NEAR(toSeconds(previous_odometry_stamp), 1025.496, 5e-4);
}

TEST(McapReader, UnknownMessageTypesAreListedNotFatal) {
  testing::ScratchDir dir;
  const std::string path = dir / "camera.mcap";
  const Bytes image = {0x00, 0x01, 0x00, 0x00, 1, 2, 3, 4};
  {
    McapWriter writer = McapWriter::create(path);
    writer.addTopic({"/camera", "sensor_msgs/msg/Image", "cdr", "", "", "", 0, {}});
    writer.addTopic({"/odom", "nav_msgs/msg/Odometry", "cdr", "", "", "", 0, {}});
    writer.write("/camera", 5, 4, image.data(), image.size());
    writer.close();
  }
  BagReader reader = BagReader::open(path);
  std::vector<std::string> unknown;
  for (const auto& topic : reader.topics()) {
    if (!messageKindOf(topic.type)) unknown.push_back(topic.name + " (" + topic.type + ")");
  }
  EXPECT_EQ(unknown, (std::vector<std::string>{"/camera (sensor_msgs/msg/Image)"}));
  BagMessage message;
  ASSERT_TRUE(reader.next(message));
  EXPECT_EQ(message.data, image);
  // Every type of the real recording is one coloc decodes (/tf and /tf_static too), and all is read.
  BagReader recording = BagReader::open(nav2Bag());
  for (const auto& topic : recording.topics()) EXPECT_TRUE(messageKindOf(topic.type).has_value()) << topic.name;
  std::size_t read = 0;
  while (recording.next(message)) ++read;
  EXPECT_EQ(read, 8197u);
}

TEST(McapReader, OpeningAMissingPathNamesIt) {
  const std::string message = testing::errorMessage([] { BagReader::open("/nonexistent/bag.mcap"); });
  EXPECT_NE(message.find("/nonexistent/bag.mcap: no such file or directory"), std::string::npos) << message;
}

}  // namespace
}  // namespace coloc::io
