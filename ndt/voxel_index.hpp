#pragma once
// A key (a voxel's coordinates, packed or not) -> a dense index 0, 1, 2, ... in order of first
// appearance: open addressing that starts small and doubles, so that a pass over a cloud's points
// touches a table that stays in cache (a cloud has far fewer voxels than points). Used wherever points
// are binned by voxel.
#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

namespace coloc::ndt {

template <typename Key, typename Hash>
class DenseIndex {
 public:
  DenseIndex() : slots_(4096), mask_(4095) {}

  /// The index of `key` and whether it is new (its index is then size() - 1).
  std::pair<std::size_t, bool> insert(const Key& key) {
    for (std::size_t i = Hash()(key) & mask_;; i = (i + 1) & mask_) {
      Slot& s = slots_[i];
      if (s.index == kFree) {
        if (2 * (size_ + 1) > slots_.size()) {
          grow();
          slots_[free(key)] = {key, static_cast<std::uint32_t>(size_)};
        } else {
          s = {key, static_cast<std::uint32_t>(size_)};
        }
        return {size_++, true};
      }
      if (s.key == key) return {s.index, false};
    }
  }
  std::size_t size() const { return size_; }
  static constexpr std::size_t kNone = ~std::size_t{0};
  /// The index of `key`, kNone if it has none.
  std::size_t find(const Key& key) const {
    for (std::size_t i = Hash()(key) & mask_;; i = (i + 1) & mask_) {
      const Slot& s = slots_[i];
      if (s.index == kFree) return kNone;
      if (s.key == key) return s.index;
    }
  }

 private:
  static constexpr std::uint32_t kFree = 0xFFFFFFFFu;  // more voxels than that do not fit in memory anyway
  struct Slot {
    Key key{};
    std::uint32_t index = kFree;
  };
  std::size_t free(const Key& key) const {
    std::size_t i = Hash()(key) & mask_;
    while (slots_[i].index != kFree) i = (i + 1) & mask_;
    return i;
  }
  void grow() {
    std::vector<Slot> old(slots_.size() * 2);
    old.swap(slots_);
    mask_ = slots_.size() - 1;
    for (const Slot& s : old)
      if (s.index != kFree) slots_[free(s.key)] = s;
  }
  std::vector<Slot> slots_;
  std::size_t mask_;
  std::size_t size_ = 0;
};

/// murmur3's 64-bit finaliser: every input bit reaches the low bits a table uses.
inline std::uint64_t mixBits(std::uint64_t h) {
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdULL;
  h ^= h >> 33;
  return h;
}

// floor(v) as an integer voxel coordinate, false for a value that is not finite or whose voxel is
// beyond 2e9 (integer arithmetic: floor() has no instruction on the baseline x86-64 this is built for).
inline bool voxelCoordinate(double v, std::int32_t& out) {
  if (!(std::abs(v) < 4e9)) return false;
  std::int64_t k = static_cast<std::int64_t>(v);  // toward zero
  if (static_cast<double>(k) > v) --k;
  if (!(std::abs(static_cast<double>(k)) < 2e9)) return false;
  out = static_cast<std::int32_t>(k);
  return true;
}

/// Integer voxel coordinates over the whole int32 range.
struct VoxelCoordinates {
  std::int32_t x = 0, y = 0, z = 0;
  bool operator==(const VoxelCoordinates& o) const { return x == o.x && y == o.y && z == o.z; }
};
/// The voxel of (x, y, z) with voxels 1 / `inverse` wide; false for a point that has none.
inline bool voxelOf(double x, double y, double z, double inverse, VoxelCoordinates& key) {
  return voxelCoordinate(x * inverse, key.x) && voxelCoordinate(y * inverse, key.y) && voxelCoordinate(z * inverse, key.z);
}
struct VoxelCoordinatesHash {
  std::size_t operator()(const VoxelCoordinates& c) const {
    return static_cast<std::size_t>(mixBits(static_cast<std::uint32_t>(c.x) * 0x9E3779B97F4A7C15ULL ^
                                            static_cast<std::uint32_t>(c.y) * 0xC2B2AE3D27D4EB4FULL ^
                                            static_cast<std::uint32_t>(c.z) * 0x165667B19E3779F9ULL));
  }
};
using VoxelIndex = DenseIndex<VoxelCoordinates, VoxelCoordinatesHash>;

/// Voxel coordinates packed into 64 bits (VoxelLookup::pack, whose table hashes them the same way).
struct PackedVoxelHash {
  std::size_t operator()(std::uint64_t key) const { return static_cast<std::size_t>(mixBits(key)); }
};
using PackedVoxelIndex = DenseIndex<std::uint64_t, PackedVoxelHash>;

}  // namespace coloc::ndt
