// The few fields of these types are read and written with Fast CDR directly, after the same layout
// walk every other decoder runs (cdr_check.hpp): every length checked against the bytes present, each
// string NUL-terminated UTF-8, booleans 0 or 1, the field named in the error.
#include "coloc/io/ros_node_interfaces.hpp"

#include <functional>

#include "cdr_codec.hpp"

namespace coloc::io {
namespace {

using detail::CdrChecker;
using detail::CdrFormatError;
using eprosima::fastcdr::Cdr;

constexpr const char* kSetBoolRequestType = "std_srvs/srv/SetBool_Request";
constexpr const char* kSetBoolResponseType = "std_srvs/srv/SetBool_Response";
constexpr const char* kAlignRequestType = "autoware_internal_localization_msgs/srv/PoseWithCovarianceStamped_Request";
constexpr const char* kAlignResponseType = "autoware_internal_localization_msgs/srv/PoseWithCovarianceStamped_Response";

// ---- layout walks ----

void checkHeader(CdrChecker& c) {
  c.primitive(4, "header.stamp.sec");
  const std::uint32_t nanosec = c.uint32("header.stamp.nanosec");
  if (nanosec >= kNanosPerSecond) throw CdrFormatError("header.stamp.nanosec " + std::to_string(nanosec) + " is not below 1e9");
  c.string("header.frame_id");
}
void checkPose(CdrChecker& c) {
  checkHeader(c);
  c.primitives(8, 7, "pose.pose");
  c.primitives(8, 36, "pose.covariance");
}
void checkSetBoolRequest(CdrChecker& c) { c.boolean("data"); }
void checkSetBoolResponse(CdrChecker& c) {
  c.boolean("success");
  c.string("message");
}
void checkAlignResponse(CdrChecker& c) {
  c.boolean("success");
  c.boolean("reliable");
  checkPose(c);
}
void checkDiagnosticArray(CdrChecker& c) {
  checkHeader(c);
  // Each status at least: level, three empty strings, an empty sequence.
  const std::uint32_t n = c.sequenceLength(1 + 3 * 5 + 4, "status");
  for (std::uint32_t i = 0; i < n; ++i) {
    c.primitive(1, "status.level");
    c.string("status.name");
    c.string("status.message");
    c.string("status.hardware_id");
    const std::uint32_t values = c.sequenceLength(2 * 5, "status.values");
    for (std::uint32_t k = 0; k < values; ++k) {
      c.string("status.values.key");
      c.string("status.values.value");
    }
  }
}

// ---- Fast CDR ----

// Checks the layout, then reads with Fast CDR; any refusal becomes coloc::Error naming the type.
template <typename Result>
Result decode(const std::uint8_t* data, std::size_t size, const char* type, detail::LayoutCheck check,
              const std::function<Result(Cdr&)>& read) {
  try {
    detail::checkSerializedMessage(data, size, check);
    eprosima::fastcdr::FastBuffer buffer(reinterpret_cast<char*>(const_cast<std::uint8_t*>(data)), size);
    Cdr cdr(buffer, Cdr::DEFAULT_ENDIAN, Cdr::DDS_CDR);
    cdr.read_encapsulation();
    return read(cdr);
  } catch (const CdrFormatError& e) {
    detail::throwCodecError(type, e.what());
  } catch (const eprosima::fastcdr::exception::Exception& e) {
    detail::throwCodecError(type, std::string("Fast CDR: ") + e.what());
  }
}

Bytes encode(const char* type, const std::function<void(Cdr&)>& write) {
  eprosima::fastcdr::FastBuffer buffer;  // grows as written
  Cdr cdr(buffer, Cdr::LITTLE_ENDIANNESS, Cdr::DDS_CDR);
  try {
    cdr.serialize_encapsulation();
    write(cdr);
  } catch (const eprosima::fastcdr::exception::Exception& e) {
    detail::throwCodecError(type, std::string("Fast CDR: ") + e.what());
  }
  const auto* begin = reinterpret_cast<const std::uint8_t*>(buffer.getBuffer());
  return Bytes(begin, begin + cdr.getSerializedDataLength());
}

void writeString(Cdr& cdr, const std::string& s, const char* type, const char* field) {
  if (s.find('\0') != std::string::npos) detail::throwCodecError(type, std::string(field) + " holds a NUL character");
  cdr << s;
}

void writeHeader(Cdr& cdr, const Header& h, const char* type) {
  if (h.stamp < 0 || h.stamp / kNanosPerSecond > 0x7fffffffLL) detail::throwCodecError(type, "header.stamp does not fit builtin_interfaces/Time");
  cdr << static_cast<std::int32_t>(h.stamp / kNanosPerSecond) << static_cast<std::uint32_t>(h.stamp % kNanosPerSecond);
  writeString(cdr, h.frame_id, type, "header.frame_id");
}

Header readHeader(Cdr& cdr) {
  std::int32_t sec = 0;
  std::uint32_t nanosec = 0;
  Header h;
  cdr >> sec >> nanosec >> h.frame_id;
  h.stamp = static_cast<Stamp>(sec) * kNanosPerSecond + nanosec;
  return h;
}

void writePose(Cdr& cdr, const StampedPose& p, const char* type) {
  writeHeader(cdr, p.header, type);
  const Pose& pose = p.measurement.pose;
  cdr << pose.position.x() << pose.position.y() << pose.position.z() << pose.orientation.x() << pose.orientation.y() << pose.orientation.z()
      << pose.orientation.w();
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) cdr << p.measurement.covariance(r, c);
}

StampedPose readPose(Cdr& cdr) {
  StampedPose p;
  p.header = readHeader(cdr);
  double v[7];
  for (double& x : v) cdr >> x;
  p.measurement.stamp = p.header.stamp;
  p.measurement.pose.position = {v[0], v[1], v[2]};
  p.measurement.pose.orientation = Eigen::Quaterniond(v[6], v[3], v[4], v[5]);
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) cdr >> p.measurement.covariance(r, c);
  return p;
}

}  // namespace

