#pragma once
// The NDT score function of PCL's NormalDistributionsTransform (Magnusson 2009, ch. 6) and its first
// and second derivatives with respect to the pose, evaluated over a source cloud in parallel.
//
// Pose vector p = [x, y, z, a, b, c] with rotation R = Rx(a) Ry(b) Rz(c), PCL's parametrisation, so
// that both backends walk the same landscape. Per point-voxel pair, with q = R x + t - mean and C the
// voxel's inverse covariance: s = -d1 exp(-d2/2 q'Cq) (d1 < 0, so the score is positive and maximised).
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "coloc/core/types.hpp"
#include "coloc/ndt/ndt_config.hpp"
#include "voxel_lookup.hpp"

namespace coloc::ndt {

struct ScoreConstants {
  double d1 = 0.0, d2 = 0.0;
};

/// PCL's Gaussian fitting constants for a voxel size and outlier ratio.
ScoreConstants scoreConstants(double resolution, double outlier_ratio);

struct ScoreOptions {
  Neighborhood neighborhood = Neighborhood::kRadius;
  bool gradient = true;
  bool hessian = true;
  bool nvtl = false;  ///< also the best voxel's score per point (always over the radius neighbourhood)
  int threads = 0;    ///< 0 = all cores
};

struct ScoreEvaluation {
  double score = 0.0;  ///< sum over point-voxel pairs
  Vector6d gradient = Vector6d::Zero();
  Matrix6d hessian = Matrix6d::Zero();
  double nvtl_sum = 0.0;       ///< sum over points of their best voxel's score
  std::size_t nvtl_points = 0; ///< points with at least one voxel in reach
};

/// What one alignment remembers between evaluations of the radius neighbourhood: for each source
/// point, the voxels whose means lay within resolution + margin of where the point was last gathered.
/// While a point stays within `margin` of that place, every voxel within one resolution of it is on
/// its list, which is kept in the order the 27-cell search visits voxels, so the sums are the same
/// bits as without the cache; a point that moved farther is gathered again. Saves the 27 hash probes
/// per point and evaluation that otherwise dominate an evaluation.
struct NeighbourCache {
  NeighbourCache(std::size_t points, double resolution, double margin);

  static constexpr int kMaxCandidates = 48;
  static constexpr std::uint8_t kUnset = 255, kOverflow = 254;
  double resolution_, margin_;
  std::vector<Eigen::Vector3d> at_;
  std::vector<std::uint8_t> count_;
  std::vector<std::uint32_t> candidates_;  ///< kMaxCandidates per point
};

/// `cache` (radius neighbourhood only; else ignored): the alignment's memory of each point's voxels.
ScoreEvaluation evaluateScore(const VoxelLookup& voxels, double resolution, const ScoreConstants& constants,
                              const std::vector<Eigen::Vector3f>& source, const Vector6d& pose, const ScoreOptions& options,
                              NeighbourCache* cache = nullptr);

/// Pose vector <-> homogeneous transform, in PCL's parametrisation.
Eigen::Matrix4d poseToMatrix(const Vector6d& pose);
Vector6d matrixToPose(const Eigen::Matrix4d& transform);

}  // namespace coloc::ndt
