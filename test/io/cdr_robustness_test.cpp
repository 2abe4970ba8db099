// Bad CDR input: every failure is a coloc::Error naming the ROS type and the reason, never a crash,
// a huge allocation or another exception type.
#include <gtest/gtest.h>

#include <cstring>
#include <functional>

#include "coloc/io/ros_messages.hpp"
#include "io_test_support.hpp"
#include "transform_stamped.hpp"

namespace coloc::io {
namespace {

using testing::errorMessage;

struct Sample {
  MessageKind kind;
  Bytes bytes;
};

std::vector<Sample> samples() {
  StampedPose pose;
  pose.header = {fromRosTime(5, 6), "map"};
  StampedTwist twist;
  twist.header = {fromRosTime(7, 8), "base_link"};
  Odometry odometry;
  odometry.header = {fromRosTime(9, 10), "odom"};
  odometry.child_frame_id = "base_link";
  Imu imu;
  imu.header = {fromRosTime(11, 12), "imu"};
  PointCloud2 cloud;
  cloud.header = {fromRosTime(13, 14), "lidar"};
  cloud.width = 2;
  cloud.height = 1;
  cloud.fields = {{"x", 0, PointField::kFloat32, 1}, {"i", 4, PointField::kUint8, 1}};
  cloud.point_step = 5;
  cloud.row_step = 10;
  cloud.data.assign(10, 0xAB);
  TFMessage tf;
  tf.transforms.push_back(coloc::testing::transformStamped(fromRosTime(15, 16), "base_link", "lidar", {1.0, 0.0, 1.8}, Eigen::Quaterniond::Identity()));
  return {{MessageKind::kPoseWithCovarianceStamped, encodePoseWithCovarianceStamped(pose)},
          {MessageKind::kPoseStamped, encodePoseStamped(pose)},
          {MessageKind::kTwistWithCovarianceStamped, encodeTwistWithCovarianceStamped(twist)},
          {MessageKind::kTwistStamped, encodeTwistStamped(twist)},
          {MessageKind::kOdometry, encodeOdometry(odometry)},
          {MessageKind::kImu, encodeImu(imu)},
          {MessageKind::kPointCloud2, encodePointCloud2(cloud)},
          {MessageKind::kTFMessage, encodeTFMessage(tf)}};
}

std::string decodeError(MessageKind kind, const Bytes& bytes) {
  return errorMessage([&] { decodeMessage(kind, bytes); });
}

void putU32(Bytes& bytes, std::size_t offset, std::uint32_t value) { std::memcpy(bytes.data() + offset, &value, 4); }

TEST(CdrRobustness, EveryTruncationThrowsAnErrorNamingTheType) {
  for (const auto& sample : samples()) {
    const std::string type(rosTypeName(sample.kind));
    for (std::size_t size = 0; size < sample.bytes.size(); ++size) {
      const Bytes cut(sample.bytes.begin(), sample.bytes.begin() + static_cast<std::ptrdiff_t>(size));
      const std::string message = decodeError(sample.kind, cut);
      ASSERT_EQ(message.rfind(type + ": ", 0), 0u) << "size " << size << ": " << message;
      ASSERT_NE(message.find("truncated"), std::string::npos) << "size " << size << ": " << message;
    }
  }
}

TEST(CdrRobustness, XcdrVersionTwoAndUnknownEncapsulationsAreRejected) {
  Bytes bytes = samples()[0].bytes;
  bytes[1] = 0x07;
  EXPECT_NE(decodeError(MessageKind::kPoseWithCovarianceStamped, bytes).find("XCDR2"), std::string::npos);
  bytes[1] = 0x03;  // PL_CDR_LE
  EXPECT_NE(decodeError(MessageKind::kPoseWithCovarianceStamped, bytes).find("unsupported encapsulation 0x0003"),
            std::string::npos);
  bytes[0] = 0x01, bytes[1] = 0x01;
  EXPECT_NE(decodeError(MessageKind::kPoseWithCovarianceStamped, bytes).find("unsupported encapsulation 0x0101"),
            std::string::npos);
}

TEST(CdrRobustness, HugeDataLengthIsRejectedBeforeAnyAllocation) {
  // A PointCloud2 whose data sequence claims 4e9 bytes while about 100 are present.
  PointCloud2 cloud;
  cloud.header.frame_id = "lidar";
  cloud.data.assign(40, 1);
  Bytes bytes = encodePointCloud2(cloud);
  // Body: sec, nanosec, length, "lidar\0" padded (20), height, width, fields count, is_bigendian
  // padded to 4 (36), point_step, row_step: the data length is at body offset 44.
  const std::size_t data_length_offset = 4 + 44;
  std::uint32_t stored = 0;
  std::memcpy(&stored, bytes.data() + data_length_offset, 4);
  ASSERT_EQ(stored, 40u);
  putU32(bytes, data_length_offset, 4'000'000'000u);
  const std::string message = decodeError(MessageKind::kPointCloud2, bytes);
  EXPECT_NE(message.find("sensor_msgs/msg/PointCloud2: data: sequence length 4000000000"), std::string::npos)
      << message;
}

TEST(CdrRobustness, HugeFieldCountIsRejected) {
  Bytes bytes = samples()[6].bytes;  // PointCloud2 with frame "lidar"
  putU32(bytes, 4 + 28, 0x7FFFFFFFu);  // fields count after sec, nanosec, frame (20), height, width
  const std::string message = decodeError(MessageKind::kPointCloud2, bytes);
  EXPECT_NE(message.find("fields: sequence length 2147483647"), std::string::npos) << message;
}

TEST(CdrRobustness, HugeTransformCountIsRejected) {
  Bytes bytes = samples()[7].bytes;  // TFMessage with one transform
  putU32(bytes, 4, 0x7FFFFFFFu);     // the transforms count opens the body
  const std::string message = decodeError(MessageKind::kTFMessage, bytes);
  EXPECT_NE(message.find("tf2_msgs/msg/TFMessage: transforms: sequence length 2147483647"), std::string::npos) << message;
}

TEST(CdrRobustness, HugeStringLengthIsRejected) {
  Bytes bytes = samples()[0].bytes;
  putU32(bytes, 4 + 8, 0xFFFFFFF0u);  // frame_id length
  const std::string message = decodeError(MessageKind::kPoseWithCovarianceStamped, bytes);
  EXPECT_NE(message.find("header.frame_id: string length 4294967280"), std::string::npos) << message;
}

TEST(CdrRobustness, FrameIdThatIsNotUtf8IsRejected) {
  Bytes bytes = samples()[0].bytes;  // frame "map" at body offset 12
  bytes[4 + 12] = 0xFF, bytes[4 + 13] = 0xFE;
  const std::string message = decodeError(MessageKind::kPoseWithCovarianceStamped, bytes);
  EXPECT_NE(message.find("header.frame_id: string at body offset 12 is not valid UTF-8"), std::string::npos)
      << message;
}

TEST(CdrRobustness, StringWithoutTerminatingNulIsRejected) {
  Bytes bytes = samples()[0].bytes;
  bytes[4 + 15] = 'x';  // the NUL after "map"
  EXPECT_NE(decodeError(MessageKind::kPoseWithCovarianceStamped, bytes).find("not NUL-terminated"),
            std::string::npos);
}

TEST(CdrRobustness, NanosecondsOfOneSecondOrMoreAreRejected) {
  Bytes bytes = samples()[0].bytes;
  putU32(bytes, 4 + 4, 1'000'000'000u);
  EXPECT_NE(decodeError(MessageKind::kPoseWithCovarianceStamped, bytes).find("nanosec 1000000000"),
            std::string::npos);
}

TEST(CdrRobustness, BooleanOtherThanZeroOrOneIsRejected) {
  Bytes bytes = samples()[6].bytes;
  bytes.back() = 2;  // is_dense
  EXPECT_NE(decodeError(MessageKind::kPointCloud2, bytes).find("is_dense: boolean byte 2"), std::string::npos);
}

TEST(CdrRobustness, BytesOfAnotherTypeAreRejected) {
  // PoseWithCovarianceStamped bytes read as PoseStamped leave the 288 covariance bytes over.
  const std::string message = decodeError(MessageKind::kPoseStamped, samples()[0].bytes);
  EXPECT_NE(message.find("geometry_msgs/msg/PoseStamped: 288 unexpected bytes"), std::string::npos) << message;
}

TEST(CdrRobustness, AlignmentPaddingAfterTheMessageIsAccepted) {
  Bytes bytes = samples()[1].bytes;
  bytes.insert(bytes.end(), {0, 0, 0});
  EXPECT_NO_THROW(decodePoseStamped(bytes));
}

TEST(CdrRobustness, CorruptedBytesNeverEscapeAsAnythingButColocError) {
  // Every byte of every sample set to a few telling values: decoding succeeds or throws coloc::Error.
  for (const auto& sample : samples()) {
    for (std::size_t i = 0; i < sample.bytes.size(); ++i) {
      for (const std::uint8_t value : {0x00, 0x01, 0x7F, 0x80, 0xFF}) {
        Bytes bytes = sample.bytes;
        bytes[i] = value;
        try {
          decodeMessage(sample.kind, bytes);
        } catch (const Error&) {
        } catch (const std::exception& e) {
          FAIL() << rosTypeName(sample.kind) << " byte " << i << " = " << int(value) << ": " << e.what();
        }
      }
    }
  }
}

}  // namespace
}  // namespace coloc::io
