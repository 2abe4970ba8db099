// ndt's own range checks, so that every way in (config file, command line, a linked program) refuses
// the same values with the same words.
#include <cmath>
#include <string>

#include "coloc/core/error.hpp"
#include "coloc/ndt/ndt_pose_source.hpp"

namespace coloc::ndt {

namespace {

void require(bool ok, const char* key, const std::string& why) {
  if (!ok) throw Error(std::string("ndt.") + key + ": " + why);
}

void positive(double v, const char* key) { require(std::isfinite(v) && v > 0.0, key, "must be a finite number > 0"); }

}  // namespace

void validate(const NdtPoseSourceConfig& c) {
  positive(c.ndt.resolution, "resolution");
  positive(c.ndt.step_size, "step_size");
  positive(c.ndt.transformation_epsilon, "transformation_epsilon");
  require(c.ndt.max_iterations >= 1, "max_iterations", "must be >= 1");
  require(c.ndt.outlier_ratio > 0.0 && c.ndt.outlier_ratio < 1.0, "outlier_ratio", "must be in (0, 1)");
  require(c.ndt.threads >= 0, "threads", "must be >= 0 (0 = all cores)");
  require(std::isfinite(c.ndt.nvtl_threshold), "nvtl_threshold", "must be finite");
  require(c.ndt.max_oscillations >= 1, "max_oscillations", "must be >= 1");
  for (int i = 0; i < 6; ++i)
    require(c.ndt.fixed_covariance[i] > 0.0 && !std::isnan(c.ndt.fixed_covariance[i]), "fixed_covariance",
            "variances must be > 0 (.inf for not measured)");
  for (int i = 0; i < 6; ++i)
    require(c.ndt.covariance_floor[i] > 0.0 && std::isfinite(c.ndt.covariance_floor[i]), "covariance_floor", "variances must be finite and > 0");
  require(std::isfinite(c.ndt.score_temperature) && c.ndt.score_temperature > 0.0, "score_temperature", "must be a finite number > 0");
  require(std::isfinite(c.ndt.score_yaw_offset_deg) && c.ndt.score_yaw_offset_deg >= 0.0 && c.ndt.score_yaw_offset_deg <= 45.0,
          "score_yaw_offset_deg", "must be in [0, 45] deg (0 = no yaw probes)");
  require(std::isfinite(c.preprocess.min_range) && c.preprocess.min_range >= 0.0, "min_range", "must be a finite number >= 0");
  positive(c.preprocess.max_range, "max_range");
  require(c.preprocess.min_range < c.preprocess.max_range, "min_range", "must be below max_range");
  require(std::isfinite(c.preprocess.voxel_size) && c.preprocess.voxel_size >= 0.0, "voxel_size", "must be a finite number >= 0 (0 = off)");
  require(c.lidar_pose.allFinite(), "lidar_pose", "must be finite");
  positive(c.map.radius, "map_radius");
  positive(c.map.update_distance, "map_update_distance");
}

}  // namespace coloc::ndt
