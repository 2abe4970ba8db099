#pragma once
// NdtTarget's insides; PCL appears only here and in the .cpp files of ndt/.
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/ndt.h>

#include <memory>

#include "coloc/ndt/ndt_target.hpp"
#include "ndt_score.hpp"
#include "voxel_lookup.hpp"

namespace coloc::ndt {

using PclPoint = pcl::PointXYZ;
using PclCloud = pcl::PointCloud<PclPoint>;

/// PCL's NDT with its voxel grid made readable, so that scores and the direct lookup are built from the
/// very voxels PCL aligns against.
class ExposedNdt : public pcl::NormalDistributionsTransform<PclPoint, PclPoint> {
 public:
  const TargetGrid& grid() const { return target_cells_; }
};

struct NdtTarget::Impl {
  NdtConfig config;
  ScoreConstants constants;
  PclCloud::Ptr cloud;  ///< the stock backend's input (the fast backend needs no PCL copy)
  std::size_t point_count = 0;  ///< finite map points the target was built from
  /// The stock backend aligns with this object; its voxel grid also feeds `voxels`.
  std::shared_ptr<ExposedNdt> pcl_ndt;
  VoxelLookup voxels;
  /// Each cell's reachable voxels, shared by every alignment against the target.
  std::unique_ptr<CellNeighbours> neighbours;
};

PclCloud::Ptr toPcl(const PointCloud& cloud);

}  // namespace coloc::ndt
