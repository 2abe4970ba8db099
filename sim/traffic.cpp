#include "coloc/sim/traffic.hpp"

#include <cmath>

namespace coloc::sim {

std::optional<Eigen::Vector3d> trafficPose(const Route& route, const TrafficVehicle& vehicle, double t) {
  const double s = vehicle.start + (vehicle.oncoming ? -1.0 : 1.0) * vehicle.speed * t;
  if (s < 0.0 || s > route.length()) return std::nullopt;
  Eigen::Vector2d p;
  double yaw = 0.0, curvature = 0.0;
  route.at(s, p, yaw, curvature);
  const Eigen::Vector2d left(-std::sin(yaw), std::cos(yaw));
  p += vehicle.lane_offset * left;
  return Eigen::Vector3d(p.x(), p.y(), vehicle.oncoming ? std::atan2(-std::sin(yaw), -std::cos(yaw)) : yaw);
}

}  // namespace coloc::sim
