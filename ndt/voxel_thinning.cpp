#include "coloc/ndt/voxel_thinning.hpp"

#include <utility>
#include <vector>

#include "voxel_index.hpp"

namespace coloc::ndt {

// Why a pass need not see the old points: the cloud's points are each alone in their voxel, so a
// downsampling of (cloud + new points) keeps the cloud's voxels first, in the cloud's order (its points
// come first), then the new voxels in order of first appearance; a voxel without new points gives its
// point back unchanged ((0 + x) / 1 is x, x a float, and 0 + x is never -0); one with new points gives
// (0 + x + p1 + p2 ...) / (1 + n). Each centroid stays in its voxel, so the cloud's points stay alone in
// theirs: a mean can only leave its voxel near a bound, where all its points are, of like magnitude,
// and the sum of such floats in double is exact; the mean, rounded once, then lies between the
// smallest and the largest of them, and scaling and rounding are monotonic, so its voxel is theirs
// (nor is it -0: the points of a voxel below 0 are at most the largest negative float). The tests
// put points on and around voxel bounds, -0 and denormals through pass after pass.
struct VoxelThinning::Impl {
  static constexpr std::uint32_t kUntouched = 0xFFFFFFFFu;
  struct Sum {
    std::size_t voxel;
    double x = 0.0, y = 0.0, z = 0.0;
    int count = 0;
  };

  double voxel_size, inverse;
  PointCloud cloud;
  std::vector<Eigen::Vector3f> added;
  VoxelIndex index;                   ///< voxel -> its point in `cloud`
  std::vector<std::uint32_t> sum_of;  ///< per point of `cloud`: its Sum in this pass, or kUntouched
  std::vector<Sum> sums;

  explicit Impl(double size) : voxel_size(size), inverse(1.0 / size) {}

  void pass() {
    sums.clear();
    for (const Eigen::Vector3f& p : added) {
      const double x = p.x(), y = p.y(), z = p.z();
      VoxelCoordinates key;
      if (!voxelOf(x, y, z, inverse, key)) continue;  // as voxelDownsample: a point without a voxel is left out
      const auto [voxel, fresh] = index.insert(key);
      if (fresh) {
        cloud.points.emplace_back();
        sum_of.push_back(kUntouched);
      }
      std::uint32_t& s = sum_of[voxel];
      if (s == kUntouched) {
        s = static_cast<std::uint32_t>(sums.size());
        Sum& sum = sums.emplace_back();
        sum.voxel = voxel;
        if (!fresh) {  // the voxel's point from the cloud, first
          const Eigen::Vector3f& q = cloud.points[voxel];
          sum.x += q.x();
          sum.y += q.y();
          sum.z += q.z();
          sum.count = 1;
        }
      }
      Sum& sum = sums[s];
      sum.x += x;
      sum.y += y;
      sum.z += z;
      ++sum.count;
    }
    for (const Sum& s : sums) {
      cloud.points[s.voxel] = Eigen::Vector3f(static_cast<float>(s.x / s.count), static_cast<float>(s.y / s.count), static_cast<float>(s.z / s.count));
      sum_of[s.voxel] = kUntouched;
    }
  }
};

VoxelThinning::VoxelThinning(double voxel_size) : impl_(std::make_unique<Impl>(voxel_size)) {}
VoxelThinning::~VoxelThinning() = default;
VoxelThinning::VoxelThinning(VoxelThinning&&) noexcept = default;
VoxelThinning& VoxelThinning::operator=(VoxelThinning&&) noexcept = default;

void VoxelThinning::add(const Eigen::Vector3f& point) { impl_->added.push_back(point); }

void VoxelThinning::thin() {
  Impl& m = *impl_;
  if (m.voxel_size > 0.0)
    m.pass();
  else
    m.cloud.points.insert(m.cloud.points.end(), m.added.begin(), m.added.end());
  m.added.clear();
}

const PointCloud& VoxelThinning::cloud() const { return impl_->cloud; }

PointCloud VoxelThinning::release() {
  PointCloud out = std::move(impl_->cloud);
  impl_ = std::make_unique<Impl>(impl_->voxel_size);
  return out;
}

}  // namespace coloc::ndt
