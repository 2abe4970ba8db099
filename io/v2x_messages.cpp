// Read and written with Fast CDR directly, after the same layout walk every other decoder runs
// (cdr_check.hpp).
#include "coloc/io/v2x_messages.hpp"

#include <algorithm>

#include <cmath>
#include <functional>

#include "cdr_codec.hpp"

namespace coloc::io {
namespace {

using detail::CdrChecker;
using detail::CdrFormatError;
using eprosima::fastcdr::Cdr;

void checkCam(CdrChecker& c) {
  c.primitive(4, "header.stamp.sec");
  const std::uint32_t nanosec = c.uint32("header.stamp.nanosec");
  if (nanosec >= kNanosPerSecond) throw CdrFormatError("header.stamp.nanosec " + std::to_string(nanosec) + " is not below 1e9");
  c.string("header.frame_id");
  c.primitive(4, "station_id");
  c.primitives(8, 7, "x, y, heading, speed, yaw_rate, length, width");
}

}  // namespace

double camSizeSent(double size, double step) { return step > 0.0 ? std::max(step, std::round(size / step) * step) : size; }

Eigen::Vector2d Cam::centre() const { return reference - 0.5 * length * Eigen::Vector2d(std::cos(heading), std::sin(heading)); }

Bytes encodeCam(const Cam& cam) {
  if (cam.header.stamp < 0 || cam.header.stamp / kNanosPerSecond > 0x7fffffffLL) detail::throwCodecError(kCamType, "header.stamp does not fit builtin_interfaces/Time");
  if (cam.header.frame_id.find('\0') != std::string::npos) detail::throwCodecError(kCamType, "header.frame_id holds a NUL character");
  eprosima::fastcdr::FastBuffer buffer;
  Cdr cdr(buffer, Cdr::LITTLE_ENDIANNESS, Cdr::DDS_CDR);
  try {
    cdr.serialize_encapsulation();
    cdr << static_cast<std::int32_t>(cam.header.stamp / kNanosPerSecond) << static_cast<std::uint32_t>(cam.header.stamp % kNanosPerSecond);
    cdr << cam.header.frame_id << cam.station_id << cam.reference.x() << cam.reference.y() << cam.heading << cam.speed << cam.yaw_rate << cam.length
        << cam.width;
  } catch (const eprosima::fastcdr::exception::Exception& e) {
    detail::throwCodecError(kCamType, std::string("Fast CDR: ") + e.what());
  }
  const auto* begin = reinterpret_cast<const std::uint8_t*>(buffer.getBuffer());
  return Bytes(begin, begin + cdr.getSerializedDataLength());
}

Cam decodeCam(const std::uint8_t* data, std::size_t size) {
  try {
    detail::checkSerializedMessage(data, size, checkCam);
    eprosima::fastcdr::FastBuffer buffer(reinterpret_cast<char*>(const_cast<std::uint8_t*>(data)), size);
    Cdr cdr(buffer, Cdr::DEFAULT_ENDIAN, Cdr::DDS_CDR);
    cdr.read_encapsulation();
    Cam cam;
    std::int32_t sec = 0;
    std::uint32_t nanosec = 0;
    cdr >> sec >> nanosec >> cam.header.frame_id >> cam.station_id;
    cam.header.stamp = static_cast<Stamp>(sec) * kNanosPerSecond + nanosec;
    double x = 0.0, y = 0.0;
    cdr >> x >> y >> cam.heading >> cam.speed >> cam.yaw_rate >> cam.length >> cam.width;
    cam.reference = {x, y};
    const double values[] = {x, y, cam.heading, cam.speed, cam.yaw_rate, cam.length, cam.width};
    static const char* const kNames[] = {"x", "y", "heading", "speed", "yaw_rate", "length", "width"};
    for (int i = 0; i < 7; ++i)
      if (!std::isfinite(values[i])) throw CdrFormatError(std::string(kNames[i]) + " is not finite");
    if (!(cam.length > 0.0) || !(cam.width > 0.0)) throw CdrFormatError("length and width must be > 0 m");
    return cam;
  } catch (const CdrFormatError& e) {
    detail::throwCodecError(kCamType, e.what());
  } catch (const eprosima::fastcdr::exception::Exception& e) {
    detail::throwCodecError(kCamType, std::string("Fast CDR: ") + e.what());
  }
}

}  // namespace coloc::io
