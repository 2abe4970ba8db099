#include "cell_neighbours.hpp"

#include <algorithm>
#include <mutex>

#include "voxel_index.hpp"

namespace coloc::ndt {

void gatherCell(const VoxelLookup& voxels, double resolution, const Eigen::Vector3i& cell, std::vector<std::uint32_t>& out) {
  // A point in the cell is nearer to a mean than the box is, so no voxel within reach of a point is
  // left out (the slack covers a point rounded onto the cell from outside).
  const Eigen::Vector3d low = cell.cast<double>() * resolution, high = low + Eigen::Vector3d::Constant(resolution);
  const double reach = resolution * (1.0 + 1e-6), reach_sq = reach * reach;
  for (int x = -1; x <= 1; ++x)
    for (int y = -1; y <= 1; ++y)
      for (int z = -1; z <= 1; ++z) {
        const std::int64_t v = voxels.indexOf(cell + Eigen::Vector3i(x, y, z));
        if (v < 0) continue;
        const Eigen::Vector3d& mean = voxels.voxels()[static_cast<std::size_t>(v)].mean;
        if ((mean.cwiseMax(low).cwiseMin(high) - mean).squaredNorm() <= reach_sq) out.push_back(static_cast<std::uint32_t>(v));
      }
}

namespace {

// 16 shards: the threads of a vehicle or an experiment (two to eight) seldom want the same lock, and an
// unused target costs little (each shard's table starts at 64 KB, its first block at 16 KB).
constexpr int kShardBits = 4;
constexpr std::size_t kBlock = 1 << 12;  // list storage comes in blocks of this many indices; a list (<= 27) fits in one

}  // namespace

struct CellNeighbours::Shard {
  std::mutex mutex;
  PackedVoxelIndex index;                             ///< packed cell -> list number
  std::vector<List> lists;
  std::vector<std::unique_ptr<std::uint32_t[]>> blocks;  ///< never moved: lists point into them
  std::size_t used = 0;                               ///< of the last block
  std::vector<std::uint32_t> gathered;
};

CellNeighbours::CellNeighbours(const VoxelLookup& voxels, double resolution, std::size_t max_cells)
    : voxels_(voxels),
      resolution_(resolution),
      max_per_shard_(max_cells >> kShardBits),
      shards_(std::make_unique<Shard[]>(std::size_t{1} << kShardBits)) {}

CellNeighbours::~CellNeighbours() = default;

CellNeighbours::List CellNeighbours::get(const Eigen::Vector3i& cell, std::uint64_t key, std::vector<std::uint32_t>& scratch) const {
  Shard& s = shards_[mixBits(key) >> (64 - kShardBits)];  // the high bits: the shard's table uses the low ones
  std::lock_guard<std::mutex> lock(s.mutex);
  if (const std::size_t at = s.index.find(key); at != PackedVoxelIndex::kNone) return s.lists[at];
  if (s.lists.size() >= max_per_shard_) {  // this shard's share of the bound
    scratch.clear();
    gatherCell(voxels_, resolution_, cell, scratch);
    return {scratch.data(), static_cast<std::uint32_t>(scratch.size()), false};
  }
  s.index.insert(key);
  s.gathered.clear();
  gatherCell(voxels_, resolution_, cell, s.gathered);
  if (s.blocks.empty() || s.used + s.gathered.size() > kBlock) {
    s.blocks.push_back(std::make_unique<std::uint32_t[]>(kBlock));
    s.used = 0;
  }
  std::uint32_t* stored = s.blocks.back().get() + s.used;
  std::copy(s.gathered.begin(), s.gathered.end(), stored);
  s.used += s.gathered.size();
  s.lists.push_back({stored, static_cast<std::uint32_t>(s.gathered.size()), true});
  return s.lists.back();
}

std::size_t CellNeighbours::cells() const {
  std::size_t n = 0;
  for (std::size_t i = 0; i < (std::size_t{1} << kShardBits); ++i) {
    std::lock_guard<std::mutex> lock(shards_[i].mutex);
    n += shards_[i].lists.size();
  }
  return n;
}

}  // namespace coloc::ndt
