#include "coloc/io/ros_messages.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "io_test_support.hpp"
#include "transform_stamped.hpp"

namespace coloc::io {
namespace {

using testing::errorMessage;

Matrix6d distinctEntries() {
  Matrix6d m;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) m(r, c) = 0.01 * (r * 6 + c) + 0.001;
  return m;
}

StampedPose samplePose(const std::string& frame = "map") {
  StampedPose m;
  m.header = {fromRosTime(924, 102000000u), frame};
  m.measurement.stamp = m.header.stamp;
  m.measurement.pose.position = {4.3652, 7.5794, -0.25};
  m.measurement.pose.orientation = quaternionFromRollPitchYaw(0.01, -0.02, 0.1796);
  m.measurement.covariance = distinctEntries();
  return m;
}

StampedTwist sampleTwist() {
  StampedTwist m;
  m.header = {fromRosTime(-3, 999999999u), "base_link"};
  m.measurement.stamp = m.header.stamp;
  m.measurement.linear = {0.5, -0.01, 0.0};
  m.measurement.angular = {0.0, 0.001, -0.3};
  m.measurement.covariance = distinctEntries() * 2.0;
  return m;
}

Odometry sampleOdometry() {
  Odometry m;
  m.header = {fromRosTime(928, 800000000u), "odom"};
  m.child_frame_id = "base_link";
  m.pose = samplePose().measurement;
  m.pose.stamp = m.header.stamp;
  m.twist = sampleTwist().measurement;
  m.twist.stamp = m.header.stamp;
  return m;
}

Imu sampleImu() {
  Imu m;
  m.header = {fromRosTime(1700000000, 5u), "imu_link"};
  m.orientation = quaternionFromRollPitchYaw(0.1, 0.2, 0.3);
  m.orientation_covariance << 1, 2, 3, 4, 5, 6, 7, 8, 9;
  m.angular_velocity = {0.01, 0.02, 0.03};
  m.angular_velocity_covariance = Eigen::Matrix3d::Identity() * 1e-4;
  m.angular_velocity_covariance(0, 2) = 7e-6;
  m.linear_acceleration = {0.1, 0.2, 9.81};
  m.linear_acceleration_covariance(0, 0) = -1.0;  // "no estimate"
  return m;
}

PointCloud2 sampleCloud() {
  PointCloud2 m;
  m.header = {fromRosTime(12, 345u), "lidar"};
  m.height = 1;
  m.width = 3;
  m.fields = {{"x", 0, PointField::kFloat32, 1}, {"y", 4, PointField::kFloat32, 1},
              {"z", 8, PointField::kFloat32, 1}, {"intensity", 12, PointField::kUint8, 1}};
  m.point_step = 13;
  m.row_step = 39;
  for (int i = 0; i < 39; ++i) m.data.push_back(static_cast<std::uint8_t>(i * 7));
  m.is_dense = true;
  return m;
}

void expectSamePose(const Pose& a, const Pose& b) {
  EXPECT_EQ(a.position, b.position);
  EXPECT_EQ(a.orientation.coeffs(), b.orientation.coeffs());
}

TEST(RosMessages, PoseWithCovarianceStampedWithFrameMapEncodesTo364Bytes) {
  const Bytes bytes = encodePoseWithCovarianceStamped(samplePose("map"));
  ASSERT_EQ(bytes.size(), 364u);
  EXPECT_EQ(bytes[0], 0x00);
  EXPECT_EQ(bytes[1], 0x01);
  EXPECT_EQ(bytes[2], 0x00);
  EXPECT_EQ(bytes[3], 0x00);
}

TEST(RosMessages, CovarianceIsRowMajorOnTheWire) {
  const StampedPose pose = samplePose("map");
  const Bytes bytes = encodePoseWithCovarianceStamped(pose);
  // Body: sec, nanosec, length, "map\0" = 16 bytes, then 7 pose doubles; the covariance follows.
  const std::size_t covariance_start = 4 + 16 + 7 * 8;
  double second_on_wire = 0.0;
  std::memcpy(&second_on_wire, bytes.data() + covariance_start + 8, 8);
  EXPECT_EQ(second_on_wire, pose.measurement.covariance(0, 1));
}

TEST(RosMessages, PoseWithCovarianceStampedRoundTrips) {
  const StampedPose in = samplePose("map");
  const StampedPose out = decodePoseWithCovarianceStamped(encodePoseWithCovarianceStamped(in));
  EXPECT_EQ(out.header.stamp, in.header.stamp);
  EXPECT_EQ(out.header.frame_id, "map");
  EXPECT_EQ(out.measurement.stamp, in.header.stamp);
  expectSamePose(out.measurement.pose, in.measurement.pose);
  EXPECT_EQ(out.measurement.covariance, in.measurement.covariance);
}

TEST(RosMessages, PoseStampedRoundTripsAndDecodesAsNotMeasured) {
  const StampedPose in = samplePose("earth");
  const StampedPose out = decodePoseStamped(encodePoseStamped(in));
  EXPECT_EQ(out.header.stamp, in.header.stamp);
  EXPECT_EQ(out.header.frame_id, "earth");
  EXPECT_EQ(out.measurement.stamp, in.header.stamp);
  expectSamePose(out.measurement.pose, in.measurement.pose);
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) EXPECT_EQ(out.measurement.covariance(r, c), r == c ? kInfinity : 0.0);
}

