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
  /// Autoware's MULTI_NDT_SCORE: the NVTL at poses offset from the optimum along and across the
  /// heading (Autoware's offsets: 0.5 and 1 m along, 0.5 m across) and, unlike Autoware, turned about
  /// it (`score_yaw_offset_deg`); their softmax weights give a weighted covariance of x/y and yaw,
  /// floored at the fixed matrix. It sees a score that is flat along a direction, which the Hessian at
  /// the optimum does not: repeated structure curves the score locally but holds nothing in place.
  kMultiNdtScore,
};

/// The configuration's word for each mode (`ndt.covariance`, `coloc align --covariance`).
inline const char* covarianceModeName(CovarianceMode mode) {
  switch (mode) {
    case CovarianceMode::kFixed: return "fixed";
    case CovarianceMode::kLaplace: return "laplace";
    case CovarianceMode::kMultiNdtScore: return "multi_ndt_score";
  }
  return "?";
}

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
  /// multi_ndt_score by default, not Autoware's fixed matrix: the fixed 15 cm makes the filter follow
  /// the odometry's error for seconds where NDT is a centimetre good (the twin's uncalibrated start:
  /// fused 2.74x NDT's own error with `fixed`, 1.06x with this), while the score's spread along and
  /// across the heading still says where a corridor holds nothing. What the score cannot see, NDT's
  /// bias (a match off the truth that every scan repeats), the pipeline's travel and fix-agreement
  /// checks widen; docs/ndt.md, "Covariance". `fixed` gives Autoware's behaviour.
  CovarianceMode covariance = CovarianceMode::kMultiNdtScore;
  /// x, y, z, roll, pitch, yaw variances (m^2, rad^2) of the fixed covariance.
  Vector6d fixed_covariance = (Vector6d() << 0.0225, 0.0225, 0.0225, 0.000625, 0.000625, 0.000625).finished();
  /// laplace and multi_ndt_score: each variance at least this (the rotated x/y block in every
  /// direction for multi_ndt_score). x and y at a centimetre: a real match is not better than the
  /// map's survey, and a score-based covariance below it lets ten poses a second, each repeating the
  /// last one's small bias, outvote a fix. z, roll, pitch and yaw at Autoware's fixed figures, which
  /// the filter's 2-D state and its yaw-bias state were tuned with.
  Vector6d covariance_floor = (Vector6d() << 1e-4, 1e-4, 0.0225, 0.000625, 0.000625, 0.000625).finished();
  /// multi_ndt_score: the softmax temperature on NVTL: an offset whose NVTL is this much below the
  /// optimum's weighs 1/e of it. Autoware's 0.05 makes the ground of an open road, which scores alike
  /// a metre along, outweigh the structure that holds the scan (10-50 cm along the road where NDT is
  /// within 2 cm); 0.02 keeps the floor there and still sees the open stretch of the twin's site B,
  /// where 0.01 no longer does (docs/experiment.md, "The filter against its best input").
  double score_temperature = 0.02;
  /// multi_ndt_score: yaw probes at +-1 and +-2 times this (deg); 0 = x/y only, as Autoware. Equal
  /// weights over five probes give a variance of 2 x this squared, so they matter only under a yaw
  /// floor below that (Autoware's fixed yaw is 1.4 deg: off by default, four score evaluations saved).
  double score_yaw_offset_deg = 0.0;
};

}  // namespace coloc::ndt
