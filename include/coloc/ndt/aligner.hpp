#pragma once
// Scan matching of a source cloud against an NdtTarget from an initial guess. Every result carries its
// quality scores and, if it must not reach the filter, the reason.
#include <string>

#include "coloc/ndt/ndt_config.hpp"
#include "coloc/ndt/ndt_target.hpp"

namespace coloc::ndt {

enum class AlignRejection {
  kNone,
  kMaxIterations,  ///< stopped by the iteration limit, not by convergence
  kOscillation,    ///< the steps kept reversing direction
  kLowScore,       ///< NVTL under the threshold: the scan does not fit the map here
  kEmptySource,    ///< nothing to align (empty or all points outside the map)
};
const char* toString(AlignRejection rejection);

struct AlignResult {
  Eigen::Matrix4d transform = Eigen::Matrix4d::Identity();  ///< maps source into target
  Matrix6d covariance = Matrix6d::Identity();  ///< (x, y, z, roll, pitch, yaw) in the target frame
  int iterations = 0;
  int oscillations = 0;
  double elapsed_ms = 0.0;            ///< the optimisation only (scores excluded)
  double transform_probability = 0.0; ///< PCL's score per point at the result
  double nvtl = 0.0;                  ///< nearest-voxel transformation likelihood at the result
  AlignRejection rejection = AlignRejection::kNone;
  std::string detail;                 ///< why, when rejected

  bool accepted() const { return rejection == AlignRejection::kNone; }
};

/// Throws coloc::Error for a non-finite guess; every other failure is a rejected result.
AlignResult align(const NdtTarget& target, const PointCloud& source, const Eigen::Matrix4d& guess, const NdtConfig& config);

}  // namespace coloc::ndt
