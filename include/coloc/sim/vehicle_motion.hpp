#pragma once
// The ego vehicle's drive: a route of straight and circular pieces, a speed profile with bounded
// acceleration, and a kinematic model (no slip), so that yaw rate and speed are exact and the pose is
// known at any time. Its sensors: wheel speed and yaw rate with noise and bias.
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "coloc/sim/random_engine.hpp"

namespace coloc::sim {

struct RoutePiece {
  double length;     ///< m along the route
  double curvature;  ///< 1/m; 0 = straight, > 0 turns left
};

struct VehicleState {
  double t = 0.0;  ///< s since the start
  double s = 0.0;  ///< m along the route
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  double yaw = 0.0;
  double speed = 0.0;     ///< m/s
  double yaw_rate = 0.0;  ///< rad/s
};

class Route {
 public:
  Route(const Eigen::Vector2d& start, double heading, std::vector<RoutePiece> pieces);
  double length() const { return length_; }
  /// Position, heading and curvature at arc length s (clamped to the route).
  void at(double s, Eigen::Vector2d& position, double& yaw, double& curvature) const;

 private:
  struct Piece {
    RoutePiece shape;
    double s0;
    Eigen::Vector2d p0;
    double yaw0;
  };
  std::vector<Piece> pieces_;
  double length_ = 0.0;
};

struct SpeedProfile {
  double cruise = 10.0;        ///< m/s
  double acceleration = 1.5;   ///< m/s^2, from standstill and back to it at the end
};

/// The drive along a route: standstill at both ends, cruise in between.
class Drive {
 public:
  Drive(Route route, SpeedProfile profile);
  double duration() const { return duration_; }
  VehicleState at(double t) const;
  const Route& route() const { return route_; }

 private:
  Route route_;
  SpeedProfile profile_;
  double ramp_time_, ramp_length_, cruise_time_, duration_;
};

struct OdometryNoise {
  double speed_sigma = 0.05;      ///< m/s
  double speed_scale = 1.01;      ///< wheel-radius error
  double yaw_rate_sigma = 0.005;  ///< rad/s
  double yaw_rate_bias = 0.002;   ///< rad/s
};

struct OdometrySample {
  double speed, yaw_rate;
};

/// Noisy wheel speed and gyro readings of a true state; draws from `rng`.
OdometrySample measureOdometry(const VehicleState& truth, const OdometryNoise& noise, RandomEngine& rng);

}  // namespace coloc::sim
