#include "voxel_lookup.hpp"

namespace coloc::ndt {

void VoxelLookup::reserve(std::size_t voxels) {
  voxels_.reserve(voxels);
  coordinates_.reserve(voxels);
}

void VoxelLookup::insert(const Eigen::Vector3i& coordinates, const Voxel& voxel) {
  voxels_.push_back(voxel);
  coordinates_.push_back(coordinates);
}

void VoxelLookup::finish() {
  // Load factor at most 1/2 keeps probe sequences short.
  std::size_t capacity = 16;
  while (capacity < 2 * voxels_.size()) capacity *= 2;
  slots_.assign(capacity, Slot{});
  mask_ = capacity - 1;
  for (std::size_t v = 0; v < voxels_.size(); ++v) {
    const std::uint64_t key = pack(coordinates_[v]);
    std::size_t i = hash(key) & mask_;
    while (slots_[i].voxel >= 0) i = (i + 1) & mask_;
    slots_[i] = {key, static_cast<std::int64_t>(v)};
  }
  coordinates_.clear();
  coordinates_.shrink_to_fit();
}

}  // namespace coloc::ndt
