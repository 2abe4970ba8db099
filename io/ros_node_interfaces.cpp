// The few fields of these types are written and read directly, with every length checked against the
// bytes present: no generated code is needed for them.
#include "coloc/io/ros_node_interfaces.hpp"

#include <cmath>
#include <cstring>

#include "coloc/core/error.hpp"

namespace coloc::io {
namespace {

// XCDR1, little endian; alignment relative to the body (after the 4-byte encapsulation header).
class Writer {
 public:
  Writer() : bytes_{0x00, 0x01, 0x00, 0x00} {}
  void u8(std::uint8_t v) { bytes_.push_back(v); }
  void boolean(bool v) { u8(v ? 1 : 0); }
  void u32(std::uint32_t v) {
    align(4);
    for (int i = 0; i < 4; ++i) bytes_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  }
  void f64(double v) {
    align(8);
    std::uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    for (int i = 0; i < 8; ++i) bytes_.push_back(static_cast<std::uint8_t>(bits >> (8 * i)));
  }
  void string(const std::string& s, const char* type, const char* field) {
    if (s.find('\0') != std::string::npos) throw Error(std::string(type) + ": " + field + " holds a NUL character");
    u32(static_cast<std::uint32_t>(s.size() + 1));
    bytes_.insert(bytes_.end(), s.begin(), s.end());
    bytes_.push_back(0);
  }
  void header(const Header& h, const char* type) {
    if (h.stamp < 0 || h.stamp / kNanosPerSecond > 0x7fffffffLL) throw Error(std::string(type) + ": header.stamp does not fit builtin_interfaces/Time");
    u32(static_cast<std::uint32_t>(h.stamp / kNanosPerSecond));
    u32(static_cast<std::uint32_t>(h.stamp % kNanosPerSecond));
    string(h.frame_id, type, "header.frame_id");
  }
  void poseWithCovarianceStamped(const StampedPose& p, const char* type) {
    header(p.header, type);
    const Pose& pose = p.measurement.pose;
    for (double v : {pose.position.x(), pose.position.y(), pose.position.z(), pose.orientation.x(), pose.orientation.y(),
                     pose.orientation.z(), pose.orientation.w()})
      f64(v);
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < 6; ++c) f64(p.measurement.covariance(r, c));
  }
  Bytes take() { return std::move(bytes_); }

 private:
  void align(std::size_t n) {
    while ((bytes_.size() - 4) % n != 0) bytes_.push_back(0);
  }
  Bytes bytes_;
};

class Reader {
 public:
  Reader(const std::uint8_t* data, std::size_t size, const char* type) : data_(data), size_(size), type_(type) {
    if (size < 4 || data == nullptr) fail("the encapsulation header", "shorter than 4 bytes");
    if (data[0] != 0 || data[1] > 1) fail("the encapsulation header", "not plain CDR (00 00 or 00 01)");
    little_ = data[1] == 1;
    at_ = 4;
  }
  std::uint8_t u8(const char* field) {
    need(1, field);
    return data_[at_++];
  }
  bool boolean(const char* field) {
    const std::uint8_t v = u8(field);
    if (v > 1) fail(field, "is " + std::to_string(v) + ", not a boolean");
    return v == 1;
  }
  std::uint32_t u32(const char* field) {
    align(4);
    need(4, field);
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(data_[at_ + (little_ ? i : 3 - i)]) << (8 * i);
    at_ += 4;
    return v;
  }
  double f64(const char* field) {
    align(8);
    need(8, field);
    std::uint64_t bits = 0;
    for (int i = 0; i < 8; ++i) bits |= static_cast<std::uint64_t>(data_[at_ + (little_ ? i : 7 - i)]) << (8 * i);
    at_ += 8;
    double v;
    std::memcpy(&v, &bits, sizeof v);
    return v;
  }
  std::string string(const char* field) {
    const std::uint32_t length = u32(field);
    if (length == 0) fail(field, "has length 0 (a CDR string holds at least its NUL)");
    need(length, field);
    if (data_[at_ + length - 1] != 0) fail(field, "is not NUL-terminated");
    std::string s(reinterpret_cast<const char*>(data_ + at_), length - 1);
    if (s.find('\0') != std::string::npos) fail(field, "holds a NUL character");
    at_ += length;
    return s;
  }
  /// A sequence length, each element at least `min_size` bytes.
  std::uint32_t sequence(std::size_t min_size, const char* field) {
    const std::uint32_t n = u32(field);
    if (static_cast<std::uint64_t>(n) * min_size > size_ - at_) fail(field, std::to_string(n) + " elements do not fit the bytes left");
    return n;
  }
  Header header() {
    Header h;
    const auto sec = static_cast<std::int32_t>(u32("header.stamp.sec"));
    const std::uint32_t nanosec = u32("header.stamp.nanosec");
    if (nanosec >= kNanosPerSecond) fail("header.stamp.nanosec", std::to_string(nanosec) + " is not below 1e9");
    h.stamp = static_cast<Stamp>(sec) * kNanosPerSecond + nanosec;
    h.frame_id = string("header.frame_id");
    return h;
  }
  StampedPose poseWithCovarianceStamped() {
    StampedPose p;
    p.header = header();
    double v[7];
    for (double& x : v) x = f64("pose.pose");
    p.measurement.stamp = p.header.stamp;
    p.measurement.pose.position = {v[0], v[1], v[2]};
    p.measurement.pose.orientation = Eigen::Quaterniond(v[6], v[3], v[4], v[5]);
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < 6; ++c) p.measurement.covariance(r, c) = f64("pose.covariance");
    return p;
  }
  [[noreturn]] void fail(const char* field, const std::string& why) const { throw Error(std::string(type_) + ": " + field + " " + why); }