TEST(RosMessages, TwistWithCovarianceStampedRoundTripsWithNegativeStamp) {
  const StampedTwist in = sampleTwist();
  const StampedTwist out = decodeTwistWithCovarianceStamped(encodeTwistWithCovarianceStamped(in));
  EXPECT_EQ(out.header.stamp, in.header.stamp);
  EXPECT_EQ(out.header.frame_id, "base_link");
  EXPECT_EQ(out.measurement.linear, in.measurement.linear);
  EXPECT_EQ(out.measurement.angular, in.measurement.angular);
  EXPECT_EQ(out.measurement.covariance, in.measurement.covariance);
}

TEST(RosMessages, TwistStampedRoundTripsAndDecodesAsNotMeasured) {
  const StampedTwist in = sampleTwist();
  const StampedTwist out = decodeTwistStamped(encodeTwistStamped(in));
  EXPECT_EQ(out.measurement.stamp, in.header.stamp);
  EXPECT_EQ(out.measurement.linear, in.measurement.linear);
  EXPECT_EQ(out.measurement.angular, in.measurement.angular);
  EXPECT_TRUE(std::isinf(out.measurement.covariance(5, 5)));
  EXPECT_EQ(out.measurement.covariance(0, 5), 0.0);
}

TEST(RosMessages, OdometryRoundTrips) {
  const Odometry in = sampleOdometry();
  const Bytes bytes = encodeOdometry(in);
  EXPECT_EQ(bytes.size(), 724u);  // as the recorded /odom messages with frames odom and base_link
  const Odometry out = decodeOdometry(bytes);
  EXPECT_EQ(out.header.frame_id, "odom");
  EXPECT_EQ(out.child_frame_id, "base_link");
  EXPECT_EQ(out.pose.stamp, in.header.stamp);
  EXPECT_EQ(out.twist.stamp, in.header.stamp);
  expectSamePose(out.pose.pose, in.pose.pose);
  EXPECT_EQ(out.pose.covariance, in.pose.covariance);
  EXPECT_EQ(out.twist.linear, in.twist.linear);
  EXPECT_EQ(out.twist.angular, in.twist.angular);
  EXPECT_EQ(out.twist.covariance, in.twist.covariance);
}

TEST(RosMessages, ImuRoundTrips) {
  const Imu in = sampleImu();
  const Imu out = decodeImu(encodeImu(in));
  EXPECT_EQ(out.header.stamp, in.header.stamp);
  EXPECT_EQ(out.header.frame_id, "imu_link");
  EXPECT_EQ(out.orientation.coeffs(), in.orientation.coeffs());
  EXPECT_EQ(out.orientation_covariance, in.orientation_covariance);
  EXPECT_EQ(out.angular_velocity, in.angular_velocity);
  EXPECT_EQ(out.angular_velocity_covariance, in.angular_velocity_covariance);
  EXPECT_EQ(out.linear_acceleration, in.linear_acceleration);
  EXPECT_EQ(out.linear_acceleration_covariance, in.linear_acceleration_covariance);
}

