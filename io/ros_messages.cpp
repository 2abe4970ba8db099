// Codecs of the ROS 2 messages: layout walks, conversions between the fastddsgen types and coloc's
// plain structs, and the decode/encode entry points.
#include "coloc/io/ros_messages.hpp"

#include <array>
#include <cstring>
#include <limits>

#include "Imu.h"
#include "Odometry.h"
#include "PointCloud2.h"
#include "PoseStamped.h"
#include "PoseWithCovarianceStamped.h"
#include "TFMessage.h"
#include "TwistStamped.h"
#include "TwistWithCovarianceStamped.h"
#include "cdr_codec.hpp"
#include "coloc/core/error.hpp"
#include "coloc/core/utf8.hpp"

namespace coloc::io {
namespace {

using detail::CdrChecker;
using detail::CdrFormatError;

constexpr std::string_view kPoseWithCovarianceStampedType = "geometry_msgs/msg/PoseWithCovarianceStamped";
constexpr std::string_view kPoseStampedType = "geometry_msgs/msg/PoseStamped";
constexpr std::string_view kTwistWithCovarianceStampedType = "geometry_msgs/msg/TwistWithCovarianceStamped";
constexpr std::string_view kTwistStampedType = "geometry_msgs/msg/TwistStamped";
constexpr std::string_view kOdometryType = "nav_msgs/msg/Odometry";
constexpr std::string_view kImuType = "sensor_msgs/msg/Imu";
constexpr std::string_view kPointCloud2Type = "sensor_msgs/msg/PointCloud2";
constexpr std::string_view kTFMessageType = "tf2_msgs/msg/TFMessage";

constexpr std::array<std::pair<MessageKind, std::string_view>, kMessageKindCount> kKinds{{
    {MessageKind::kPoseWithCovarianceStamped, kPoseWithCovarianceStampedType},
    {MessageKind::kPoseStamped, kPoseStampedType},
    {MessageKind::kTwistWithCovarianceStamped, kTwistWithCovarianceStampedType},
    {MessageKind::kTwistStamped, kTwistStampedType},
    {MessageKind::kOdometry, kOdometryType},
    {MessageKind::kImu, kImuType},
    {MessageKind::kPointCloud2, kPointCloud2Type},
    {MessageKind::kTFMessage, kTFMessageType},
}};

// ---- layout walks (field names as a user would look them up in the .msg files) ----

// A header's field names as errors give them: at the top of a message, or inside a sequence.
struct HeaderFields {
  const char* sec;
  const char* nanosec;
  const char* frame_id;
};
constexpr HeaderFields kHeaderFields{"header.stamp.sec", "header.stamp.nanosec", "header.frame_id"};

void checkHeader(CdrChecker& c, const HeaderFields& f = kHeaderFields) {
  c.primitive(4, f.sec);
  const std::uint32_t nanosec = c.uint32(f.nanosec);
  if (nanosec >= kNanosPerSecond) {
    throw CdrFormatError(std::string(f.nanosec) + " " + std::to_string(nanosec) + " is not below 1e9");
  }
  c.string(f.frame_id);
}

void checkPoseWithCovarianceStamped(CdrChecker& c) {
  checkHeader(c);
  c.primitives(8, 7 + 36, "pose");
}

void checkPoseStamped(CdrChecker& c) {
  checkHeader(c);
  c.primitives(8, 7, "pose");
}

void checkTwistWithCovarianceStamped(CdrChecker& c) {
  checkHeader(c);
  c.primitives(8, 6 + 36, "twist");
}

void checkTwistStamped(CdrChecker& c) {
  checkHeader(c);
  c.primitives(8, 6, "twist");
}

void checkOdometry(CdrChecker& c) {
  checkHeader(c);
  c.string("child_frame_id");
  c.primitives(8, 7 + 36, "pose");
  c.primitives(8, 6 + 36, "twist");
}

void checkImu(CdrChecker& c) {
  checkHeader(c);
  c.primitives(8, 4, "orientation");
  c.primitives(8, 9, "orientation_covariance");
  c.primitives(8, 3, "angular_velocity");
  c.primitives(8, 9, "angular_velocity_covariance");
  c.primitives(8, 3, "linear_acceleration");
  c.primitives(8, 9, "linear_acceleration_covariance");
}

void checkPointCloud2(CdrChecker& c) {
  checkHeader(c);
  c.primitive(4, "height");
  c.primitive(4, "width");
  // Smallest PointField: name length + NUL, offset, datatype, count, without padding.
  const std::uint32_t field_count = c.sequenceLength(4 + 1 + 4 + 1 + 4, "fields");
  for (std::uint32_t i = 0; i < field_count; ++i) {
    c.string("fields[].name");
    c.primitive(4, "fields[].offset");
    c.primitive(1, "fields[].datatype");
    c.primitive(4, "fields[].count");
  }
  c.boolean("is_bigendian");
  c.primitive(4, "point_step");
  c.primitive(4, "row_step");
  const std::uint32_t data_size = c.sequenceLength(1, "data");
  c.primitives(1, data_size, "data");
  c.boolean("is_dense");
}

void checkTFMessage(CdrChecker& c) {
  // Smallest TransformStamped: stamp, two empty strings (length + NUL), 7 doubles, without padding.
  const std::uint32_t count = c.sequenceLength(8 + 5 + 5 + 7 * 8, "transforms");
  for (std::uint32_t i = 0; i < count; ++i) {
    checkHeader(c, {"transforms[].header.stamp.sec", "transforms[].header.stamp.nanosec", "transforms[].header.frame_id"});
    c.string("transforms[].child_frame_id");
    c.primitives(8, 7, "transforms[].transform");
  }
}

// ---- generated types -> coloc ----

Header fromRos(const std_msgs::msg::Header& h) {
  return {fromRosTime(h.stamp().sec(), h.stamp().nanosec()), h.frame_id()};
}

Pose fromRos(const geometry_msgs::msg::Pose& p) {
  Pose pose;
  pose.position = {p.position().x(), p.position().y(), p.position().z()};
  const auto& q = p.orientation();
  pose.orientation = Eigen::Quaterniond(q.w(), q.x(), q.y(), q.z());
  return pose;
}

Eigen::Vector3d fromRos(const geometry_msgs::msg::Vector3& v) { return {v.x(), v.y(), v.z()}; }

Eigen::Quaterniond fromRos(const geometry_msgs::msg::Quaternion& q) { return {q.w(), q.x(), q.y(), q.z()}; }

template <int N>
Eigen::Matrix<double, N, N> fromRowMajor(const std::array<double, N * N>& values) {
  return Eigen::Map<const Eigen::Matrix<double, N, N, Eigen::RowMajor>>(values.data());
}

/// "Not measured": what a message without covariance says about each component.
Matrix6d unmeasuredCovariance() {
  Matrix6d covariance = Matrix6d::Zero();
  covariance.diagonal().setConstant(kInfinity);
  return covariance;
}

PoseMeasurement poseMeasurement(Stamp stamp, const geometry_msgs::msg::PoseWithCovariance& p) {
  PoseMeasurement m;
  m.stamp = stamp;
  m.pose = fromRos(p.pose());
  m.covariance = fromRowMajor<6>(p.covariance());
  return m;
}

TwistMeasurement twistMeasurement(Stamp stamp, const geometry_msgs::msg::Twist& t, const Matrix6d& covariance) {
  TwistMeasurement m;
  m.stamp = stamp;
  m.linear = fromRos(t.linear());
  m.angular = fromRos(t.angular());
  m.covariance = covariance;
  return m;
}

// ---- coloc -> generated types ----

void checkEncodableString(const std::string& text, const char* field, std::string_view type) {
  if (text.find('\0') != std::string::npos) {
    detail::throwCodecError(type, std::string(field) + " contains a NUL byte");
  }
  if (!isValidUtf8(text.data(), text.size())) {
    detail::throwCodecError(type, std::string(field) + " is not valid UTF-8");
  }
}

std_msgs::msg::Header toRos(const Header& header, std::string_view type) {
  const RosTime time = toRosTime(header.stamp);
  if (!time.fits) {
    detail::throwCodecError(type, "header stamp " + formatSeconds(header.stamp) +
                                      " s does not fit builtin_interfaces/Time (int32 seconds)");
  }
  checkEncodableString(header.frame_id, "header.frame_id", type);
  std_msgs::msg::Header out;
  out.stamp().sec(time.sec);
  out.stamp().nanosec(time.nanosec);
  out.frame_id(header.frame_id);
  return out;
}

geometry_msgs::msg::Quaternion toRos(const Eigen::Quaterniond& q) {
  geometry_msgs::msg::Quaternion out;
  out.x(q.x());
  out.y(q.y());
  out.z(q.z());
  out.w(q.w());
  return out;
}

geometry_msgs::msg::Vector3 toRosVector(const Eigen::Vector3d& v) {
  geometry_msgs::msg::Vector3 out;
  out.x(v.x());
  out.y(v.y());
  out.z(v.z());
  return out;
}

geometry_msgs::msg::Pose toRos(const Pose& pose) {
  geometry_msgs::msg::Pose out;
  out.position().x(pose.position.x());
  out.position().y(pose.position.y());
  out.position().z(pose.position.z());
  out.orientation(toRos(pose.orientation));
  return out;
}

geometry_msgs::msg::Twist toRosTwist(const TwistMeasurement& m) {
  geometry_msgs::msg::Twist out;
  out.linear(toRosVector(m.linear));
  out.angular(toRosVector(m.angular));
  return out;
}

template <int N>
std::array<double, N * N> toRowMajor(const Eigen::Matrix<double, N, N>& m) {
  std::array<double, N * N> values;
  Eigen::Map<Eigen::Matrix<double, N, N, Eigen::RowMajor>>(values.data()) = m;
  return values;
}

geometry_msgs::msg::PoseWithCovariance toRos(const PoseMeasurement& m) {
  geometry_msgs::msg::PoseWithCovariance out;
  out.pose(toRos(m.pose));
  out.covariance(toRowMajor<6>(m.covariance));
  return out;
}

geometry_msgs::msg::TwistWithCovariance toRos(const TwistMeasurement& m) {
  geometry_msgs::msg::TwistWithCovariance out;
  out.twist(toRosTwist(m));
  out.covariance(toRowMajor<6>(m.covariance));
  return out;
}

template <class T>
std::uint32_t checkedSize(const T& container, const char* field, std::string_view type) {
  if (container.size() > UINT32_MAX) {
    detail::throwCodecError(type, std::string(field) + " has " + std::to_string(container.size()) +
                                      " elements, more than a CDR sequence holds");
  }
  return static_cast<std::uint32_t>(container.size());
}

}  // namespace

// ---- type registry ----

std::optional<MessageKind> messageKindOf(std::string_view ros_type) {
  for (const auto& [kind, name] : kKinds) {
    if (name == ros_type) return kind;
  }
  return std::nullopt;
}

std::string_view rosTypeName(MessageKind kind) {
  for (const auto& [k, name] : kKinds) {
    if (k == kind) return name;
  }
  throw Error("rosTypeName: invalid MessageKind " + std::to_string(static_cast<int>(kind)));
}

std::vector<std::string_view> supportedRosTypes() {
  std::vector<std::string_view> names;
  for (const auto& entry : kKinds) names.push_back(entry.second);
  return names;
}

// ---- decoders ----

StampedPose decodePoseWithCovarianceStamped(const std::uint8_t* data, std::size_t size) {
  const auto msg = detail::deserializeCdr<geometry_msgs::msg::PoseWithCovarianceStamped>(
      data, size, kPoseWithCovarianceStampedType, checkPoseWithCovarianceStamped);
  StampedPose out;
  out.header = fromRos(msg.header());
  out.measurement = poseMeasurement(out.header.stamp, msg.pose());
  return out;
}

StampedPose decodePoseStamped(const std::uint8_t* data, std::size_t size) {
  const auto msg = detail::deserializeCdr<geometry_msgs::msg::PoseStamped>(data, size, kPoseStampedType,
                                                                            checkPoseStamped);
  StampedPose out;
  out.header = fromRos(msg.header());
  out.measurement.stamp = out.header.stamp;
  out.measurement.pose = fromRos(msg.pose());
  out.measurement.covariance = unmeasuredCovariance();
  return out;
}

StampedTwist decodeTwistWithCovarianceStamped(const std::uint8_t* data, std::size_t size) {
  const auto msg = detail::deserializeCdr<geometry_msgs::msg::TwistWithCovarianceStamped>(
      data, size, kTwistWithCovarianceStampedType, checkTwistWithCovarianceStamped);
  StampedTwist out;
  out.header = fromRos(msg.header());
  out.measurement =
      twistMeasurement(out.header.stamp, msg.twist().twist(), fromRowMajor<6>(msg.twist().covariance()));
  return out;
}

StampedTwist decodeTwistStamped(const std::uint8_t* data, std::size_t size) {
  const auto msg = detail::deserializeCdr<geometry_msgs::msg::TwistStamped>(data, size, kTwistStampedType,
                                                                             checkTwistStamped);
  StampedTwist out;
  out.header = fromRos(msg.header());
  out.measurement = twistMeasurement(out.header.stamp, msg.twist(), unmeasuredCovariance());
  return out;
}

Odometry decodeOdometry(const std::uint8_t* data, std::size_t size) {
  const auto msg = detail::deserializeCdr<nav_msgs::msg::Odometry>(data, size, kOdometryType, checkOdometry);
  Odometry out;
  out.header = fromRos(msg.header());
  out.child_frame_id = msg.child_frame_id();
  out.pose = poseMeasurement(out.header.stamp, msg.pose());
  out.twist = twistMeasurement(out.header.stamp, msg.twist().twist(), fromRowMajor<6>(msg.twist().covariance()));
  return out;
}

Imu decodeImu(const std::uint8_t* data, std::size_t size) {
  const auto msg = detail::deserializeCdr<sensor_msgs::msg::Imu>(data, size, kImuType, checkImu);
  Imu out;
  out.header = fromRos(msg.header());
  out.orientation = fromRos(msg.orientation());
  out.orientation_covariance = fromRowMajor<3>(msg.orientation_covariance());
  out.angular_velocity = fromRos(msg.angular_velocity());
  out.angular_velocity_covariance = fromRowMajor<3>(msg.angular_velocity_covariance());
  out.linear_acceleration = fromRos(msg.linear_acceleration());
  out.linear_acceleration_covariance = fromRowMajor<3>(msg.linear_acceleration_covariance());
  return out;
}

PointCloud2 decodePointCloud2(const std::uint8_t* data, std::size_t size) {
  auto msg = detail::deserializeCdr<sensor_msgs::msg::PointCloud2>(data, size, kPointCloud2Type, checkPointCloud2);
  PointCloud2 out;
  out.header = fromRos(msg.header());
  out.height = msg.height();
  out.width = msg.width();
  out.fields.reserve(msg.fields().size());
  for (const auto& f : msg.fields()) out.fields.push_back({f.name(), f.offset(), f.datatype(), f.count()});
  out.is_bigendian = msg.is_bigendian();
  out.point_step = msg.point_step();
  out.row_step = msg.row_step();
  out.data = std::move(msg.data());
  out.is_dense = msg.is_dense();
  return out;
}

TFMessage decodeTFMessage(const std::uint8_t* data, std::size_t size) {
  const auto msg = detail::deserializeCdr<tf2_msgs::msg::TFMessage>(data, size, kTFMessageType, checkTFMessage);
  TFMessage out;
  out.transforms.reserve(msg.transforms().size());
  for (const auto& t : msg.transforms()) {
    TransformStamped transform;
    transform.header = fromRos(t.header());
    transform.child_frame_id = t.child_frame_id();
    transform.translation = fromRos(t.transform().translation());
    transform.rotation = fromRos(t.transform().rotation());
    out.transforms.push_back(std::move(transform));
  }
  return out;
}

RosMessage decodeMessage(MessageKind kind, const std::uint8_t* data, std::size_t size) {
  switch (kind) {
    case MessageKind::kPoseWithCovarianceStamped: return decodePoseWithCovarianceStamped(data, size);
    case MessageKind::kPoseStamped: return decodePoseStamped(data, size);
    case MessageKind::kTwistWithCovarianceStamped: return decodeTwistWithCovarianceStamped(data, size);
    case MessageKind::kTwistStamped: return decodeTwistStamped(data, size);
    case MessageKind::kOdometry: return decodeOdometry(data, size);
    case MessageKind::kImu: return decodeImu(data, size);
    case MessageKind::kPointCloud2: return decodePointCloud2(data, size);
    case MessageKind::kTFMessage: return decodeTFMessage(data, size);
  }
  throw Error("decodeMessage: invalid MessageKind " + std::to_string(static_cast<int>(kind)));
}

// ---- encoders ----

Bytes encodePoseWithCovarianceStamped(const StampedPose& message) {
  geometry_msgs::msg::PoseWithCovarianceStamped msg;
  msg.header(toRos(message.header, kPoseWithCovarianceStampedType));
  msg.pose(toRos(message.measurement));
  return detail::serializeCdr(msg, kPoseWithCovarianceStampedType);
}

Bytes encodePoseStamped(const StampedPose& message) {
  geometry_msgs::msg::PoseStamped msg;
  msg.header(toRos(message.header, kPoseStampedType));
  msg.pose(toRos(message.measurement.pose));
  return detail::serializeCdr(msg, kPoseStampedType);
}

Bytes encodeTwistWithCovarianceStamped(const StampedTwist& message) {
  geometry_msgs::msg::TwistWithCovarianceStamped msg;
  msg.header(toRos(message.header, kTwistWithCovarianceStampedType));
  msg.twist(toRos(message.measurement));
  return detail::serializeCdr(msg, kTwistWithCovarianceStampedType);
}

Bytes encodeTwistStamped(const StampedTwist& message) {
  geometry_msgs::msg::TwistStamped msg;
  msg.header(toRos(message.header, kTwistStampedType));
  msg.twist(toRosTwist(message.measurement));
  return detail::serializeCdr(msg, kTwistStampedType);
}

Bytes encodeOdometry(const Odometry& message) {
  nav_msgs::msg::Odometry msg;
  msg.header(toRos(message.header, kOdometryType));
  checkEncodableString(message.child_frame_id, "child_frame_id", kOdometryType);
  msg.child_frame_id(message.child_frame_id);
  msg.pose(toRos(message.pose));
  msg.twist(toRos(message.twist));
  return detail::serializeCdr(msg, kOdometryType);
}

Bytes encodeImu(const Imu& message) {
  sensor_msgs::msg::Imu msg;
  msg.header(toRos(message.header, kImuType));
  msg.orientation(toRos(message.orientation));
  msg.orientation_covariance(toRowMajor<3>(message.orientation_covariance));
  msg.angular_velocity(toRosVector(message.angular_velocity));
  msg.angular_velocity_covariance(toRowMajor<3>(message.angular_velocity_covariance));
  msg.linear_acceleration(toRosVector(message.linear_acceleration));
  msg.linear_acceleration_covariance(toRowMajor<3>(message.linear_acceleration_covariance));
  return detail::serializeCdr(msg, kImuType);
}

Bytes encodePointCloud2(const PointCloud2& message) {
  sensor_msgs::msg::PointCloud2 msg;
  msg.header(toRos(message.header, kPointCloud2Type));
  msg.height(message.height);
  msg.width(message.width);
  checkedSize(message.fields, "fields", kPointCloud2Type);
  for (const auto& f : message.fields) {
    checkEncodableString(f.name, "fields[].name", kPointCloud2Type);
    sensor_msgs::msg::PointField field;
    field.name(f.name);
    field.offset(f.offset);
    field.datatype(f.datatype);
    field.count(f.count);
    msg.fields().push_back(std::move(field));
  }
  msg.is_bigendian(message.is_bigendian);
  msg.point_step(message.point_step);
  msg.row_step(message.row_step);
  checkedSize(message.data, "data", kPointCloud2Type);
  msg.data(message.data);
  msg.is_dense(message.is_dense);
  return detail::serializeCdr(msg, kPointCloud2Type);
}

Bytes encodeTFMessage(const TFMessage& message) {
  tf2_msgs::msg::TFMessage msg;
  checkedSize(message.transforms, "transforms", kTFMessageType);
  for (const TransformStamped& t : message.transforms) {
    geometry_msgs::msg::TransformStamped out;
    out.header(toRos(t.header, kTFMessageType));
    checkEncodableString(t.child_frame_id, "transforms[].child_frame_id", kTFMessageType);
    out.child_frame_id(t.child_frame_id);
    out.transform().translation(toRosVector(t.translation));
    out.transform().rotation(toRos(t.rotation));
    msg.transforms().push_back(std::move(out));
  }
  return detail::serializeCdr(msg, kTFMessageType);
}

// ---- rosgraph_msgs/Clock: two 32-bit fields, written by hand ----

Bytes encodeClock(Stamp time) {
  const RosTime ros = toRosTime(time);
  if (!ros.fits) throw Error("Clock: " + formatSeconds(time) + " s does not fit builtin_interfaces/Time (int32 seconds)");
  const std::int32_t s32 = ros.sec;
  const std::uint32_t ns = ros.nanosec;
  Bytes b = {0x00, 0x01, 0x00, 0x00};  // XCDR1, little endian
  for (int i = 0; i < 4; ++i) b.push_back(static_cast<std::uint8_t>(static_cast<std::uint32_t>(s32) >> (8 * i)));
  for (int i = 0; i < 4; ++i) b.push_back(static_cast<std::uint8_t>(ns >> (8 * i)));
  return b;
}

Stamp decodeClock(const std::uint8_t* data, std::size_t size) {
  if (size < 12) throw Error("Clock: " + std::to_string(size) + " bytes, expected 12");
  if (data[0] != 0 || data[1] > 1) throw Error("Clock: encapsulation is not plain CDR");
  const bool little = data[1] == 1;
  auto u32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(data[at + (little ? i : 3 - i)]) << (8 * i);
    return v;
  };
  const auto sec = static_cast<std::int32_t>(u32(4));
  const std::uint32_t ns = u32(8);
  if (ns >= kNanosPerSecond) throw Error("Clock: nanosec " + std::to_string(ns) + " is not below 1e9");
  return static_cast<Stamp>(sec) * kNanosPerSecond + ns;
}

}  // namespace coloc::io
