#include "coloc/ndt/preprocess.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>

#include "scan_stage.hpp"
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
// at time t, seen from time 0, moving on a circular arc (a line if wz ~ 0).
RunMotion motionAt(double vx, double wz, double t) {
  RunMotion m;
  m.moves = true;
  const double angle = wz * t;
  if (std::abs(wz) < 1e-9) {
    m.dx = vx * t;
    m.dy = 0.0;
  } else {
    m.dx = vx * std::sin(angle) / wz;
    m.dy = vx * (1.0 - std::cos(angle)) / wz;
  }
  m.c = std::cos(angle);
  m.s = std::sin(angle);
  return m;
}

// The lasers of one firing share its time, so the motion is recomputed only when the time changes.
class Deskew {
 public:
  Deskew(double vx, double wz) : vx_(vx), wz_(wz) {}
  Eigen::Vector3f operator()(const Eigen::Vector3f& p, float time) {
    const double t = time;
    if (!(t == last_t_)) {
      last_t_ = t;
      m_ = motionAt(vx_, wz_, t);
    }
    return Eigen::Vector3f(static_cast<float>(m_.c * p.x() - m_.s * p.y() + m_.dx), static_cast<float>(m_.s * p.x() + m_.c * p.y() + m_.dy), p.z());
  }

 private:
  double vx_, wz_;
  double last_t_ = std::nan("");
  RunMotion m_;
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

// One point per occupied voxel, the centroid of the cloud's points as staged (cropped, moved) in runs,
// in order of first appearance: `runAt(i, motion)` gives the motion of the run that starts at point i
// and returns where it ends.
// `zero_times`: the points' times are 0 after the motion (deskewed), else their own.
template <typename RunAt>
PointCloud voxelCentroids(const PointCloud& cloud, const StageBounds& bounds, bool zero_times, RunAt&& runAt) {
  // The thread's tables, kept between scans; bound once (a thread-local's address is a library call away).
  thread_local VoxelSlots thread_slots;
  constexpr std::size_t kBlock = 256;  // staged at a time: stays in the first-level cache
  thread_local std::vector<StagedPoint> thread_staged(kBlock);
  VoxelSlots& slots = thread_slots;
  StagedPoint* const staged = thread_staged.data();
  struct Clear {
    VoxelSlots& s;
    ~Clear() { s.clear(); }
  } clear_after{slots};
  const bool times = cloud.hasTimes();
  std::vector<VoxelSum> sums;
  VoxelCoordinates last_key;
  std::size_t last_at = 0;
  bool have_last = false;
  for (std::size_t i = 0; i < cloud.size();) {
    RunMotion motion;
    const std::size_t end = std::min(runAt(i, motion), i + kBlock);
    stageRun(cloud.points.data() + i, end - i, motion, bounds, staged);
    for (std::size_t j = i; j < end; ++j) {
      const StagedPoint& p = staged[j - i];
      // A point cropped, not finite, or too far out for integer voxel coordinates has no voxel.
      if (!p.ok) continue;
      // Neighbours in a scan's order (lasers of one firing, successive firings) often share a voxel.
      if (!(have_last && p.key == last_key)) {
        bool inserted = false;
        const std::size_t at = slots.find(p.key, sums.size(), inserted);
        if (inserted) sums.emplace_back();
        last_key = p.key;
        last_at = at;
        have_last = true;
      }
      VoxelSum& s = sums[last_at];
      s.x += p.p.x();
      s.y += p.p.y();
      s.z += p.p.z();
      if (times) s.time += zero_times ? 0.0f : cloud.times[j];
      ++s.count;
    }
    i = end;
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
  StageBounds everything;  // no crop: no squared range is below 0 or above infinity
  everything.hi = std::numeric_limits<double>::infinity();
  everything.inverse = 1.0 / voxel_size;
  return voxelCentroids(cloud, everything, false, [&](std::size_t, RunMotion&) { return cloud.size(); });
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
  const bool moving = config.deskew && scan.hasTimes();
  StageBounds bounds;
  bounds.lo = config.min_range * config.min_range;
  bounds.hi = config.max_range * config.max_range;
  bounds.inverse = 1.0 / config.voxel_size;
  // Runs of one time (the lasers of a firing) share their motion.
  const PointCloud cloud = voxelCentroids(scan, bounds, moving, [&](std::size_t i, RunMotion& motion) {
    if (!moving) return scan.size();
    const float t = scan.times[i];
    std::size_t end = i + 1;
    while (end < scan.size() && scan.times[end] == t) ++end;
    motion = motionAt(vx, wz, t);
    return end;
  });
  return capPoints(cloud, config.max_points, config.seed);
}

}  // namespace coloc::ndt
