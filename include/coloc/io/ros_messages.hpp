#pragma once
// The ROS 2 messages coloc reads from logs and writes for the digital twin, as plain structs, and
// their CDR codecs. Bytes are XCDR1 as on the wire and in rosbag2/MCAP: a 4-byte encapsulation header
// (00 01 00 00 little endian, 00 00 00 00 big endian) then the body. Decoding accepts both byte orders;
// encoding writes little endian.
//
// Every decoder throws coloc::Error naming the ROS type and the reason (truncated, bad encapsulation,
// a length that exceeds the bytes present, a string that is not UTF-8, ...). The caller adds the
// topic and message index it knows.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "coloc/core/types.hpp"

namespace coloc::io {

using Bytes = std::vector<std::uint8_t>;

/// std_msgs/msg/Header.
struct Header {
  Stamp stamp = 0;  ///< sensing time of the data
  std::string frame_id;
};

/// geometry_msgs/msg/PoseWithCovarianceStamped or PoseStamped. measurement.stamp == header.stamp.
/// A PoseStamped carries no covariance: decoding it gives +inf on the diagonal and 0 elsewhere
/// ("not measured"), so the caller must supply a covariance before feeding the filter.
struct StampedPose {
  Header header;
  PoseMeasurement measurement;
};

/// geometry_msgs/msg/TwistWithCovarianceStamped or TwistStamped; TwistStamped decodes with the same
/// +inf diagonal as PoseStamped.
struct StampedTwist {
  Header header;
  TwistMeasurement measurement;
};

/// nav_msgs/msg/Odometry: pose in header.frame_id, twist in child_frame_id. Both stamps == header.stamp.
struct Odometry {
  Header header;
  std::string child_frame_id;
  PoseMeasurement pose;
  TwistMeasurement twist;
};

/// sensor_msgs/msg/Imu. Covariances as ROS defines them: element (0, 0) == -1 means "no estimate of
/// this quantity"; all zeros means "unknown".
struct Imu {
  Header header;
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  Eigen::Matrix3d orientation_covariance = Eigen::Matrix3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  ///< rad/s
  Eigen::Matrix3d angular_velocity_covariance = Eigen::Matrix3d::Zero();
  Eigen::Vector3d linear_acceleration = Eigen::Vector3d::Zero();  ///< m/s^2
  Eigen::Matrix3d linear_acceleration_covariance = Eigen::Matrix3d::Zero();
};

/// sensor_msgs/msg/PointField.
struct PointField {
  enum DataType : std::uint8_t {
    kInt8 = 1, kUint8 = 2, kInt16 = 3, kUint16 = 4, kInt32 = 5, kUint32 = 6, kFloat32 = 7, kFloat64 = 8
  };
  std::string name;
  std::uint32_t offset = 0;
  std::uint8_t datatype = 0;
  std::uint32_t count = 1;
};

/// sensor_msgs/msg/PointCloud2, data kept as the raw point bytes.
struct PointCloud2 {
  Header header;
  std::uint32_t height = 0;
  std::uint32_t width = 0;
  std::vector<PointField> fields;
  bool is_bigendian = false;
  std::uint32_t point_step = 0;
  std::uint32_t row_step = 0;
  std::vector<std::uint8_t> data;
  bool is_dense = false;
};

/// geometry_msgs/msg/TransformStamped: where child_frame_id's origin and axes are in header.frame_id
/// (a point p in the child frame is rotation * p + translation in the parent frame).
struct TransformStamped {
  Header header;
  std::string child_frame_id;
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();  ///< as sent: not normalised
};

/// tf2_msgs/msg/TFMessage, what /tf and /tf_static carry.
struct TFMessage {
  std::vector<TransformStamped> transforms;
};

/// The message types coloc decodes, one per ROS type name.
enum class MessageKind : std::uint8_t {
  kPoseWithCovarianceStamped,
  kPoseStamped,
  kTwistWithCovarianceStamped,
  kTwistStamped,
  kOdometry,
  kImu,
  kPointCloud2,
  kTFMessage,
};
inline constexpr int kMessageKindCount = 8;

/// "geometry_msgs/msg/PoseWithCovarianceStamped" -> kPoseWithCovarianceStamped; nullopt for types coloc
/// does not decode (callers list those to the user instead of failing).
std::optional<MessageKind> messageKindOf(std::string_view ros_type);
/// The ROS 2 type name, e.g. "nav_msgs/msg/Odometry".
std::string_view rosTypeName(MessageKind kind);
/// All decodable ROS type names.
std::vector<std::string_view> supportedRosTypes();
/// The ros2msg schema text (the type's .msg fields, then each dependency after an 80 '=' separator and
/// "MSG: pkg/Name"), as MCAP's ros2msg schema encoding expects; empty for types coloc does not know.
std::string rosMessageDefinition(std::string_view ros_type);

// Decoders. `data` holds the whole serialized message including the encapsulation header.
StampedPose decodePoseWithCovarianceStamped(const std::uint8_t* data, std::size_t size);
StampedPose decodePoseStamped(const std::uint8_t* data, std::size_t size);
StampedTwist decodeTwistWithCovarianceStamped(const std::uint8_t* data, std::size_t size);
StampedTwist decodeTwistStamped(const std::uint8_t* data, std::size_t size);
Odometry decodeOdometry(const std::uint8_t* data, std::size_t size);
Imu decodeImu(const std::uint8_t* data, std::size_t size);
PointCloud2 decodePointCloud2(const std::uint8_t* data, std::size_t size);
TFMessage decodeTFMessage(const std::uint8_t* data, std::size_t size);

inline StampedPose decodePoseWithCovarianceStamped(const Bytes& b) {
  return decodePoseWithCovarianceStamped(b.data(), b.size());
}
inline StampedPose decodePoseStamped(const Bytes& b) { return decodePoseStamped(b.data(), b.size()); }
inline StampedTwist decodeTwistWithCovarianceStamped(const Bytes& b) {
  return decodeTwistWithCovarianceStamped(b.data(), b.size());
}
inline StampedTwist decodeTwistStamped(const Bytes& b) { return decodeTwistStamped(b.data(), b.size()); }
inline Odometry decodeOdometry(const Bytes& b) { return decodeOdometry(b.data(), b.size()); }
inline Imu decodeImu(const Bytes& b) { return decodeImu(b.data(), b.size()); }
inline PointCloud2 decodePointCloud2(const Bytes& b) { return decodePointCloud2(b.data(), b.size()); }
inline TFMessage decodeTFMessage(const Bytes& b) { return decodeTFMessage(b.data(), b.size()); }

/// Any decodable message; the alternative follows the kind (both pose kinds give StampedPose, ...).
using RosMessage = std::variant<StampedPose, StampedTwist, Odometry, Imu, PointCloud2, TFMessage>;
RosMessage decodeMessage(MessageKind kind, const std::uint8_t* data, std::size_t size);
inline RosMessage decodeMessage(MessageKind kind, const Bytes& b) { return decodeMessage(kind, b.data(), b.size()); }

// Encoders: little-endian XCDR1 starting with 00 01 00 00. The header stamp is written (the
// measurement stamps are not read); it must fit builtin_interfaces/Time (int32 seconds). Strings must
// be UTF-8 without NUL. PoseStamped/TwistStamped drop the covariance. Throw coloc::Error otherwise.
Bytes encodePoseWithCovarianceStamped(const StampedPose& message);
Bytes encodePoseStamped(const StampedPose& message);
Bytes encodeTwistWithCovarianceStamped(const StampedTwist& message);
Bytes encodeTwistStamped(const StampedTwist& message);
Bytes encodeOdometry(const Odometry& message);
Bytes encodeImu(const Imu& message);
Bytes encodePointCloud2(const PointCloud2& message);
Bytes encodeTFMessage(const TFMessage& message);

/// rosgraph_msgs/msg/Clock, what a player of recorded logs publishes on /clock so that nodes run on the
/// log's time (ROS 2's use_sim_time). Its one field, builtin_interfaces/Time, as a stamp.
inline constexpr const char* kClockType = "rosgraph_msgs/msg/Clock";
inline constexpr const char* kClockTopic = "/clock";
Bytes encodeClock(Stamp time);
/// Throws coloc::Error for a payload that is not a CDR Clock (short, unknown encapsulation, nanosec >= 1e9).
Stamp decodeClock(const std::uint8_t* data, std::size_t size);

}  // namespace coloc::io