TEST(RosMessages, PointCloud2RoundTrips) {
  const PointCloud2 in = sampleCloud();
  const PointCloud2 out = decodePointCloud2(encodePointCloud2(in));
  EXPECT_EQ(out.header.stamp, in.header.stamp);
  EXPECT_EQ(out.header.frame_id, "lidar");
  EXPECT_EQ(out.height, 1u);
  EXPECT_EQ(out.width, 3u);
  ASSERT_EQ(out.fields.size(), 4u);
  EXPECT_EQ(out.fields[3].name, "intensity");
  EXPECT_EQ(out.fields[3].offset, 12u);
  EXPECT_EQ(out.fields[3].datatype, PointField::kUint8);
  EXPECT_EQ(out.fields[3].count, 1u);
  EXPECT_FALSE(out.is_bigendian);
  EXPECT_EQ(out.point_step, 13u);
  EXPECT_EQ(out.row_step, 39u);
  EXPECT_EQ(out.data, in.data);
  EXPECT_TRUE(out.is_dense);
}

TEST(RosMessages, EmptyPointCloudAndEmptyFrameRoundTrip) {
  PointCloud2 in;
  in.header.frame_id = "";
  const PointCloud2 out = decodePointCloud2(encodePointCloud2(in));
  EXPECT_TRUE(out.fields.empty());
  EXPECT_TRUE(out.data.empty());
  EXPECT_EQ(out.header.frame_id, "");
}

TEST(RosMessages, Utf8FrameIdsRoundTrip) {
  const StampedPose out = decodePoseWithCovarianceStamped(encodePoseWithCovarianceStamped(samplePose("карта/地図")));
  EXPECT_EQ(out.header.frame_id, "карта/地図");
}

/// PoseStamped bytes written by hand in big-endian XCDR1, as a big-endian DDS writer sends them.
Bytes bigEndianPoseStamped() {
  Bytes b{0x00, 0x00, 0x00, 0x00};
  auto u32 = [&](std::uint32_t v) {
    for (int s = 24; s >= 0; s -= 8) b.push_back(static_cast<std::uint8_t>(v >> s));
  };
  auto f64 = [&](double d) {
    std::uint64_t v;
    std::memcpy(&v, &d, 8);
    for (int s = 56; s >= 0; s -= 8) b.push_back(static_cast<std::uint8_t>(v >> s));
  };
  u32(100);          // sec
  u32(250000000u);   // nanosec
  u32(4);            // "map" + NUL
  for (char c : std::string("map")) b.push_back(static_cast<std::uint8_t>(c));
  b.push_back(0);
  // body offset 16: already 8-aligned for the doubles
  for (double d : {1.5, -2.0, 0.25, 0.0, 0.0, 0.6, 0.8}) f64(d);
  return b;
}

