#include "coloc/roadside/road_surface.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <random>

namespace coloc::roadside {

namespace {

std::uint64_t cellKey(std::int64_t i, std::int64_t j) {
  return (static_cast<std::uint64_t>(i + (1LL << 31)) << 32) | static_cast<std::uint64_t>(j + (1LL << 31));
}

// Least squares z = a + b x + c y through the points with weight > 0.
std::optional<Eigen::Vector3d> planeThrough(const std::vector<Eigen::Vector3d>& p, const std::vector<double>& w) {
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (w[i] <= 0.0) continue;
    const Eigen::Vector3d row(1.0, p[i].x(), p[i].y());
    A += w[i] * row * row.transpose();
    rhs += w[i] * row * p[i].z();
  }
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(A);
  if (ldlt.info() != Eigen::Success || !(ldlt.rcond() > 1e-12)) return std::nullopt;
  return ldlt.solve(rhs);
}

}  // namespace

std::optional<GroundPlane> fitGroundPlane(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector2d& origin, const RoadSurfaceConfig& config) {
  // The lowest return of each cell.
  std::unordered_map<std::uint64_t, Eigen::Vector3d> lowest;
  for (const Eigen::Vector3d& p : points) {
    if (!p.allFinite()) continue;
    const double range = (p.head<2>() - origin).norm();
    if (range < config.min_range || range > config.max_range) continue;
    const auto i = static_cast<std::int64_t>(std::floor(p.x() / config.cell)), j = static_cast<std::int64_t>(std::floor(p.y() / config.cell));
    auto [it, fresh] = lowest.emplace(cellKey(i, j), p);
    if (!fresh && p.z() < it->second.z()) it->second = p;
  }
  if (lowest.size() < 10) return std::nullopt;
  std::vector<Eigen::Vector3d> low;
  low.reserve(lowest.size());
  for (const auto& [key, p] : lowest) low.push_back(p);
  std::sort(low.begin(), low.end(), [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());  // a fixed order: the same frames give the same plane
  });
  // RANSAC over triples for the plane most cells lie on (a canopy or a roof over some cells, walls'
  // lowest returns above their foot), then least squares over the cells weighted by a Cauchy function
  // of their residual, to convergence. A hard inlier band instead (the plane refit over the cells
  // within it) flips which cells count where the road's own swell is about the band's width: on a
  // crowned road with a 0.25 m swell (test RoadSurface.TheLocalRoad*) the tilt came out 3.00-3.16 or
  // 3.33-3.39 deg by the LiDAR's noise; weighted, 3.105-3.118 deg over ten seeds.
  std::mt19937 rng(7);
  std::uniform_int_distribution<std::size_t> pick(0, low.size() - 1);
  const double inlier = 0.2;  // m: the road's own unevenness within a plane
  std::vector<double> w(low.size(), 0.0);
  std::size_t best_count = 0;
  Eigen::Vector3d best(0, 0, 0);
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<Eigen::Vector3d> three = {low[pick(rng)], low[pick(rng)], low[pick(rng)]};
    const std::vector<double> ones(3, 1.0);
    const auto abc = planeThrough(three, ones);
    if (!abc) continue;
    // A road is no steeper than 30 %: a wall's three returns are no plane of it.
    if (std::hypot((*abc)[1], (*abc)[2]) > 0.3) continue;
    std::size_t count = 0;
    for (const Eigen::Vector3d& p : low) count += std::abs(p.z() - ((*abc)[0] + (*abc)[1] * p.x() + (*abc)[2] * p.y())) <= inlier ? 1 : 0;
    if (count > best_count) best_count = count, best = *abc;
  }
  if (best_count < 10) return std::nullopt;
  for (int round = 0; round < 30; ++round) {
    for (std::size_t i = 0; i < low.size(); ++i) {
      const double r = std::abs(low[i].z() - (best[0] + best[1] * low[i].x() + best[2] * low[i].y())) / inlier;
      w[i] = r <= 3.0 ? 1.0 / (1.0 + r * r) : 0.0;
    }
    const auto refined = planeThrough(low, w);
    if (!refined) break;
    const bool settled = (*refined - best).cwiseAbs().maxCoeff() < 1e-9;
    best = *refined;
    if (settled) break;
  }
  // The cells within the band are the plane's: its rms and count.
  for (std::size_t i = 0; i < low.size(); ++i)
    w[i] = std::abs(low[i].z() - (best[0] + best[1] * low[i].x() + best[2] * low[i].y())) <= inlier ? 1.0 : 0.0;
  GroundPlane g{best[0], best[1], best[2], 0, 0.0};
  double sum_sq = 0.0;
  for (std::size_t i = 0; i < low.size(); ++i)
    if (w[i] > 0.0) {
      const double r = low[i].z() - g.at(low[i].head<2>());
      sum_sq += r * r;
      ++g.cells;
    }
  g.rms = g.cells ? std::sqrt(sum_sq / static_cast<double>(g.cells)) : 0.0;
  return g;
}

Levelling levellingOf(const GroundPlane& g) {
  // The map's up seen in the sensor frame is R^T z = (-sin p, cos p sin r, cos p cos r) for
  // R = Rz(yaw) Ry(p) Rx(r); the LiDAR's height is the origin's distance to the plane.
  const Eigen::Vector3d n = g.normal();
  return {std::atan2(n.y(), n.z()), std::asin(std::clamp(-n.x(), -1.0, 1.0)), -g.a * n.z()};
}

