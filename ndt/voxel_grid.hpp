#pragma once
// The NDT target's voxels built with a hash instead of PCL's std::map: each point goes to the voxel
// PCL's VoxelGridCovariance puts it in (the same float arithmetic), the sums are accumulated in the
// same order, and a voxel's mean and inverse covariance are computed as PCL computes them (at least 6
// points, the smaller eigenvalues raised to 1 % of the largest, singular voxels dropped): the same
// statistics, bit for bit, in a fraction of the time. No PCL type here.
#include <Eigen/Core>
#include <vector>

#include "voxel_lookup.hpp"

namespace coloc::ndt {

/// Fills `out` (and finishes it) from the finite `points` at voxel size `leaf`, on two threads. Throws
/// coloc::Error when a point lies beyond the +-1e6 voxels the lookup can address.
void buildVoxels(const std::vector<Eigen::Vector3f>& points, float leaf, VoxelLookup& out);

}  // namespace coloc::ndt
