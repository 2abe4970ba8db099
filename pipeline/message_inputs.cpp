#include "coloc/pipeline/message_inputs.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "coloc/core/error.hpp"

namespace coloc::pipeline {

namespace {

const io::PointField* field(const io::PointCloud2& m, std::initializer_list<const char*> names) {
  for (const char* n : names)
    for (const auto& f : m.fields)
      if (f.name == n) return &f;
  return nullptr;
}

double read(const std::uint8_t* at, std::uint8_t type) {
  switch (type) {
    case io::PointField::kFloat32: { float v; std::memcpy(&v, at, 4); return v; }
    case io::PointField::kFloat64: { double v; std::memcpy(&v, at, 8); return v; }
    case io::PointField::kUint32: { std::uint32_t v; std::memcpy(&v, at, 4); return v; }
    case io::PointField::kInt32: { std::int32_t v; std::memcpy(&v, at, 4); return v; }
    default: return std::nan("");
  }
}

std::size_t sizeOf(std::uint8_t type) {
  switch (type) {
    case io::PointField::kInt8: case io::PointField::kUint8: return 1;
    case io::PointField::kInt16: case io::PointField::kUint16: return 2;
    case io::PointField::kInt32: case io::PointField::kUint32: case io::PointField::kFloat32: return 4;
    case io::PointField::kFloat64: return 8;
  }
  return 0;
}

}  // namespace

ndt::PointCloud toPointCloud(const io::PointCloud2& m) {
  if (m.is_bigendian) throw Error("PointCloud2: big-endian point data is not supported");
  const io::PointField* fx = field(m, {"x"});
  const io::PointField* fy = field(m, {"y"});
  const io::PointField* fz = field(m, {"z"});
  if (!fx || !fy || !fz) throw Error("PointCloud2: no x, y and z fields");
  const io::PointField* ft = field(m, {"time", "t", "time_stamp", "timestamp", "offset_time"});
  for (const io::PointField* f : {fx, fy, fz, ft}) {
    if (!f) continue;
    const std::size_t size = sizeOf(f->datatype);
    if (size == 0 || f->offset + size > m.point_step) throw Error("PointCloud2: field " + f->name + " lies outside point_step");
    const std::uint8_t zeros[8] = {};
    if (std::isnan(read(zeros, f->datatype)))
      throw Error("PointCloud2: field " + f->name + " has a type coloc cannot read as a number");
  }
  const std::size_t count = static_cast<std::size_t>(m.width) * m.height;
  if (m.point_step == 0 || m.row_step < static_cast<std::size_t>(m.width) * m.point_step ||
      m.data.size() < static_cast<std::size_t>(m.row_step) * m.height)
    throw Error("PointCloud2: data is shorter than height x row_step, or point_step is inconsistent");
  ndt::PointCloud cloud;
  cloud.points.reserve(count);
  // Drivers give per-point time as seconds (float) relative to the sweep, nanoseconds (uint32: Ouster's
  // t, Livox's offset_time), absolute seconds (float64: Hesai, RoboSense) or absolute nanoseconds in a
  // float64 (Livox's timestamp): all become seconds relative to the first point.
  std::vector<double> times;
  if (ft) times.reserve(count);
  const auto isFloat = [](const io::PointField* f) { return !f || f->datatype == io::PointField::kFloat32; };
  if (isFloat(fx) && isFloat(fy) && isFloat(fz) && isFloat(ft)) {
    // The common case (every driver's x, y, z; most drivers' time): float32 read as such, the same
    // values as through read() and back to float, without a switch per field and point.
    const auto get = [](const std::uint8_t* at) {
      float v;
      std::memcpy(&v, at, 4);
      return v;
    };
    for (std::uint32_t row = 0; row < m.height; ++row) {
      const std::uint8_t* p = m.data.data() + static_cast<std::size_t>(row) * m.row_step;
      for (std::uint32_t col = 0; col < m.width; ++col, p += m.point_step) {
        const float x = get(p + fx->offset), y = get(p + fy->offset), z = get(p + fz->offset);
        if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) continue;
        cloud.points.emplace_back(x, y, z);
        if (ft) times.push_back(get(p + ft->offset));
      }
    }
  } else {
    for (std::uint32_t row = 0; row < m.height; ++row)
      for (std::uint32_t col = 0; col < m.width; ++col) {
        const std::uint8_t* p = m.data.data() + static_cast<std::size_t>(row) * m.row_step + static_cast<std::size_t>(col) * m.point_step;
        const double x = read(p + fx->offset, fx->datatype), y = read(p + fy->offset, fy->datatype), z = read(p + fz->offset, fz->datatype);
        if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) continue;
        cloud.points.emplace_back(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
        if (ft) times.push_back(read(p + ft->offset, ft->datatype));
      }
  }
  if (ft && !times.empty()) {
    double first = times.front(), last = times.front();
    for (double t : times) first = std::min(first, t), last = std::max(last, t);
    // Integers count nanoseconds. A float's unit shows in the span: a sweep lasts a fraction of a
    // second, so a span of more than a second is of nanoseconds (or microseconds), never seconds.
    const double span = last - first;
    double scale = 1.0;
    if (ft->datatype != io::PointField::kFloat32 && ft->datatype != io::PointField::kFloat64) scale = 1e-9;
    else if (!std::isfinite(span)) throw Error("PointCloud2: field " + ft->name + " holds a time that is not a finite number");
    else if (span > 1.0) scale = span * 1e-6 <= 1.0 ? 1e-6 : 1e-9;
    if (span * scale > 1.0)
      throw Error("PointCloud2: field " + ft->name + " spans " + std::to_string(span) +
                  " units, more than a second of one sweep in seconds, microseconds or nanoseconds");
    cloud.times.reserve(times.size());
    for (double t : times) cloud.times.push_back(static_cast<float>((t - first) * scale));
  }
  return cloud;
}

