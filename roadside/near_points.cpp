#include "near_points.hpp"

#include <absl/container/flat_hash_map.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>

#include "coloc/core/error.hpp"

namespace coloc::roadside {

namespace {
using CellKey = std::array<std::int32_t, 3>;

// The cell index along one axis, or false where it does not fit (a coordinate some 10^8 cells out).
bool cellIndex(double coordinate, double inverse_cell, std::int32_t& out) {
  const double c = std::floor(coordinate * inverse_cell);
  if (!(std::abs(c) < static_cast<double>(std::numeric_limits<std::int32_t>::max() - 1))) return false;
  out = static_cast<std::int32_t>(c);
  return true;
}
}  // namespace

struct NearPoints::Impl {
  double distance = 0.0, distance_sq = 0.0, inverse_cell = 0.0;
  std::vector<Eigen::Vector3f> points;  // sorted by cell
  absl::flat_hash_map<CellKey, std::pair<std::uint32_t, std::uint32_t>> cells;  // [begin, end) in points
};

NearPoints::NearPoints(const std::vector<Eigen::Vector3f>& points, double distance) : impl_(std::make_unique<Impl>()) {
  if (!(std::isfinite(distance) && distance > 0.0)) throw Error("near points: the distance must be finite and > 0, got " + std::to_string(distance));
  Impl& m = *impl_;
  m.distance = distance;
  m.distance_sq = distance * distance;
  m.inverse_cell = 1.0 / (2.0 * distance);
  std::vector<std::pair<CellKey, Eigen::Vector3f>> binned;
  binned.reserve(points.size());
  for (const Eigen::Vector3f& p : points) {
    if (!p.allFinite()) continue;
    CellKey key;
    bool fits = true;
    for (int i = 0; i < 3; ++i) fits = fits && cellIndex(p[i], m.inverse_cell, key[static_cast<std::size_t>(i)]);
    if (fits) binned.emplace_back(key, p);
  }
  std::stable_sort(binned.begin(), binned.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  m.points.reserve(binned.size());
  for (std::size_t i = 0; i < binned.size(); ++i) {
    const auto index = static_cast<std::uint32_t>(i);
    ++m.cells.try_emplace(binned[i].first, index, index).first->second.second;
    m.points.push_back(binned[i].second);
  }
}

NearPoints::~NearPoints() = default;
NearPoints::NearPoints(NearPoints&&) noexcept = default;
NearPoints& NearPoints::operator=(NearPoints&&) noexcept = default;

std::size_t NearPoints::size() const { return impl_->points.size(); }

bool NearPoints::anyWithin(const Eigen::Vector3f& query) const {
  const Impl& m = *impl_;
  if (!query.allFinite()) return false;
  // The reach a little beyond the distance: a point whose float distance rounds to the bound may lie
  // a rounding outside it, and so in the next cell.
  const double reach = m.distance * (1.0 + 1e-6) + 1e-9;
  std::array<std::int32_t, 3> lo{}, hi{};
  for (std::size_t i = 0; i < 3; ++i) {
    const double q = static_cast<double>(query[static_cast<int>(i)]);
    if (!cellIndex(q - reach, m.inverse_cell, lo[i]) || !cellIndex(q + reach, m.inverse_cell, hi[i])) return false;
  }
  for (std::int32_t x = lo[0]; x <= hi[0]; ++x)
    for (std::int32_t y = lo[1]; y <= hi[1]; ++y)
      for (std::int32_t z = lo[2]; z <= hi[2]; ++z) {
        const auto found = m.cells.find(CellKey{x, y, z});
        if (found == m.cells.end()) continue;
        for (std::uint32_t k = found->second.first; k < found->second.second; ++k) {
          const Eigen::Vector3f& p = m.points[k];
          // In float, x then y then z, as a k-d tree of float points sums them.
          const float dx = query.x() - p.x(), dy = query.y() - p.y(), dz = query.z() - p.z();
          float sq = dx * dx;
          sq += dy * dy;
          sq += dz * dz;
          if (static_cast<double>(sq) <= m.distance_sq) return true;
        }
      }
  return false;
}

}  // namespace coloc::roadside
