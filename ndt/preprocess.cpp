#include "coloc/ndt/preprocess.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "voxel_index.hpp"

namespace coloc::ndt {

namespace {

double squaredRange(const Eigen::Vector3f& p) {
  const double x = p.x(), y = p.y(), z = p.z();
  return x * x + y * y + z * z;
}

}  // namespace

PointCloud cropRange(const PointCloud& cloud, double min_range, double max_range) {
  PointCloud out;
  const bool times = cloud.hasTimes();
  out.points.reserve(cloud.size());
  if (times) out.times.reserve(cloud.size());
  const double lo = min_range * min_range, hi = max_range * max_range;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const double r = squaredRange(cloud.points[i]);
    if (r < lo || r > hi) continue;
    out.points.push_back(cloud.points[i]);
    if (times) out.times.push_back(cloud.times[i]);
  }
  return out;
}

namespace {

// The sensor's motion over a sweep, for moving a point into the frame at time 0: where the sensor was
// at time t, seen from time 0, moving on a circular arc (a line if wz ~ 0). The lasers of one firing
// share its time, so the motion is recomputed only when the time changes.
class Deskew {
 public:
  Deskew(double vx, double wz) : vx_(vx), wz_(wz) {}
  Eigen::Vector3f operator()(const Eigen::Vector3f& p, float time) {
    const double t = time;
    if (!(t == last_t_)) {
      last_t_ = t;
      const double angle = wz_ * t;
      if (std::abs(wz_) < 1e-9) {
        dx_ = vx_ * t;
        dy_ = 0.0;
      } else {
        dx_ = vx_ * std::sin(angle) / wz_;
        dy_ = vx_ * (1.0 - std::cos(angle)) / wz_;
      }
      c_ = std::cos(angle);
      s_ = std::sin(angle);
    }
    return Eigen::Vector3f(static_cast<float>(c_ * p.x() - s_ * p.y() + dx_), static_cast<float>(s_ * p.x() + c_ * p.y() + dy_), p.z());
  }

 private:
  double vx_, wz_;
  double last_t_ = std::nan(""), dx_ = 0.0, dy_ = 0.0, c_ = 1.0, s_ = 0.0;
};

void deskewInPlace(PointCloud& cloud, double vx, double wz) {
  if (!cloud.hasTimes()) return;
  Deskew move(vx, wz);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    cloud.points[i] = move(cloud.points[i], cloud.times[i]);
    cloud.times[i] = 0.0f;
  }
}

struct VoxelSum {
  double x = 0.0, y = 0.0, z = 0.0, time = 0.0;
  int count = 0;
};

// One point per occupied voxel, the centroid of the points `pointAt(i, point, time)` gives for
// i = 0 .. count - 1 (false: no point), in order of first appearance.
// Voxel -> its sum, by direct lookup for the voxels within kReach of the sensor's horizontally and
// kReachZ vertically (a scan's, at the voxel sizes NDT downsamples with: 256 KB, cache-resident), by
// hash for the rest. The table is the thread's, kept between scans; only the cells a scan used are
// cleared after it.
class VoxelSlots {
 public:
  static constexpr int kReach = 32, kReachZ = 8;
  static constexpr std::uint32_t kSide = 2 * kReach, kSideZ = 2 * kReachZ;
  VoxelSlots() : cells_(static_cast<std::size_t>(kSide) * kSide * kSideZ, 0u) {}
  /// Sum index of `key`, new ones numbered from `next`; `inserted` says whether it was new.
  std::size_t find(const VoxelCoordinates& key, std::size_t next, bool& inserted) {
    const std::uint32_t ux = static_cast<std::uint32_t>(key.x + kReach), uy = static_cast<std::uint32_t>(key.y + kReach),
                        uz = static_cast<std::uint32_t>(key.z + kReachZ);
    if ((ux | uy) >= kSide || uz >= kSideZ) return findFar(key, next, inserted);
    const std::size_t cell = ux + kSide * (uy + static_cast<std::size_t>(kSide) * uz);
    std::uint32_t& slot = cells_[cell];
    inserted = slot == 0;
    if (inserted) {
      slot = static_cast<std::uint32_t>(next + 1);
      used_.push_back(static_cast<std::uint32_t>(cell));
    }
    return slot - 1;
  }
  /// Forgets this scan's voxels.
  void clear() {
    for (std::uint32_t cell : used_) cells_[cell] = 0;
    used_.clear();
    if (!far_sums_.empty()) {
      far_ = VoxelIndex();
      far_sums_.clear();
    }
  }

