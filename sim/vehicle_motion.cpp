#include "coloc/sim/vehicle_motion.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "coloc/core/error.hpp"

namespace coloc::sim {

Route::Route(const Eigen::Vector2d& start, double heading, std::vector<RoutePiece> pieces) {
  if (pieces.empty()) throw Error("route: no pieces");
  Eigen::Vector2d p = start;
  double yaw = heading, s = 0.0;
  for (const RoutePiece& piece : pieces) {
    if (!(piece.length > 0.0) || !std::isfinite(piece.curvature)) throw Error("route: a piece needs a length > 0 and a finite curvature");
    pieces_.push_back({piece, s, p, yaw});
    double dummy_curvature;
    s += piece.length;
    length_ = s;
    at(s, p, yaw, dummy_curvature);
  }
}

void Route::at(double s, Eigen::Vector2d& position, double& yaw, double& curvature) const {
  s = std::clamp(s, 0.0, length_);
  const Piece* piece = &pieces_.front();
  for (const Piece& p : pieces_)
    if (s >= p.s0) piece = &p;
  const double d = std::min(s - piece->s0, piece->shape.length);
  const double k = piece->shape.curvature;
  curvature = k;
  yaw = piece->yaw0 + k * d;
  if (std::abs(k) < 1e-12) {
    position = piece->p0 + d * Eigen::Vector2d(std::cos(piece->yaw0), std::sin(piece->yaw0));
  } else {
    position = piece->p0 + Eigen::Vector2d(std::sin(yaw) - std::sin(piece->yaw0), -(std::cos(yaw) - std::cos(piece->yaw0))) / k;
  }
}

Drive::Drive(Route route, SpeedProfile profile) : route_(std::move(route)), profile_(profile) {
  if (!(profile.cruise > 0.0 && profile.acceleration > 0.0)) throw Error("drive: cruise speed and acceleration must be > 0");
  ramp_time_ = profile.cruise / profile.acceleration;
  ramp_length_ = 0.5 * profile.cruise * ramp_time_;
  if (2.0 * ramp_length_ > route_.length()) {  // too short to reach cruise speed: a triangle profile
    ramp_length_ = 0.5 * route_.length();
    ramp_time_ = std::sqrt(2.0 * ramp_length_ / profile.acceleration);
    profile_.cruise = profile.acceleration * ramp_time_;
  }
  cruise_time_ = (route_.length() - 2.0 * ramp_length_) / profile_.cruise;
  duration_ = 2.0 * ramp_time_ + cruise_time_;
}

VehicleState Drive::at(double t) const {
  VehicleState v;
  v.t = std::clamp(t, 0.0, duration_);
  const double a = profile_.acceleration;
  if (v.t < ramp_time_) {
    v.speed = a * v.t;
    v.s = 0.5 * a * v.t * v.t;
  } else if (v.t < ramp_time_ + cruise_time_) {
    v.speed = profile_.cruise;
    v.s = ramp_length_ + profile_.cruise * (v.t - ramp_time_);
  } else {
    const double r = duration_ - v.t;  // time left
    v.speed = a * r;
    v.s = route_.length() - 0.5 * a * r * r;
  }
  double curvature;
  route_.at(v.s, v.position, v.yaw, curvature);
  v.yaw_rate = curvature * v.speed;
  return v;
}

OdometrySample measureOdometry(const VehicleState& truth, const OdometryNoise& noise, RandomEngine& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  const double a = n(rng), b = n(rng);  // always two draws: the sequence does not depend on the state
  return {truth.speed * noise.speed_scale + noise.speed_sigma * a, truth.yaw_rate + noise.yaw_rate_bias + noise.yaw_rate_sigma * b};
}

}  // namespace coloc::sim
