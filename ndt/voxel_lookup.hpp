#pragma once
// Direct lookup of NDT voxels by integer voxel coordinates: an open-addressing hash over the usable
// voxels (built by voxel_grid.hpp, or copied from PCL's grid for the stock backend), with each voxel's
// mean and inverse covariance stored contiguously. Replaces the k-d tree radius search PCL's NDT does
// for every point and iteration.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "voxel_index.hpp"

namespace coloc::ndt {

struct Voxel {
  Eigen::Vector3d mean;
  Eigen::Matrix3d inverse_covariance;
};

class VoxelLookup {
 public:
  void reserve(std::size_t voxels);
  void insert(const Eigen::Vector3i& coordinates, const Voxel& voxel);
  /// Call after the last insert.
  void finish();

  const Voxel* find(const Eigen::Vector3i& coordinates) const {
    const std::int64_t i = indexOf(coordinates);
    return i < 0 ? nullptr : &voxels_[static_cast<std::size_t>(i)];
  }
  /// The voxel's position in voxels(), -1 if there is none at these coordinates.
  std::int64_t indexOf(const Eigen::Vector3i& coordinates) const {
    if (slots_.empty()) return -1;
    const std::uint64_t key = pack(coordinates);
    for (std::size_t i = hash(key) & mask_;; i = (i + 1) & mask_) {
      const Slot& s = slots_[i];
      if (s.voxel < 0 || s.key == key) return s.voxel;
    }
  }

  std::size_t size() const { return voxels_.size(); }
  const std::vector<Voxel>& voxels() const { return voxels_; }

  /// Voxel coordinates must be within (-kMaxCoordinate, kMaxCoordinate) on each axis.
  static constexpr int kMaxCoordinate = 1 << 20;
  static std::uint64_t pack(const Eigen::Vector3i& c) {
    // 21 bits per axis with an offset: +-1e6 voxels, i.e. +-2000 km at 2 m resolution.
    constexpr std::int64_t kOffset = kMaxCoordinate;
    return (static_cast<std::uint64_t>(c.x() + kOffset) << 42) | (static_cast<std::uint64_t>(c.y() + kOffset) << 21) |
           static_cast<std::uint64_t>(c.z() + kOffset);
  }
  static std::uint64_t hash(std::uint64_t key) { return mixBits(key); }

 private:
  struct Slot {
    std::uint64_t key = 0;
    std::int64_t voxel = -1;
  };

  std::vector<Voxel> voxels_;
  std::vector<Eigen::Vector3i> coordinates_;
  std::vector<Slot> slots_;
  std::size_t mask_ = 0;
};

}  // namespace coloc::ndt
