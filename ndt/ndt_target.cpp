#include "coloc/ndt/ndt_target.hpp"

#include <algorithm>
#include <cmath>

#include "coloc/core/error.hpp"
#include "target_impl.hpp"
#include "voxel_grid.hpp"

namespace coloc::ndt {

namespace {

// Copies the usable leaves (enough points for a covariance) of a PCL voxel grid into the lookup.
void fillLookup(const pcl::VoxelGridCovariance<PclPoint>& const_grid, VoxelLookup& lookup) {
  // PCL's accessors are not const-qualified, though they only read.
  auto& grid = const_cast<pcl::VoxelGridCovariance<PclPoint>&>(const_grid);
  const auto& leaves = grid.getLeaves();
  const Eigen::Vector3i min_b = grid.getMinBoxCoordinates();
  const Eigen::Vector3i mul = grid.getDivisionMultiplier();
  lookup.reserve(leaves.size());
  for (const auto& [index, leaf] : leaves) {
    if (leaf.nr_points < grid.getMinPointPerVoxel()) continue;
    // PCL's leaf index is (ijk - min_b) . (1, div_x, div_x * div_y); undo it to get the voxel's coordinates.
    const int i = static_cast<int>(index);
    const Eigen::Vector3i ijk(i % mul[1] + min_b[0], (i % mul[2]) / mul[1] + min_b[1], i / mul[2] + min_b[2]);
    lookup.insert(ijk, {leaf.getMean(), leaf.getInverseCov()});
  }
  lookup.finish();
}

}  // namespace

PclCloud::Ptr toPcl(const PointCloud& cloud) {
  auto out = std::make_shared<PclCloud>();
  out->reserve(cloud.size());
  for (const Eigen::Vector3f& p : cloud.points) {
    if (!p.allFinite()) continue;  // PCL's voxel grid trusts is_dense; non-finite points never reach it
    PclPoint q;
    q.getVector3fMap() = p;
    out->push_back(q);
  }
  out->width = static_cast<std::uint32_t>(out->size());
  out->height = 1;
  out->is_dense = true;
  return out;
}

NdtTarget::NdtTarget(const PointCloud& map, const NdtConfig& config) : impl_(std::make_unique<Impl>()) {
  if (map.empty()) throw Error("NDT target: the map cloud is empty");
  if (!(config.resolution > 0.0 && std::isfinite(config.resolution))) throw Error("NDT target: resolution must be > 0");
  Impl& d = *impl_;
  d.config = config;
  d.constants = scoreConstants(config.resolution, config.outlier_ratio);
  if (config.backend == NdtBackend::kPcl) {
    d.cloud = toPcl(map);
    d.point_count = d.cloud->size();
    if (d.point_count == 0) throw Error("NDT target: the map cloud holds no finite point");
    d.pcl_ndt = std::make_shared<ExposedNdt>();
    d.pcl_ndt->setResolution(static_cast<float>(config.resolution));
    d.pcl_ndt->setStepSize(config.step_size);
    d.pcl_ndt->setTransformationEpsilon(config.transformation_epsilon);
    d.pcl_ndt->setMaximumIterations(config.max_iterations);
    d.pcl_ndt->setOulierRatio  /* sic, PCL 1.13 */(config.outlier_ratio);
    d.pcl_ndt->setInputTarget(d.cloud);
    fillLookup(d.pcl_ndt->grid(), d.voxels);
  } else {
    // The same voxels as PCL's grid (tested), built with a hash: PCL's std::map dominated the build.
    d.point_count = static_cast<std::size_t>(
        std::count_if(map.points.begin(), map.points.end(), [](const Eigen::Vector3f& p) { return p.allFinite(); }));
    if (d.point_count == 0) throw Error("NDT target: the map cloud holds no finite point");
    buildVoxels(map.points, static_cast<float>(config.resolution), d.voxels);
  }
  if (d.voxels.size() == 0)
    throw Error("NDT target: no voxel of " + std::to_string(config.resolution) +
                " m holds the 6 points a covariance needs; the map is too sparse for this resolution");
  d.neighbours = std::make_unique<CellNeighbours>(d.voxels, config.resolution);
}

NdtTarget::~NdtTarget() = default;
NdtTarget::NdtTarget(NdtTarget&&) noexcept = default;
NdtTarget& NdtTarget::operator=(NdtTarget&&) noexcept = default;

std::size_t NdtTarget::voxelCount() const { return impl_->voxels.size(); }
std::size_t NdtTarget::pointCount() const { return impl_->point_count; }
double NdtTarget::resolution() const { return impl_->config.resolution; }

}  // namespace coloc::ndt