TEST(RosMessages, DecodesBigEndianMessages) {
  const StampedPose out = decodePoseStamped(bigEndianPoseStamped());
  EXPECT_EQ(out.header.stamp, 100'250'000'000LL);
  EXPECT_EQ(out.header.frame_id, "map");
  EXPECT_EQ(out.measurement.pose.position, Eigen::Vector3d(1.5, -2.0, 0.25));
  EXPECT_EQ(out.measurement.pose.orientation.z(), 0.6);
  EXPECT_EQ(out.measurement.pose.orientation.w(), 0.8);
}

// A transform chain as a static broadcaster sends it: frames, translation and the rotation as sent.
TEST(RosMessages, TFMessageRoundTripsEveryTransformInOrder) {
  TFMessage in;
  in.transforms.push_back(coloc::testing::transformStamped(fromRosTime(100, 5), "base_link", "sensor_kit", {0.9, -0.1, 2.0}, Eigen::Quaterniond(0.9999, 0.01, 0.0, 0.005)));
  in.transforms.push_back(coloc::testing::transformStamped(fromRosTime(100, 5), "sensor_kit", "velodyne_top", {0.0, 0.0, 0.1}, Eigen::Quaterniond(0.0, 0.0, 0.0, 1.0)));
  const TFMessage out = decodeTFMessage(encodeTFMessage(in));
  ASSERT_EQ(out.transforms.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(out.transforms[i].header.stamp, in.transforms[i].header.stamp);
    EXPECT_EQ(out.transforms[i].header.frame_id, in.transforms[i].header.frame_id);
    EXPECT_EQ(out.transforms[i].child_frame_id, in.transforms[i].child_frame_id);
    EXPECT_EQ(out.transforms[i].translation, in.transforms[i].translation);
    EXPECT_EQ(out.transforms[i].rotation.coeffs(), in.transforms[i].rotation.coeffs());  // not normalised
  }
  EXPECT_TRUE(decodeTFMessage(encodeTFMessage(TFMessage{})).transforms.empty());
}

TEST(RosMessages, DecodeMessageDispatchesOnKind) {
  const RosMessage message = decodeMessage(MessageKind::kOdometry, encodeOdometry(sampleOdometry()));
  ASSERT_TRUE(std::holds_alternative<Odometry>(message));
  EXPECT_EQ(std::get<Odometry>(message).child_frame_id, "base_link");
}

TEST(RosMessages, TypeNamesMapToKindsAndUnknownTypesToNothing) {
  EXPECT_EQ(messageKindOf("geometry_msgs/msg/PoseWithCovarianceStamped"), MessageKind::kPoseWithCovarianceStamped);
  EXPECT_EQ(messageKindOf("nav_msgs/msg/Odometry"), MessageKind::kOdometry);
  EXPECT_EQ(messageKindOf("sensor_msgs/msg/PointCloud2"), MessageKind::kPointCloud2);
  EXPECT_EQ(messageKindOf("tf2_msgs/msg/TFMessage"), MessageKind::kTFMessage);
  EXPECT_FALSE(messageKindOf("sensor_msgs/msg/Image").has_value());
  EXPECT_FALSE(messageKindOf("geometry_msgs/PoseStamped").has_value());  // ROS 1 spelling
  for (const auto name : supportedRosTypes()) EXPECT_EQ(rosTypeName(*messageKindOf(name)), name);
  EXPECT_EQ(supportedRosTypes().size(), static_cast<std::size_t>(kMessageKindCount));
}

TEST(RosMessages, MessageDefinitionsListDependenciesOnce) {
  const std::string text = rosMessageDefinition("geometry_msgs/msg/PoseWithCovarianceStamped");
  EXPECT_EQ(text.rfind("std_msgs/Header header\nPoseWithCovariance pose\n", 0), 0u);
  for (const char* dependency : {"MSG: std_msgs/Header\n", "MSG: builtin_interfaces/Time\n",
                                 "MSG: geometry_msgs/PoseWithCovariance\n", "MSG: geometry_msgs/Pose\n",
                                 "MSG: geometry_msgs/Point\n", "MSG: geometry_msgs/Quaternion\n"}) {
    const auto first = text.find(dependency);
    EXPECT_NE(first, std::string::npos) << dependency;
    EXPECT_EQ(text.find(dependency, first + 1), std::string::npos) << dependency;
  }
  EXPECT_NE(text.find(std::string(80, '=') + "\nMSG: "), std::string::npos);
  EXPECT_NE(rosMessageDefinition("sensor_msgs/msg/PointCloud2").find("uint8 FLOAT32=7"), std::string::npos);
  EXPECT_EQ(rosMessageDefinition("sensor_msgs/msg/Image"), "");
  EXPECT_EQ(rosMessageDefinition("tf2_msgs/msg/TFMessage").rfind("geometry_msgs/TransformStamped[] transforms\n", 0), 0u);
}

TEST(RosMessages, EncodingRejectsStampsOutsideRosTime) {
  StampedPose pose = samplePose();
  pose.header.stamp = (std::int64_t{INT32_MAX} + 1) * kNanosPerSecond;
  const std::string message = errorMessage([&] { encodePoseWithCovarianceStamped(pose); });
  EXPECT_NE(message.find("geometry_msgs/msg/PoseWithCovarianceStamped"), std::string::npos) << message;
  EXPECT_NE(message.find("int32"), std::string::npos) << message;
}

TEST(RosMessages, EncodingRejectsStringsThatAreNotUtf8OrHoldNul) {
  StampedPose pose = samplePose(std::string("ma\0p", 4));
  EXPECT_NE(errorMessage([&] { encodePoseStamped(pose); }).find("NUL"), std::string::npos);
  Odometry odometry = sampleOdometry();
  odometry.child_frame_id = "\xff\xfe";
  const std::string message = errorMessage([&] { encodeOdometry(odometry); });
  EXPECT_NE(message.find("nav_msgs/msg/Odometry: child_frame_id is not valid UTF-8"), std::string::npos) << message;
}

}  // namespace
}  // namespace coloc::io
