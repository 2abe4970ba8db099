#include "coloc/sim/roadside_perception.hpp"

#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <unordered_map>

#include "coloc/core/error.hpp"

namespace coloc::sim {

struct RoadsidePerception::Impl {
  RoadsidePerceptionConfig config;
  RsuMount mount;
  pcl::PointCloud<pcl::PointXYZ>::Ptr background;
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  Eigen::Matrix2d rotation;  ///< sensor x-y to map x-y
};

namespace {

// Groups points closer than `distance` on the ground plane (single linkage), through a grid of that
// cell size. Vehicles are apart on the road, while a sparse LiDAR's rings on one body can lie farther
// apart in height than any sensible 3-D linkage distance (0.66 m for a VLP-16 at 19 m).
std::vector<std::vector<std::size_t>> clusters(const std::vector<Eigen::Vector3d>& points, double distance) {
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> grid;
  auto key = [&](const Eigen::Vector3d& p, int dx, int dy) {
    const auto c = (p.head<2>() / distance).array().floor().cast<std::int64_t>();
    return (static_cast<std::uint64_t>(c.x() + dx + (1 << 30)) << 32) | static_cast<std::uint64_t>(c.y() + dy + (1 << 30));
  };
  for (std::size_t i = 0; i < points.size(); ++i) grid[key(points[i], 0, 0)].push_back(i);
  std::vector<int> label(points.size(), -1);
  std::vector<std::vector<std::size_t>> out;
  for (std::size_t seed = 0; seed < points.size(); ++seed) {
    if (label[seed] >= 0) continue;
    out.emplace_back();
    std::vector<std::size_t> stack = {seed};
    label[seed] = static_cast<int>(out.size() - 1);
    while (!stack.empty()) {
      const std::size_t i = stack.back();
      stack.pop_back();
      out.back().push_back(i);
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy) {
          const auto it = grid.find(key(points[i], dx, dy));
          if (it == grid.end()) continue;
          for (std::size_t j : it->second)
            if (label[j] < 0 && (points[j] - points[i]).head<2>().norm() <= distance) {
              label[j] = label[seed];
              stack.push_back(j);
            }
        }
    }
  }
  return out;
}

}  // namespace

RoadsidePerception::RoadsidePerception(const std::vector<Eigen::Vector3f>& reference_frame, const RsuMount& mount,
                                       const RoadsidePerceptionConfig& config)
    : impl_(std::make_unique<Impl>()) {
  if (reference_frame.empty()) throw Error("roadside perception: the reference (background) frame is empty");
  impl_->config = config;
  impl_->mount = mount;
  impl_->background = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  for (const auto& p : reference_frame) impl_->background->push_back({p.x(), p.y(), p.z()});
  impl_->tree.setInputCloud(impl_->background);
  impl_->rotation = Eigen::Rotation2Dd(mount.yaw).toRotationMatrix();
}

RoadsidePerception::~RoadsidePerception() = default;
RoadsidePerception::RoadsidePerception(RoadsidePerception&&) noexcept = default;
RoadsidePerception& RoadsidePerception::operator=(RoadsidePerception&&) noexcept = default;
const RoadsidePerceptionConfig& RoadsidePerception::config() const { return impl_->config; }

VehicleDetection RoadsidePerception::detect(const std::vector<Eigen::Vector3f>& frame, Stamp stamp, const Eigen::Vector2d& reference,
                                            double heading_prior, double length, double width) const {
  const auto start = std::chrono::steady_clock::now();
  const RoadsidePerceptionConfig& c = impl_->config;
  VehicleDetection out;
  out.stamp = stamp;
  // 1. Foreground: near the expected position and away from the reference frame. Points farther from
  //    the reference position are background without a tree query (the paper's restriction).
  std::vector<Eigen::Vector3d> foreground;  // map frame, z = height above the road
  std::vector<int> index(1);
  std::vector<float> distance_sq(1);
  const double background_sq = c.background_distance * c.background_distance;
  for (const Eigen::Vector3f& p : frame) {
    const Eigen::Vector2d xy = impl_->rotation * p.head<2>().cast<double>() + impl_->mount.position.head<2>();
    if ((xy - reference).norm() > c.search_radius) continue;
    if (impl_->tree.nearestKSearch(pcl::PointXYZ(p.x(), p.y(), p.z()), 1, index, distance_sq) > 0 && distance_sq[0] <= background_sq)
      continue;
    const double height = p.z() + impl_->mount.position.z();
    if (height < 0.05) continue;  // the road itself
    foreground.emplace_back(xy.x(), xy.y(), height);
  }
  out.foreground_points = foreground.size();
  const auto groups = clusters(foreground, c.cluster_distance);
  // 2. The vehicle is every cluster that reaches into its footprint around the expected position. A
  //    body seen from afar falls apart into pieces (bumper, cabin, side) farther apart than any linkage
  //    distance that still separates it from its neighbours; its size, known from the CAM, joins them.
  const double reach = 0.5 * std::hypot(length, width) + 1.0;
  std::vector<std::size_t> vehicle_points;
  for (const auto& g : groups) {
    bool near = false;
    for (std::size_t i : g) near = near || (foreground[i].head<2>() - reference).norm() <= reach;
    if (near) vehicle_points.insert(vehicle_points.end(), g.begin(), g.end());
  }
  const std::vector<std::size_t>* vehicle = vehicle_points.size() >= 5 ? &vehicle_points : nullptr;
  if (vehicle) {
    // 3. The lowest part of the body: below the cut, at most max_points, lowest first.
    std::vector<Eigen::Vector3d> body;
    for (std::size_t i : *vehicle)
      if (!c.height_cut || foreground[i].z() < c.cut_height) body.push_back(foreground[i]);
    std::sort(body.begin(), body.end(), [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return a.z() < b.z(); });
    if (c.max_points > 0 && body.size() > static_cast<std::size_t>(c.max_points)) body.resize(static_cast<std::size_t>(c.max_points));
    if (body.size() >= 3) {
      std::vector<Eigen::Vector2d> xy;
      for (const auto& p : body) xy.push_back(p.head<2>());
      const FittedRectangle fit = fitLShape(xy, c.lshape);
      // 4. The plain L-shape centre, or the true-size box on the alignment point.
      const AlignedBox box = alignTrueSizeBox(fit, xy, impl_->mount.position.head<2>(), length, width, heading_prior);
      out.found = true;
      out.fit_points = body.size();
      out.alignment_point = box.alignment_point;
      out.position = c.align_true_size ? box.center : fit.center;
      out.yaw = box.yaw;
    }
  }
  out.processing_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace coloc::sim