RoadSurface::RoadSurface(const std::vector<Eigen::Vector3d>& background, const Eigen::Vector2d& lidar, const RoadSurfaceConfig& config)
    : cell_(config.cell) {
  plane_ = fitGroundPlane(background, lidar, config);
  if (!plane_) return;
  // Each cell's road: the lower half of its returns near the plane (a kerb's top and a sidewalk lie
  // above the road beside them), their median.
  std::unordered_map<std::uint64_t, std::vector<double>> near;
  for (const Eigen::Vector3d& p : background) {
    if (!p.allFinite()) continue;
    const double range = (p.head<2>() - lidar).norm();
    if (range > config.max_range) continue;
    if (std::abs(p.z() - plane_->at(p.head<2>())) > config.band) continue;
    const auto i = static_cast<std::int64_t>(std::floor(p.x() / cell_)), j = static_cast<std::int64_t>(std::floor(p.y() / cell_));
    near[cellKey(i, j)].push_back(p.z());
  }
  std::unordered_map<std::uint64_t, double> own;
  for (auto& [key, z] : near) {
    if (static_cast<int>(z.size()) < config.min_points) continue;
    const std::size_t quarter = z.size() / 4;
    std::nth_element(z.begin(), z.begin() + static_cast<std::ptrdiff_t>(quarter), z.end());
    own[key] = z[quarter];
  }
  // A pole's LiDAR sees the road in rings around it, 10 m apart and more: most cells have no return of
  // their own. Each cell within reach gets the global plane plus what the cells with returns around it
  // (Gaussian-weighted: the nearest rings dominate) say of the height over that plane there.
  const auto reach = static_cast<std::int64_t>(std::ceil(config.max_range / cell_));
  const auto ci = static_cast<std::int64_t>(std::floor(lidar.x() / cell_)), cj = static_cast<std::int64_t>(std::floor(lidar.y() / cell_));
  const auto around = static_cast<std::int64_t>(std::ceil(4.0 * config.smoothing / cell_));
  const double inv_two_sigma_sq = 1.0 / (2.0 * config.smoothing * config.smoothing);
  std::unordered_map<std::uint64_t, double> over_plane;
  for (const auto& [key, z] : own) {
    const auto i = static_cast<std::int64_t>(key >> 32) - (1LL << 31), j = static_cast<std::int64_t>(key & 0xffffffffULL) - (1LL << 31);
    over_plane[key] = z - plane_->at(Eigen::Vector2d((i + 0.5) * cell_, (j + 0.5) * cell_));
  }
  for (std::int64_t i = ci - reach; i <= ci + reach; ++i)
    for (std::int64_t j = cj - reach; j <= cj + reach; ++j) {
      const Eigen::Vector2d centre((i + 0.5) * cell_, (j + 0.5) * cell_);
      if ((centre - lidar).norm() > config.max_range + cell_) continue;
      // Weighted least squares of the height over the plane, r0 + r1 dx + r2 dy, with the slopes held
      // towards 0 (ridge, over kArm): a slope is taken only where returns lie on both sides (two
      // rings), never extrapolated from one ring's arc.
      constexpr double kArm = 5.0;  // m
      Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
      Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
      double weight = 0.0;
      for (std::int64_t di = -around; di <= around; ++di)
        for (std::int64_t dj = -around; dj <= around; ++dj) {
          const auto it = over_plane.find(cellKey(i + di, j + dj));
          if (it == over_plane.end()) continue;
          const Eigen::Vector3d row(1.0, di * cell_, dj * cell_);
          const double w = std::exp(-(row[1] * row[1] + row[2] * row[2]) * inv_two_sigma_sq);
          A += w * row * row.transpose();
          rhs += w * row * it->second;
          weight += w;
        }
      if (weight <= 1e-12) continue;
      A(1, 1) += weight * kArm * kArm;
      A(2, 2) += weight * kArm * kArm;
      const double residual = A.ldlt().solve(rhs)[0];
      heights_[cellKey(i, j)] = plane_->at(centre) + residual;
    }
}

double RoadSurface::cellHeight(std::int64_t i, std::int64_t j) const {
  const auto it = heights_.find(cellKey(i, j));
  if (it != heights_.end()) return it->second;
  return plane_ ? plane_->at(Eigen::Vector2d((i + 0.5) * cell_, (j + 0.5) * cell_)) : 0.0;
}

double RoadSurface::height(const Eigen::Vector2d& xy) const {
  if (!plane_) return 0.0;
  // Bilinear between the four nearest cell centres.
  const double u = xy.x() / cell_ - 0.5, v = xy.y() / cell_ - 0.5;
  const double fu = std::floor(u), fv = std::floor(v);
  const auto i = static_cast<std::int64_t>(fu), j = static_cast<std::int64_t>(fv);
  const double s = u - fu, t = v - fv;
  return (1 - s) * (1 - t) * cellHeight(i, j) + s * (1 - t) * cellHeight(i + 1, j) + (1 - s) * t * cellHeight(i, j + 1) + s * t * cellHeight(i + 1, j + 1);
}

}  // namespace coloc::roadside
