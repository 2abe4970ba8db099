#include "voxel_grid.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <string>
#include <exception>
#include <thread>
#include <utility>

#include "coloc/core/error.hpp"
#include "voxel_index.hpp"

namespace coloc::ndt {

namespace {

constexpr int kMinPointsPerVoxel = 6;          // PCL's VoxelGridCovariance default
constexpr double kMinCovarianceEigenRatio = 0.01;  // its min_covar_eigvalue_mult_

// A voxel's running sums; the outer products keep their 6 distinct entries (xx xy xz yy yz zz), each
// summed in point order as PCL sums the full matrix.
struct Sums {
  Eigen::Vector3i ijk;
  int n = 0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;
};

// A voxel's mean and inverse covariance as PCL computes them; false for a voxel PCL leaves out.
bool statistics(const Sums& s, Voxel& voxel) {
  if (s.n < kMinPointsPerVoxel) return false;
  // PCL's single-pass covariance: (sum x x^T - sum x mean^T) / (n - 1).
  const Eigen::Vector3d mean = s.sum / s.n;
  Eigen::Matrix3d outer;
  outer << s.xx, s.xy, s.xz, s.xy, s.yy, s.yz, s.xz, s.yz, s.zz;
  Eigen::Matrix3d covariance = (outer - s.sum * mean.transpose()) / (s.n - 1.0);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  Eigen::Matrix3d values = solver.eigenvalues().asDiagonal();
  const Eigen::Matrix3d vectors = solver.eigenvectors();
  if (values(0, 0) < -Eigen::NumTraits<double>::dummy_precision() || values(1, 1) < -Eigen::NumTraits<double>::dummy_precision() ||
      values(2, 2) <= 0)
    return false;  // degenerate: PCL drops it
  // Flat and linear voxels are thickened (Magnusson 2009, eq. 6.11) so that they can be inverted.
  const double floor_value = kMinCovarianceEigenRatio * values(2, 2);
  if (values(0, 0) < floor_value) {
    values(0, 0) = floor_value;
    if (values(1, 1) < floor_value) values(1, 1) = floor_value;
    covariance = vectors * values * vectors.inverse();
  }
  const Eigen::Matrix3d inverse_covariance = covariance.inverse();
  if (inverse_covariance.maxCoeff() == std::numeric_limits<float>::infinity() ||
      inverse_covariance.minCoeff() == -std::numeric_limits<float>::infinity())
    return false;
  voxel = {mean, inverse_covariance};
  return true;
}

}  // namespace

namespace {

// One thread's share: the voxels whose hash falls in `part` of `parts`, with their points summed in
// point order (so that each voxel's sums are PCL's, bit for bit), then their statistics.
void buildPart(const std::vector<Eigen::Vector3f>& points, float leaf, unsigned part, unsigned parts,
               std::vector<std::pair<Eigen::Vector3i, Voxel>>& out) {
  // PCL: ijk = floor(p * (1 / leaf)), all in float.
  const float inverse = 1.0f / leaf;
  PackedVoxelIndex index;
  std::vector<Sums> sums;
  for (const Eigen::Vector3f& p : points) {
    if (!p.allFinite()) continue;  // as PCL's grid never sees them (toPcl leaves them out)
    const Eigen::Vector3f scaled = p * inverse;
    // Checked before the conversion to int, which would be undefined for a value out of its range.
    if (!(scaled.array().abs() < static_cast<float>(VoxelLookup::kMaxCoordinate - 1)).all())
      throw Error("NDT target: a map point at (" + std::to_string(p.x()) + ", " + std::to_string(p.y()) + ", " + std::to_string(p.z()) +
                  ") lies beyond the voxels a " + std::to_string(leaf) + " m grid can address; re-centre the map");
    const Eigen::Vector3i ijk(static_cast<int>(std::floor(scaled.x())), static_cast<int>(std::floor(scaled.y())),
                              static_cast<int>(std::floor(scaled.z())));
    const std::uint64_t key = VoxelLookup::pack(ijk);
    if ((VoxelLookup::hash(key) >> 32) % parts != part) continue;
    const auto [at, added] = index.insert(key);
    if (added) sums.push_back(Sums{ijk});
    Sums& s = sums[at];
    const Eigen::Vector3d q = p.cast<double>();
    s.sum += q;
    s.xx += q.x() * q.x();
    s.xy += q.x() * q.y();
    s.xz += q.x() * q.z();
    s.yy += q.y() * q.y();
    s.yz += q.y() * q.z();
    s.zz += q.z() * q.z();
    ++s.n;
  }
  out.reserve(sums.size());
  Voxel voxel;
  for (const Sums& s : sums)
    if (statistics(s, voxel)) out.emplace_back(s.ijk, voxel);
}

}  // namespace

void buildVoxels(const std::vector<Eigen::Vector3f>& points, float leaf, VoxelLookup& out) {
  // Two threads, each owning half of the voxels: the pass over the points is bound by cache misses
  // into the sums, and each thread's table is half the size.
  constexpr unsigned kParts = 2;
  std::vector<std::pair<Eigen::Vector3i, Voxel>> voxels[kParts];
  std::exception_ptr failure;
  std::thread other([&] {
    try {
      buildPart(points, leaf, 1, kParts, voxels[1]);
    } catch (...) {
      failure = std::current_exception();
    }
  });
  try {
    buildPart(points, leaf, 0, kParts, voxels[0]);
  } catch (...) {
    other.join();
    throw;
  }
  other.join();
  if (failure) std::rethrow_exception(failure);
  out.reserve(voxels[0].size() + voxels[1].size());
  for (const auto& part : voxels)
    for (const auto& [ijk, voxel] : part) out.insert(ijk, voxel);
  out.finish();
}

}  // namespace coloc::ndt