Bytes encodeDiagnosticArray(const DiagnosticArray& message) {
  return encode(kDiagnosticArrayType, [&](Cdr& cdr) {
    writeHeader(cdr, message.header, kDiagnosticArrayType);
    cdr << static_cast<std::uint32_t>(message.status.size());
    for (const DiagnosticStatus& s : message.status) {
      cdr << s.level;
      writeString(cdr, s.name, kDiagnosticArrayType, "status.name");
      writeString(cdr, s.message, kDiagnosticArrayType, "status.message");
      writeString(cdr, s.hardware_id, kDiagnosticArrayType, "status.hardware_id");
      cdr << static_cast<std::uint32_t>(s.values.size());
      for (const auto& [key, value] : s.values) {
        writeString(cdr, key, kDiagnosticArrayType, "status.values.key");
        writeString(cdr, value, kDiagnosticArrayType, "status.values.value");
      }
    }
  });
}

DiagnosticArray decodeDiagnosticArray(const std::uint8_t* data, std::size_t size) {
  return decode<DiagnosticArray>(data, size, kDiagnosticArrayType, checkDiagnosticArray, [](Cdr& cdr) {
    DiagnosticArray out;
    out.header = readHeader(cdr);
    std::uint32_t n = 0;
    cdr >> n;
    for (std::uint32_t i = 0; i < n; ++i) {
      DiagnosticStatus s;
      cdr >> s.level >> s.name >> s.message >> s.hardware_id;
      if (s.level > DiagnosticStatus::kStale) throw CdrFormatError("status.level is " + std::to_string(s.level) + ", not 0-3");
      std::uint32_t values = 0;
      cdr >> values;
      for (std::uint32_t k = 0; k < values; ++k) {
        std::string key, value;
        cdr >> key >> value;
        s.values.emplace_back(std::move(key), std::move(value));
      }
      out.status.push_back(std::move(s));
    }
    return out;
  });
}

Bytes encodeSetBoolRequest(bool data) {
  return encode(kSetBoolRequestType, [&](Cdr& cdr) { cdr << data; });
}

bool decodeSetBoolRequest(const std::uint8_t* data, std::size_t size) {
  return decode<bool>(data, size, kSetBoolRequestType, checkSetBoolRequest, [](Cdr& cdr) {
    bool b = false;
    cdr >> b;
    return b;
  });
}

Bytes encodeSetBoolResponse(const SetBoolResponse& response) {
  return encode(kSetBoolResponseType, [&](Cdr& cdr) {
    cdr << response.success;
    writeString(cdr, response.message, kSetBoolResponseType, "message");
  });
}

SetBoolResponse decodeSetBoolResponse(const std::uint8_t* data, std::size_t size) {
  return decode<SetBoolResponse>(data, size, kSetBoolResponseType, checkSetBoolResponse, [](Cdr& cdr) {
    SetBoolResponse out;
    cdr >> out.success >> out.message;
    return out;
  });
}

Bytes encodePoseAlignRequest(const StampedPose& request) {
  return encode(kAlignRequestType, [&](Cdr& cdr) { writePose(cdr, request, kAlignRequestType); });
}

StampedPose decodePoseAlignRequest(const std::uint8_t* data, std::size_t size) {
  return decode<StampedPose>(data, size, kAlignRequestType, checkPose, readPose);
}

Bytes encodePoseAlignResponse(const PoseAlignResponse& response) {
  return encode(kAlignResponseType, [&](Cdr& cdr) {
    cdr << response.success << response.reliable;
    writePose(cdr, response.pose, kAlignResponseType);
  });
}

PoseAlignResponse decodePoseAlignResponse(const std::uint8_t* data, std::size_t size) {
  return decode<PoseAlignResponse>(data, size, kAlignResponseType, checkAlignResponse, [](Cdr& cdr) {
    PoseAlignResponse out;
    cdr >> out.success >> out.reliable;
    out.pose = readPose(cdr);
    return out;
  });
}

}  // namespace coloc::io
