#include "coloc/sim/survey_map.hpp"

#include <array>
#include <cmath>
#include <random>
#include <string>
#include <utility>

#include "coloc/ndt/voxel_thinning.hpp"
#include "coloc/sim/lidar_model.hpp"

namespace coloc::sim {

namespace {

// A smooth random function of distance along the route with standard deviation `sd`: a few cosines of
// random phase, their wavelengths between `length` and four times it (each has variance 1/2).
class SmoothError {
 public:
  SmoothError(double sd, double length, RandomEngine& rng) : scale_(sd * std::sqrt(2.0 / kTerms)) {
    std::uniform_real_distribution<double> wavelength(length, 4.0 * length), phase(0.0, 2.0 * M_PI);
    for (int k = 0; k < kTerms; ++k) terms_[k] = {2.0 * M_PI / wavelength(rng), phase(rng)};
  }
  double operator()(double s) const {
    double v = 0.0;
    for (const auto& [w, p] : terms_) v += std::cos(w * s + p);
    return scale_ * v;
  }

 private:
  static constexpr int kTerms = 4;
  double scale_;
  std::array<std::pair<double, double>, kTerms> terms_;
};

// One map per site: the draw depends on the site's name, not on the drive that happens to survey it.
std::uint64_t nameHash(const std::string& name) {
  std::uint64_t h = 1469598103934665603ULL;  // FNV-1a
  for (unsigned char c : name) h = (h ^ c) * 1099511628211ULL;
  return h;
}

}  // namespace

ndt::PointCloud surveyMap(const Scenario& scenario, const SurveyConfig& config, const std::function<void(double)>& progress) {
  RayCaster world;
  for (const TriangleMesh& m : scenario.mapMeshes()) world.addMesh(m);
  world.commit();
  // The surveyor carries a 32-beam LiDAR, which covers facades from near the ground to well above.
  LidarSpec lidar = vlp32c();
  lidar.range_noise = config.range_noise;
  lidar.max_range = config.max_range;
  const Route route(scenario.route_start, scenario.route_heading, scenario.route);
  RandomEngine rng(config.seed);
  // The surveyor's pose error (ErrorSources::map_*): every scan is placed where the surveyor believed it was.
  RandomEngine error_rng(config.seed ^ nameHash(scenario.name));
  const ErrorSources& e = scenario.errors;
  const SmoothError error_x(e.map_position_sd, e.map_error_length, error_rng), error_y(e.map_position_sd, e.map_error_length, error_rng),
      error_yaw(e.map_yaw_sd, e.map_error_length, error_rng);
  ndt::VoxelThinning merged(config.voxel);
  const int stops = std::max(1, static_cast<int>(std::floor(route.length() / config.spacing)) + 1);
  for (int i = 0; i < stops; ++i) {
    Eigen::Vector2d xy;
    double yaw, curvature;
    route.at(i * config.spacing, xy, yaw, curvature);
    const Eigen::Isometry3d pose = Eigen::Translation3d(xy.x(), xy.y(), config.lidar_height) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ());
    const double s = i * config.spacing;
    const Eigen::Isometry3d believed = Eigen::Translation3d(xy.x() + error_x(s), xy.y() + error_y(s), config.lidar_height) *
                                       Eigen::AngleAxisd(yaw + error_yaw(s), Eigen::Vector3d::UnitZ());
    for (const LidarPoint& p : scanSweep(lidar, world, [&](double) { return pose; }, rng))
      merged.add((believed * p.position.cast<double>()).cast<float>());
    // Thin as we go, so that memory follows the map's surface, not the number of scans.
    if (i % 10 == 9) merged.thin();
    if (progress) progress(static_cast<double>(i + 1) / stops);
  }
  merged.thin();
  return merged.release();
}

}  // namespace coloc::sim
