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
#include "cell_neighbours.hpp"
#include "voxel_index.hpp"
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

/// What one alignment remembers between evaluations of the radius neighbourhood: per point, its cell at
/// the last evaluation and that cell's voxels, the list the target's CellNeighbours keeps for every
/// alignment against it. A point still in the same cell costs no lookup, a point in another cell one
/// lookup in the shared lists (a cell no alignment has met yet: 27 hash probes, once). The sums are
/// the same bits as without the cache.
struct NeighbourCache {
  NeighbourCache(std::size_t points, const CellNeighbours& cells);

  static constexpr std::uint64_t kNoCell = ~0ULL;
  const CellNeighbours* cells_;
  std::vector<std::uint64_t> cell_;              ///< per point: its packed cell at the last evaluation
  std::vector<CellNeighbours::List> list_;       ///< per point: that cell's voxels
};

/// `cache` (radius neighbourhood only; else ignored): the alignment's memory of each point's voxels.
ScoreEvaluation evaluateScore(const VoxelLookup& voxels, double resolution, const ScoreConstants& constants,
                              const std::vector<Eigen::Vector3f>& source, const Vector6d& pose, const ScoreOptions& options,
                              NeighbourCache* cache = nullptr);

/// NVTL of the source at `pose` shifted by each translation (map frame), over the radius
/// neighbourhood: the same value per translation as evaluateScore's. Each shifted point looks at its
/// cell's list in `cells` (the target's, shared with the alignments), or in `cache` (the alignment's of
/// these points) when the shift leaves the point in the cell the alignment last saw it in.
std::vector<double> nvtlAtTranslations(const VoxelLookup& voxels, double resolution, const ScoreConstants& constants,
                                       const std::vector<Eigen::Vector3f>& source, const Vector6d& pose,
                                       const std::vector<Eigen::Vector3d>& translations, const CellNeighbours& cells, int threads = 0,
                                       const NeighbourCache* cache = nullptr);

/// Pose vector <-> homogeneous transform, in PCL's parametrisation.
Eigen::Matrix4d poseToMatrix(const Vector6d& pose);
Vector6d matrixToPose(const Eigen::Matrix4d& transform);

}  // namespace coloc::ndt
