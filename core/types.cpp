#include "coloc/core/types.hpp"

#include <cmath>
#include <algorithm>
#include <cstdio>

namespace coloc {

std::string formatSeconds(Stamp stamp) {
  // Split into whole seconds and nanoseconds so that large epoch stamps keep all nine decimals.
  const bool negative = stamp < 0;
  const std::uint64_t magnitude = negative ? static_cast<std::uint64_t>(-(stamp + 1)) + 1u
                                           : static_cast<std::uint64_t>(stamp);
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%s%llu.%09llu", negative ? "-" : "",
                static_cast<unsigned long long>(magnitude / kNanosPerSecond),
                static_cast<unsigned long long>(magnitude % kNanosPerSecond));
  return buffer;
}

double wrapAngle(double angle) {
  if (angle > -M_PI && angle <= M_PI) return angle;
  double wrapped = std::remainder(angle, 2.0 * M_PI);  // in [-pi, pi]
  if (wrapped <= -M_PI) wrapped += 2.0 * M_PI;
  return wrapped;
}

Eigen::Vector3d rollPitchYaw(const Eigen::Quaterniond& q) {
  // ZYX Euler angles computed directly from the quaternion (as tf2's getRPY), stable near the poles.
  const double w = q.w(), x = q.x(), y = q.y(), z = q.z();
  const double roll = std::atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y));
  const double sin_pitch = std::clamp(2.0 * (w * y - z * x), -1.0, 1.0);
  const double pitch = std::asin(sin_pitch);
  const double yaw = std::atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z));
  return {roll, pitch, yaw};
}

Eigen::Quaterniond quaternionFromRollPitchYaw(double roll, double pitch, double yaw) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                            Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                            Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()));
}

}  // namespace coloc
