#pragma once
// Starting guesses for NDT's basin of convergence, shared by the tests and bench/ndt_basin.
#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

namespace coloc::testing {

/// `reference` turned by `yaw` (rad) about the vertical and moved by `offset`.
inline Eigen::Matrix4d offsetPose(const Eigen::Matrix4d& reference, double yaw, const Eigen::Vector3d& offset) {
  Eigen::Matrix4d guess = reference;
  guess.topLeftCorner<3, 3>() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * reference.topLeftCorner<3, 3>();
  guess.topRightCorner<3, 1>() += offset;
  return guess;
}

/// `count` guesses around `reference`, each a horizontal offset of `metres` in a random direction and a
/// yaw of `degrees` with a random sign; seeded, so every run gets the same starts.
inline std::vector<Eigen::Matrix4d> seededStarts(const Eigen::Matrix4d& reference, double metres, double degrees, int count = 20) {
  std::mt19937 rng(20);
  std::uniform_real_distribution<double> direction(-M_PI, M_PI);
  std::bernoulli_distribution sign(0.5);
  std::vector<Eigen::Matrix4d> starts;
  for (int i = 0; i < count; ++i) {
    const double heading = direction(rng), yaw = (sign(rng) ? 1.0 : -1.0) * degrees * M_PI / 180.0;
    starts.push_back(offsetPose(reference, yaw, metres * Eigen::Vector3d(std::cos(heading), std::sin(heading), 0.0)));
  }
  return starts;
}

}  // namespace coloc::testing