 private:
  __attribute__((noinline)) std::size_t findFar(const VoxelCoordinates& key, std::size_t next, bool& inserted) {
    const auto [at, fresh] = far_.insert(key);
    inserted = fresh;
    if (fresh) far_sums_.push_back(next);
    return far_sums_[at];
  }
  std::vector<std::uint32_t> cells_;  ///< sum index + 1, 0 = none
  std::vector<std::uint32_t> used_;
  VoxelIndex far_;
  std::vector<std::size_t> far_sums_;
};

template <typename PointAt>
PointCloud voxelCentroids(std::size_t count, bool times, double voxel_size, PointAt&& pointAt) {
  thread_local VoxelSlots slots;
  struct Clear {
    VoxelSlots& s;
    ~Clear() { s.clear(); }
  } clear_after{slots};
  std::vector<VoxelSum> sums;
  const double inverse = 1.0 / voxel_size;
  VoxelCoordinates last_key;
  std::size_t last_at = 0;
  bool have_last = false;
  Eigen::Vector3f point;
  float time = 0.0f;
  for (std::size_t i = 0; i < count; ++i) {
    if (!pointAt(i, point, time)) continue;
    const double x = point.x(), y = point.y(), z = point.z();
    // A point that is not finite, or too far out for integer voxel coordinates, has no voxel.
    VoxelCoordinates key;
    if (!voxelOf(x, y, z, inverse, key)) continue;
    // Neighbours in a scan's order (lasers of one firing, successive firings) often share a voxel.
    if (!(have_last && key == last_key)) {
      bool inserted = false;
      const std::size_t at = slots.find(key, sums.size(), inserted);
      if (inserted) sums.emplace_back();
      last_key = key;
      last_at = at;
      have_last = true;
    }
    VoxelSum& s = sums[last_at];
    s.x += x;
    s.y += y;
    s.z += z;
    if (times) s.time += time;
    ++s.count;
  }
  PointCloud out;
  out.points.reserve(sums.size());
  if (times) out.times.reserve(sums.size());
  for (const VoxelSum& s : sums) {
    out.points.emplace_back(static_cast<float>(s.x / s.count), static_cast<float>(s.y / s.count), static_cast<float>(s.z / s.count));
    if (times) out.times.push_back(static_cast<float>(s.time / s.count));
  }
  return out;
}

}  // namespace

PointCloud deskew(const PointCloud& cloud, double vx, double wz) {
  PointCloud out = cloud;
  deskewInPlace(out, vx, wz);
  return out;
}

PointCloud voxelDownsample(const PointCloud& cloud, double voxel_size) {
  if (!(voxel_size > 0.0)) return cloud;
  const bool times = cloud.hasTimes();
  return voxelCentroids(cloud.size(), times, voxel_size, [&](std::size_t i, Eigen::Vector3f& p, float& t) {
    p = cloud.points[i];
    if (times) t = cloud.times[i];
    return true;
  });
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
  if (!(config.voxel_size > 0.0)) {
    PointCloud cloud = cropRange(scan, config.min_range, config.max_range);
    if (config.deskew) deskewInPlace(cloud, vx, wz);
    return capPoints(cloud, config.max_points, config.seed);
  }
  // Crop, deskew and downsample in one pass over the scan, without the cropped copy in between: the
  // same points in the same order as the three steps one after the other, so the same bytes.
  const bool times = scan.hasTimes();
  const bool moving = config.deskew && times;
  const double lo = config.min_range * config.min_range, hi = config.max_range * config.max_range;
  Deskew move(vx, wz);
  const PointCloud cloud = voxelCentroids(scan.size(), times, config.voxel_size, [&](std::size_t i, Eigen::Vector3f& p, float& t) {
    const double r = squaredRange(scan.points[i]);
    if (r < lo || r > hi) return false;
    if (moving) {
      p = move(scan.points[i], scan.times[i]);
      t = 0.0f;
    } else {
      p = scan.points[i];
      if (times) t = scan.times[i];
    }
    return true;
  });
  return capPoints(cloud, config.max_points, config.seed);
}

}  // namespace coloc::ndt
