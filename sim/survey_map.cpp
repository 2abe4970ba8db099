#include "coloc/sim/survey_map.hpp"

#include <cmath>

#include "coloc/ndt/preprocess.hpp"
#include "coloc/sim/lidar_model.hpp"

namespace coloc::sim {

ndt::PointCloud surveyMap(const Scenario& scenario, const SurveyConfig& config, const std::function<void(double)>& progress) {
  RayCaster world;
  for (const TriangleMesh& m : scenario.mapMeshes()) world.addMesh(m);
  world.commit();
  // The surveyor carries a 32-beam LiDAR, which covers facades from near the ground to well above.
  LidarSpec lidar = vlp32c();
  lidar.range_noise = config.range_noise;
  lidar.max_range = config.max_range;
  const Route route(scenario.route_start, scenario.route_heading, scenario.route);
  std::mt19937_64 rng(config.seed);
  ndt::PointCloud merged;
  const int stops = std::max(1, static_cast<int>(std::floor(route.length() / config.spacing)) + 1);
  for (int i = 0; i < stops; ++i) {
    Eigen::Vector2d xy;
    double yaw, curvature;
    route.at(i * config.spacing, xy, yaw, curvature);
    const Eigen::Isometry3d pose = Eigen::Translation3d(xy.x(), xy.y(), config.lidar_height) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ());
    for (const LidarPoint& p : scanSweep(lidar, world, [&](double) { return pose; }, rng))
      merged.points.push_back((pose * p.position.cast<double>()).cast<float>());
    // Thin as we go, so that memory follows the map's surface, not the number of scans.
    if (i % 10 == 9) merged = ndt::voxelDownsample(merged, config.voxel);
    if (progress) progress(static_cast<double>(i + 1) / stops);
  }
  return ndt::voxelDownsample(merged, config.voxel);
}

}  // namespace coloc::sim