Matrix6d completeCovariance(Matrix6d C, const Vector6d& fallback, const InputConfig* input, const MessageConfig& messages,
                            bool& used_fallback) {
  used_fallback = false;
  if (input && input->covariance_diagonal) return Matrix6d(input->covariance_diagonal->asDiagonal());
  const auto diagonal = C.diagonal();
  const bool none = (diagonal.array() == 0.0).all() || (diagonal.array() == kInfinity).all();
  if (none) {
    used_fallback = true;
    return Matrix6d(fallback.asDiagonal());
  }
  if (messages.zero_variance_is_unmeasured) {
    for (int i = 0; i < 6; ++i) {
      if (C(i, i) != 0.0) continue;
      C.row(i).setZero();
      C.col(i).setZero();
      C(i, i) = kInfinity;
    }
  }
  return C;
}

TwistMeasurement twistFromImu(const io::Imu& imu) {
  TwistMeasurement t;
  t.stamp = imu.header.stamp;
  t.angular = imu.angular_velocity;
  t.covariance = Matrix6d::Zero();
  t.covariance.diagonal().head<3>().setConstant(kInfinity);  // an IMU does not measure velocity
  t.covariance.bottomRightCorner<3, 3>() = imu.angular_velocity_covariance;
  // REP 145: -1 in the first element says the angular velocity is not estimated.
  if (imu.angular_velocity_covariance(0, 0) == -1.0) t.covariance.bottomRightCorner<3, 3>().diagonal().setConstant(kInfinity);
  return t;
}

TwistMeasurement twistFromMessage(const io::RosMessage& message, const InputConfig* input, const MessageConfig& messages,
                                  bool& used_fallback) {
  TwistMeasurement t;
  if (const auto* odom = std::get_if<io::Odometry>(&message)) t = odom->twist;
  else if (const auto* st = std::get_if<io::StampedTwist>(&message)) t = st->measurement;
  else if (const auto* imu = std::get_if<io::Imu>(&message)) t = twistFromImu(*imu);
  else throw Error("a message of this type carries no twist");
  t.covariance = completeCovariance(t.covariance, messages.fallback_twist_variance, input, messages, used_fallback);
  return t;
}

PoseMeasurement poseFromMessage(const io::RosMessage& message, const InputConfig* input, const MessageConfig& messages,
                                bool& used_fallback) {
  PoseMeasurement p;
  if (const auto* odom = std::get_if<io::Odometry>(&message)) p = odom->pose;
  else if (const auto* sp = std::get_if<io::StampedPose>(&message)) p = sp->measurement;
  else throw Error("a message of this type carries no pose");
  p.covariance = completeCovariance(p.covariance, messages.fallback_pose_variance, input, messages, used_fallback);
  return p;
}

namespace {

rsu_client::RsuFix fixFromPose(const io::Header& header, const PoseMeasurement& pose, const std::string& rsu_id) {
  rsu_client::RsuFix fix;
  fix.stamp = pose.stamp;
  fix.rsu_id = rsu_id;
  fix.x = pose.pose.position.x();
  fix.y = pose.pose.position.y();
  const double yaw_variance = pose.covariance(5, 5);
  if (std::isfinite(yaw_variance) && yaw_variance > 0.0) fix.yaw = rollPitchYaw(pose.pose.orientation)[2];
  // The decoder has refused a nanosec field of 1e9 or more already; the stamp's own is what was sent.
  rsu_client::SentFields sent;
  sent.frame_id = header.frame_id;
  sent.covariance = pose.covariance;
  sent.nanosec = static_cast<std::uint32_t>(((pose.stamp % kNanosPerSecond) + kNanosPerSecond) % kNanosPerSecond);
  fix.sent = std::move(sent);
  return fix;
}

}  // namespace

rsu_client::RsuFix fixFromMessage(const io::StampedPose& message, const std::string& rsu_id) {
  return fixFromPose(message.header, message.measurement, rsu_id);
}

rsu_client::RsuFix fixFromMessage(const io::Odometry& message, const std::string& rsu_id) {
  rsu_client::RsuFix fix = fixFromPose(message.header, message.pose, rsu_id);
  fix.sent->child_frame_id = message.child_frame_id;
  fix.station_id = rsu_client::parseStationId(message.child_frame_id);
  return fix;
}

rsu_client::RsuFix fixFromMessage(const io::RosMessage& message, const std::string& rsu_id) {
  if (const auto* odom = std::get_if<io::Odometry>(&message)) return fixFromMessage(*odom, rsu_id);
  if (const auto* pose = std::get_if<io::StampedPose>(&message)) return fixFromMessage(*pose, rsu_id);
  throw Error("an RSU fix is a nav_msgs/msg/Odometry (addressed) or a geometry_msgs/msg/PoseWithCovarianceStamped (unaddressed)");
}

}  // namespace coloc::pipeline
