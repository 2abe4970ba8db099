#pragma once
// What a ROS 2 node offers besides its data, as far as coloc serves or calls it: diagnostics
// (diagnostic_msgs/msg/DiagnosticArray on /diagnostics, what Autoware's monitors read), std_srvs/srv/SetBool
// (Autoware's trigger_node services) and autoware_internal_localization_msgs/srv/PoseWithCovarianceStamped
// (NDT's alignment service, ndt_align_srv). Codecs as in ros_messages.hpp: XCDR1 with its encapsulation
// header; encoders write little endian, decoders read either and throw coloc::Error naming the type and
// the field for anything truncated or malformed.
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "coloc/io/ros_messages.hpp"

namespace coloc::io {

inline constexpr const char* kDiagnosticArrayType = "diagnostic_msgs/msg/DiagnosticArray";
inline constexpr const char* kSetBoolType = "std_srvs/srv/SetBool";
inline constexpr const char* kPoseAlignServiceType = "autoware_internal_localization_msgs/srv/PoseWithCovarianceStamped";

/// diagnostic_msgs/msg/DiagnosticStatus.
struct DiagnosticStatus {
  enum Level : std::uint8_t { kOk = 0, kWarn = 1, kError = 2, kStale = 3 };
  std::uint8_t level = kOk;
  std::string name, message, hardware_id;
  std::vector<std::pair<std::string, std::string>> values;  ///< diagnostic_msgs/msg/KeyValue
};

/// diagnostic_msgs/msg/DiagnosticArray.
struct DiagnosticArray {
  Header header;
  std::vector<DiagnosticStatus> status;
};

Bytes encodeDiagnosticArray(const DiagnosticArray& message);
DiagnosticArray decodeDiagnosticArray(const std::uint8_t* data, std::size_t size);

/// std_srvs/srv/SetBool.
struct SetBoolResponse {
  bool success = false;
  std::string message;
};
Bytes encodeSetBoolRequest(bool data);
bool decodeSetBoolRequest(const std::uint8_t* data, std::size_t size);
Bytes encodeSetBoolResponse(const SetBoolResponse& response);
SetBoolResponse decodeSetBoolResponse(const std::uint8_t* data, std::size_t size);

/// autoware_internal_localization_msgs/srv/PoseWithCovarianceStamped: the request is the pose to align
/// from; the response says whether the alignment ran (success), whether its score is to be trusted
/// (reliable), and the aligned pose.
struct PoseAlignResponse {
  bool success = false;
  bool reliable = false;
  StampedPose pose;
};
Bytes encodePoseAlignRequest(const StampedPose& request);
StampedPose decodePoseAlignRequest(const std::uint8_t* data, std::size_t size);
Bytes encodePoseAlignResponse(const PoseAlignResponse& response);
PoseAlignResponse decodePoseAlignResponse(const std::uint8_t* data, std::size_t size);

}  // namespace coloc::io
