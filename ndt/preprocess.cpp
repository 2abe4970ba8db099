#include "coloc/ndt/preprocess.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "voxel_index.hpp"

namespace coloc::ndt {

PointCloud cropRange(const PointCloud& cloud, double min_range, double max_range) {
  PointCloud out;
  const bool times = cloud.hasTimes();
  out.points.reserve(cloud.size());
  if (times) out.times.reserve(cloud.size());
  const double lo = min_range * min_range, hi = max_range * max_range;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double r = cloud.points[i].cast<double>().squaredNorm();
    if (r < lo || r > hi) continue;
    out.points.push_back(cloud.points[i]);
    if (times) out.times.push_back(cloud.times[i]);
  }
  return out;
}

namespace {

// deskew() on a cloud of one's own, without the copy (preprocessScan's cropped cloud is its own).
void deskewInPlace(PointCloud& cloud, double vx, double wz) {
  if (!cloud.hasTimes()) return;
  // Where the sensor was at time t, seen from time 0, moving on a circular arc (a line if wz ~ 0). The
  // lasers of one firing share its time, so the motion is recomputed only when the time changes.
  double last_t = std::nan(""), dx = 0.0, dy = 0.0, c = 1.0, s = 0.0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double t = cloud.times[i];
    if (!(t == last_t)) {
      last_t = t;
      const double angle = wz * t;
      if (std::abs(wz) < 1e-9) {
        dx = vx * t;
        dy = 0.0;
      } else {
        dx = vx * std::sin(angle) / wz;
        dy = vx * (1.0 - std::cos(angle)) / wz;
      }
      c = std::cos(angle);
      s = std::sin(angle);
    }
    const Eigen::Vector3f p = cloud.points[i];
    cloud.points[i] = Eigen::Vector3f(static_cast<float>(c * p.x() - s * p.y() + dx), static_cast<float>(s * p.x() + c * p.y() + dy), p.z());
    cloud.times[i] = 0.0f;
  }
}

}  // namespace

PointCloud deskew(const PointCloud& cloud, double vx, double wz) {
  PointCloud out = cloud;
  deskewInPlace(out, vx, wz);
  return out;
}

PointCloud voxelDownsample(const PointCloud& cloud, double voxel_size) {
  if (!(voxel_size > 0.0)) return cloud;
  struct Sum {
    Eigen::Vector3d point = Eigen::Vector3d::Zero();
    double time = 0.0;
    int count = 0;
  };
  VoxelIndex index;
  std::vector<Sum> sums;
  const double inverse = 1.0 / voxel_size;
  const bool times = cloud.hasTimes();
  VoxelCoordinates last_key;
  std::size_t last_at = 0;
  bool have_last = false;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3d p = cloud.points[i].cast<double>();
    const Eigen::Array3d scaled = (p * inverse).array().floor();
    // A point that is not finite, or too far out for integer voxel coordinates, has no voxel.
    if (!(scaled.abs() < 2e9).all()) continue;
    const VoxelCoordinates key{static_cast<std::int32_t>(scaled.x()), static_cast<std::int32_t>(scaled.y()), static_cast<std::int32_t>(scaled.z())};
    // Neighbours in a scan's order (lasers of one firing, successive firings) often share a voxel.
    if (!(have_last && key == last_key)) {
      const auto [at, inserted] = index.insert(key);
      if (inserted) sums.emplace_back();
      last_key = key;
      last_at = at;
      have_last = true;
    }
    Sum& s = sums[last_at];
    s.point += p;
    if (times) s.time += cloud.times[i];
    ++s.count;
  }
  PointCloud out;
  out.points.reserve(sums.size());
  for (const Sum& s : sums) {
    out.points.push_back((s.point / s.count).cast<float>());
    if (times) out.times.push_back(static_cast<float>(s.time / s.count));
  }
  return out;
}

PointCloud capPoints(const PointCloud& cloud, std::size_t max_points, std::uint32_t seed) {
  if (max_points == 0 || cloud.size() <= max_points) return cloud;
  std::vector<std::size_t> order(cloud.size());
  std::iota(order.begin(), order.end(), 0);
  std::mt19937 rng(seed);
  // Partial Fisher-Yates: the first max_points entries become a uniform random subset.
  for (std::size_t i = 0; i < max_points; ++i) {
    std::uniform_int_distribution<std::size_t> pick(i, order.size() - 1);
    std::swap(order[i], order[pick(rng)]);
  }
  order.resize(max_points);
  std::sort(order.begin(), order.end());
  PointCloud out;
  const bool times = cloud.hasTimes();
  for (std::size_t i : order) {
    out.points.push_back(cloud.points[i]);
    if (times) out.times.push_back(cloud.times[i]);
  }
  return out;
}

PointCloud preprocessScan(const PointCloud& scan, const PreprocessConfig& config, double vx, double wz) {
  PointCloud cloud = cropRange(scan, config.min_range, config.max_range);
  if (config.deskew) deskewInPlace(cloud, vx, wz);
  cloud = voxelDownsample(cloud, config.voxel_size);
  return capPoints(cloud, config.max_points, config.seed);
}

}  // namespace coloc::ndt
