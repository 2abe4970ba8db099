#pragma once
// A street for ray casting tests and benchmarks: ground, 40 houses, 40 trees and 40 parked cars, and a
// 32-beam LiDAR sweep (1,800 azimuths x 32 beams, -25 to +15 deg) from a sensor moving along the street.
#include <cmath>
#include <vector>

#include "coloc/sim/mesh.hpp"
#include "coloc/sim/ray_caster.hpp"

namespace coloc::testing {

inline void buildStreet(sim::RayCaster& world, std::vector<Eigen::Vector3f>& origins, std::vector<Eigen::Vector3f>& directions) {
  world.addMesh(sim::groundRectangle({-150, -150}, {150, 150}));
  for (int i = 0; i < 40; ++i) {
    world.addMesh(sim::box({-100.0f + 5.0f * i, 12.0f, 0.0f}, {4.0f, 8.0f, 6.0f + (i % 3)}, 0.05f * i));
    world.addMesh(sim::cylinder({-98.0f + 5.0f * i, -9.0f, 0.0f}, 0.3f + 0.02f * (i % 5), 5.0f));
    world.addMesh(sim::box({-90.0f + 4.5f * i, -3.5f, 0.2f}, {4.4f, 1.8f, 1.4f}, 0.02f * (i % 7)));
  }
  world.commit();
  for (int a = 0; a < 1800; ++a)
    for (int b = 0; b < 32; ++b) {
      const float azimuth = 0.2f * a * static_cast<float>(M_PI) / 180.0f;
      const float elevation = (-25.0f + 40.0f * b / 31.0f) * static_cast<float>(M_PI) / 180.0f;
      origins.push_back({0.01f * a, 0.0f, 1.8f});  // the sensor moves during the sweep
      directions.push_back({std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth), std::sin(elevation)});
    }
}

}  // namespace coloc::testing
