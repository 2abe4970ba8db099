#pragma once
// Every tunable of scan matching, with Autoware's ndt_scan_matcher defaults except where a comment
// says why coloc differs.
#include "coloc/core/types.hpp"

namespace coloc::ndt {

enum class NdtBackend {
  kPcl,   ///< pcl::NormalDistributionsTransform as shipped (single-threaded, radius search)
  kFast,  ///< coloc's aligner on PCL's voxel grid: same score, direct voxel lookup, threads
};

/// Which target voxels a transformed point is scored against (fast backend).
enum class Neighborhood {
  kRadius,  ///< voxels whose mean lies within one resolution: exactly PCL's radius search
  kFace7,   ///< the point's voxel and its six face neighbours (ndt_omp's DIRECT7)
  kSingle,  ///< the point's own voxel only (DIRECT1): fastest, needs a good initial guess
};

enum class CovarianceMode {
  kFixed,    ///< Autoware's fixed matrix, rotated into the map frame
  kLaplace,  ///< -H^-1 of the score's Hessian at the optimum, floored at the fixed matrix
};

struct NdtConfig {
  NdtBackend backend = NdtBackend::kFast;
  Neighborhood neighborhood = Neighborhood::kRadius;
  double resolution = 2.0;     ///< m, voxel size of the target
  double step_size = 0.1;      ///< m, the trust region's first radius (Autoware's longest step); grows while steps succeed
  /// PCL's criterion: stop when the squared translation of a step is below this. Autoware's
  /// trans_epsilon 0.01 is a 6-D step norm; its equivalent here is 1e-4 (1 cm).
  double transformation_epsilon = 1e-4;
  int max_iterations = 30;
  double outlier_ratio = 0.55;
  int threads = 0;  ///< fast backend; 0 = all cores
  /// Quality gate: nearest-voxel transformation likelihood at the result. Autoware's 2.3 assumes
  /// resolution 2.0 and its preprocessing.
  double nvtl_threshold = 2.3;
  int max_oscillations = 10;  ///< successive steps reversing direction before the result is refused
  CovarianceMode covariance = CovarianceMode::kFixed;
  /// x, y, z, roll, pitch, yaw variances (m^2, rad^2) of the fixed covariance.
  Vector6d fixed_covariance = (Vector6d() << 0.0225, 0.0225, 0.0225, 0.000625, 0.000625, 0.000625).finished();
};

}  // namespace coloc::ndt
