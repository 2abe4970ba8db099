#pragma once
// A map cloud made ready for scan matching: PCL's voxel grid of normal distributions
// (pcl::VoxelGridCovariance, the structure PCL's NDT scores against) plus a hash from voxel
// coordinates to voxels for direct lookup. Immutable once built, so one target can serve alignments
// on several threads while a new one is being built for the next map region.
#include <memory>

#include "coloc/ndt/ndt_config.hpp"
#include "coloc/ndt/point_cloud.hpp"

namespace coloc::ndt {

class NdtTarget {
 public:
  /// Throws coloc::Error if the cloud is empty or yields no voxel with enough points.
  NdtTarget(const PointCloud& map, const NdtConfig& config);
  ~NdtTarget();
  NdtTarget(NdtTarget&&) noexcept;
  NdtTarget& operator=(NdtTarget&&) noexcept;

  std::size_t voxelCount() const;  ///< voxels with a usable covariance
  std::size_t pointCount() const;
  double resolution() const;

  struct Impl;
  const Impl& impl() const { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace coloc::ndt
