#pragma once
// Other road users: vehicles driving along the ego vehicle's route in an adjacent or oncoming lane at
// a constant speed, there for the roadside perception to tell apart from the ego vehicle and for the
// vehicle's own LiDAR to see (they are in no map).
#include <Eigen/Core>
#include <cstdint>
#include <optional>

#include "coloc/sim/vehicle_body.hpp"
#include "coloc/sim/vehicle_motion.hpp"

namespace coloc::sim {

struct TrafficVehicle {
  double lane_offset = 3.5;  ///< m to the left of the ego's route (negative: right)
  double start = 0.0;        ///< m along the route at t = 0
  double speed = 10.0;       ///< m/s
  bool oncoming = false;     ///< drives against the route's direction
  VehicleBody body;          ///< its size; the shape follows the scenario's error sources
  /// A connected vehicle: it sends CAMs with this station id, and the RSUs send it fixes addressed to
  /// it, which the ego's radio hears too. Unset: an unconnected car.
  std::optional<std::uint32_t> station_id;
};

/// x, y and heading at time t, or nothing once it has left the route (or before it enters it).
std::optional<Eigen::Vector3d> trafficPose(const Route& route, const TrafficVehicle& vehicle, double t);

}  // namespace coloc::sim