 private:
  void align(std::size_t n) {
    while ((at_ - 4) % n != 0) ++at_;
  }
  void need(std::size_t n, const char* field) const {
    if (at_ > size_ || size_ - at_ < n) fail(field, "is truncated");
  }
  const std::uint8_t* data_;
  std::size_t size_, at_ = 0;
  const char* type_;
  bool little_ = true;
};

}  // namespace

Bytes encodeDiagnosticArray(const DiagnosticArray& message) {
  Writer w;
  w.header(message.header, kDiagnosticArrayType);
  w.u32(static_cast<std::uint32_t>(message.status.size()));
  for (const DiagnosticStatus& s : message.status) {
    w.u8(s.level);
    w.string(s.name, kDiagnosticArrayType, "status.name");
    w.string(s.message, kDiagnosticArrayType, "status.message");
    w.string(s.hardware_id, kDiagnosticArrayType, "status.hardware_id");
    w.u32(static_cast<std::uint32_t>(s.values.size()));
    for (const auto& [key, value] : s.values) {
      w.string(key, kDiagnosticArrayType, "status.values.key");
      w.string(value, kDiagnosticArrayType, "status.values.value");
    }
  }
  return w.take();
}

DiagnosticArray decodeDiagnosticArray(const std::uint8_t* data, std::size_t size) {
  Reader r(data, size, kDiagnosticArrayType);
  DiagnosticArray out;
  out.header = r.header();
  const std::uint32_t n = r.sequence(1 + 3 * 5 + 4, "status");
  for (std::uint32_t i = 0; i < n; ++i) {
    DiagnosticStatus s;
    s.level = r.u8("status.level");
    if (s.level > DiagnosticStatus::kStale) r.fail("status.level", "is " + std::to_string(s.level) + ", not 0-3");
    s.name = r.string("status.name");
    s.message = r.string("status.message");
    s.hardware_id = r.string("status.hardware_id");
    const std::uint32_t values = r.sequence(2 * 5, "status.values");
    for (std::uint32_t k = 0; k < values; ++k) {
      std::string key = r.string("status.values.key");
      s.values.emplace_back(std::move(key), r.string("status.values.value"));
    }
    out.status.push_back(std::move(s));
  }
  return out;
}

Bytes encodeSetBoolRequest(bool data) {
  Writer w;
  w.boolean(data);
  return w.take();
}

bool decodeSetBoolRequest(const std::uint8_t* data, std::size_t size) {
  Reader r(data, size, "std_srvs/srv/SetBool_Request");
  return r.boolean("data");
}

Bytes encodeSetBoolResponse(const SetBoolResponse& response) {
  Writer w;
  w.boolean(response.success);
  w.string(response.message, "std_srvs/srv/SetBool_Response", "message");
  return w.take();
}

SetBoolResponse decodeSetBoolResponse(const std::uint8_t* data, std::size_t size) {
  Reader r(data, size, "std_srvs/srv/SetBool_Response");
  SetBoolResponse out;
  out.success = r.boolean("success");
  out.message = r.string("message");
  return out;
}

Bytes encodePoseAlignRequest(const StampedPose& request) {
  Writer w;
  w.poseWithCovarianceStamped(request, "autoware_internal_localization_msgs/srv/PoseWithCovarianceStamped_Request");
  return w.take();
}

StampedPose decodePoseAlignRequest(const std::uint8_t* data, std::size_t size) {
  Reader r(data, size, "autoware_internal_localization_msgs/srv/PoseWithCovarianceStamped_Request");
  return r.poseWithCovarianceStamped();
}

Bytes encodePoseAlignResponse(const PoseAlignResponse& response) {
  Writer w;
  w.boolean(response.success);
  w.boolean(response.reliable);
  w.poseWithCovarianceStamped(response.pose, "autoware_internal_localization_msgs/srv/PoseWithCovarianceStamped_Response");
  return w.take();
}

PoseAlignResponse decodePoseAlignResponse(const std::uint8_t* data, std::size_t size) {
  Reader r(data, size, "autoware_internal_localization_msgs/srv/PoseWithCovarianceStamped_Response");
  PoseAlignResponse out;
  out.success = r.boolean("success");
  out.reliable = r.boolean("reliable");
  out.pose = r.poseWithCovarianceStamped();
  return out;
}

}  // namespace coloc::io
