#include "coloc/roadside/background_model.hpp"

#include <absl/container/flat_hash_map.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "coloc/core/error.hpp"

namespace coloc::roadside {

namespace {
constexpr int kBits = 21;  // per axis: 2^21 voxels of 0.1 m cover +-104 m
constexpr std::int64_t kHalf = std::int64_t{1} << (kBits - 1);

struct Cell {
  double frames = 0.0;  ///< frames with a return here
  double points = 0.0;  ///< returns here
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();  ///< of the returns, each weighted as `points`
  std::uint64_t last_frame = 0;  ///< the frame that last counted here (1-based)
};

// A voxel index mixed into a hash (splitmix64's finaliser): the indices of neighbouring voxels differ
// in a few low bits of each axis, which an identity hash would crowd into neighbouring slots.
struct VoxelHash {
  std::size_t operator()(std::uint64_t k) const {
    k ^= k >> 30;
    k *= 0xbf58476d1ce4e5b9ULL;
    k ^= k >> 27;
    k *= 0x94d049bb133111ebULL;
    return static_cast<std::size_t>(k ^ (k >> 31));
  }
};
}  // namespace

// A frame of a 64-beam LiDAR is some 30,000 lookups. The table maps a voxel's index to its place in
// `cells`, which holds the voxels in the order first seen: a still LiDAR's rays come in the same order
// every frame, so a frame walks the cells nearly in order, and the table's slots are small enough to
// stay in cache (a node-based map followed a pointer to a scattered cell per return: 2x slower).
struct BackgroundLearner::Cells {
  absl::flat_hash_map<std::uint64_t, std::uint32_t, VoxelHash> index;
  std::vector<Cell> cells;
  std::vector<std::uint64_t> keys;  ///< each cell's voxel index
};

BackgroundLearner::~BackgroundLearner() = default;
BackgroundLearner::BackgroundLearner(BackgroundLearner&&) noexcept = default;
BackgroundLearner& BackgroundLearner::operator=(BackgroundLearner&&) noexcept = default;

std::size_t BackgroundLearner::voxels() const { return cells_->cells.size(); }

BackgroundLearner::BackgroundLearner(BackgroundConfig config) : config_(config), cells_(std::make_unique<Cells>()) {
  if (!(std::isfinite(config.voxel) && config.voxel > 0.0)) throw Error("background: voxel must be a finite number of metres > 0");
  if (!(config.min_occupancy > 0.0 && config.min_occupancy <= 1.0)) throw Error("background: min_occupancy must lie in (0, 1]");
  if (!(config.decay >= 0.0 && config.decay < 1.0)) throw Error("background: decay must lie in [0, 1)");
  if (!(std::isfinite(config.max_range) && config.max_range > 0.0)) throw Error("background: max_range must be a finite number of metres > 0");
  if (config.max_range / config.voxel >= static_cast<double>(kHalf))
    throw Error("background: max_range / voxel must be below " + std::to_string(kHalf) + " (the voxel index's reach)");
}

void BackgroundLearner::add(const std::vector<Eigen::Vector3f>& frame) {
  scale_ *= 1.0 - config_.decay;
  if (scale_ < 1e-200) rescale();
  const double unit = 1.0 / scale_;  // one frame's (or one return's) weight, at scale
  ++frame_index_;
  frames_ += unit;
  const double max_sq = config_.max_range * config_.max_range;
  for (const Eigen::Vector3f& pf : frame) {
    if (!pf.allFinite()) continue;
    const Eigen::Vector3d p = pf.cast<double>();
    if (p.squaredNorm() > max_sq) continue;
    const Eigen::Array3d c = (p / config_.voxel).array().floor();
    std::uint64_t key = 0;
    for (int i = 0; i < 3; ++i) key = (key << kBits) | static_cast<std::uint64_t>(static_cast<std::int64_t>(c[i]) + kHalf);
    const auto [slot, added] = cells_->index.try_emplace(key, static_cast<std::uint32_t>(cells_->cells.size()));
    if (added) {
      cells_->cells.emplace_back();
      cells_->keys.push_back(key);
    }
    Cell& cell = cells_->cells[slot->second];
    if (cell.last_frame != frame_index_) {
      cell.last_frame = frame_index_;
      cell.frames += unit;
    }
    cell.points += unit;
    cell.sum += unit * p;
  }
}

void BackgroundLearner::rescale() {
  Cells kept;
  for (std::size_t i = 0; i < cells_->cells.size(); ++i) {
    Cell c = cells_->cells[i];
    c.frames *= scale_, c.points *= scale_, c.sum *= scale_;
    // A voxel not hit for so long that its weight is nothing is forgotten.
    if (c.frames < 1e-9) continue;
    kept.index.emplace(cells_->keys[i], static_cast<std::uint32_t>(kept.cells.size()));
    kept.cells.push_back(c);
    kept.keys.push_back(cells_->keys[i]);
  }
  *cells_ = std::move(kept);
  frames_ *= scale_;
  scale_ = 1.0;
}

std::vector<Eigen::Vector3f> BackgroundLearner::background() const {
  const double needed = config_.min_occupancy * frames_;
  std::vector<std::pair<std::uint64_t, Eigen::Vector3f>> kept;
  for (std::size_t i = 0; i < cells_->cells.size(); ++i) {
    const Cell& c = cells_->cells[i];
    if (c.frames >= needed && c.points > 0.0) kept.emplace_back(cells_->keys[i], (c.sum / c.points).cast<float>());
  }
  std::sort(kept.begin(), kept.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<Eigen::Vector3f> out;
  out.reserve(kept.size());
  for (const auto& k : kept) out.push_back(k.second);
  return out;
}

}  // namespace coloc::roadside
