#include "coloc/replay/accurate_places.hpp"

#include <cmath>
#include <string>

#include "coloc/core/error.hpp"

namespace coloc::replay {

AccuratePlaces AccuratePlaces::fromErrors(const std::vector<ErrorSample>& errors, double cell, double below, std::size_t min_samples) {
  if (!(std::isfinite(cell) && cell > 0.0)) throw Error("accurate places: cell must be a finite number of metres > 0, not " + std::to_string(cell));
  if (!(std::isfinite(below) && below > 0.0)) throw Error("accurate places: below must be a finite number of metres > 0, not " + std::to_string(below));
  AccuratePlaces p;
  p.cell_ = cell;
  p.below_ = below;
  std::map<Key, std::pair<double, std::size_t>> sums;  // error sum, poses
  for (const ErrorSample& e : errors) {
    // A place beyond what a long long indexes at this cell size says nothing of the road.
    if (!e.truth.allFinite() || !std::isfinite(e.error) || e.truth.cwiseAbs().maxCoeff() / cell > 1e15) continue;
    auto& s = sums[p.keyOf(e.truth)];
    s.first += e.error;
    ++s.second;
  }
  for (const auto& [key, s] : sums)
    if (s.second >= std::max<std::size_t>(1, min_samples)) p.judged_[key] = s.first / static_cast<double>(s.second) < below;
  return p;
}

AccuratePlaces::Key AccuratePlaces::keyOf(const Eigen::Vector2d& xy) const {
  return {static_cast<long long>(std::floor(xy.x() / cell_)), static_cast<long long>(std::floor(xy.y() / cell_))};
}

bool AccuratePlaces::contains(const Eigen::Vector2d& xy) const {
  if (!xy.allFinite() || xy.cwiseAbs().maxCoeff() / cell_ > 1e15) return false;
  const auto found = judged_.find(keyOf(xy));
  return found != judged_.end() && found->second;
}

std::size_t AccuratePlaces::accurate() const {
  std::size_t n = 0;
  for (const auto& [key, accurate] : judged_) n += accurate ? 1 : 0;
  return n;
}

}  // namespace coloc::replay
