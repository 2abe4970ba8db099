#include "coloc/roadside/background_model.hpp"

#include <cmath>

#include "coloc/core/error.hpp"

namespace coloc::roadside {

namespace {
constexpr int kBits = 21;  // per axis: 2^21 voxels of 0.1 m cover +-104 m
constexpr std::int64_t kHalf = std::int64_t{1} << (kBits - 1);
}  // namespace

BackgroundLearner::BackgroundLearner(BackgroundConfig config) : config_(config) {
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
    Cell& cell = cells_[key];
    if (cell.last_frame != frame_index_) {
      cell.last_frame = frame_index_;
      cell.frames += unit;
    }
    cell.points += unit;
    cell.sum += unit * p;
  }
}

void BackgroundLearner::rescale() {
  for (auto it = cells_.begin(); it != cells_.end();) {
    Cell& c = it->second;
    c.frames *= scale_, c.points *= scale_, c.sum *= scale_;
    // A voxel not hit for so long that its weight is nothing is forgotten.
    if (c.frames < 1e-9) it = cells_.erase(it);
    else ++it;
  }
  frames_ *= scale_;
  scale_ = 1.0;
}

std::vector<Eigen::Vector3f> BackgroundLearner::background() const {
  std::vector<Eigen::Vector3f> out;
  const double needed = config_.min_occupancy * frames_;
  for (const auto& [key, c] : cells_)
    if (c.frames >= needed && c.points > 0.0) out.push_back((c.sum / c.points).cast<float>());
  return out;
}

}  // namespace coloc::roadside
