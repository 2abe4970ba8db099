#pragma once
// A cloud thinned again and again as it grows, as a survey merges its scans and keeps memory to the
// map's surface: after each thin() the cloud is voxelDownsample(the cloud + the points added since), to
// the bit, but a pass bins only the added points instead of the whole map anew (a site's survey
// re-binned millions of map points at every pass).
#include <memory>

#include "coloc/ndt/point_cloud.hpp"

namespace coloc::ndt {

class VoxelThinning {
 public:
  /// voxel_size <= 0: no thinning, as voxelDownsample.
  explicit VoxelThinning(double voxel_size);
  ~VoxelThinning();
  VoxelThinning(VoxelThinning&&) noexcept;
  VoxelThinning& operator=(VoxelThinning&&) noexcept;

  void add(const Eigen::Vector3f& point);
  /// cloud() becomes voxelDownsample(cloud() + the points added since the last thin(), in that order).
  void thin();
  /// The cloud as of the last thin() (points only; the points added since are not in it).
  const PointCloud& cloud() const;
  /// The cloud, moved out; the thinning starts empty again.
  PointCloud release();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace coloc::ndt
