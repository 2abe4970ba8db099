#pragma once
// A point-cloud map made the way survey maps are made: a mapping vehicle drives the route, its LiDAR
// samples the surfaces of the world as surveyed (range noise included), and the scans, placed with the
// surveyor's poses (as exact as the scenario's error sources say: ErrorSources::map_*), are merged and
// thinned on a voxel grid.
#include <cstdint>
#include <functional>

#include "coloc/ndt/point_cloud.hpp"
#include "coloc/sim/scene.hpp"

namespace coloc::sim {

struct SurveyConfig {
  double spacing = 4.0;       ///< m of route between survey scans
  double lidar_height = 2.0;  ///< m, the mapping vehicle's LiDAR
  double range_noise = 0.02;  ///< m
  double max_range = 80.0;    ///< m
  double voxel = 0.1;         ///< m, thinning of the merged cloud
  std::uint64_t seed = 7;
};

/// `progress` (optional) is called with the share done.
ndt::PointCloud surveyMap(const Scenario& scenario, const SurveyConfig& config,
                          const std::function<void(double)>& progress = nullptr);

}  // namespace coloc::sim
