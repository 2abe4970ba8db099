// NDT for a vehicle whose position is known (a roadside fix, GNSS) and whose heading is not: the scan
// is matched from headings spread around the circle and the best match wins. NDT's basin in yaw is a
// few tens of degrees, so a dozen or more starts find the true heading where the scene constrains it.
#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "coloc/ndt/ndt_pose_source.hpp"

namespace coloc::ndt {

namespace {

// The ground under a position: a low percentile of the map's points within a few metres, since the
// vehicle's frame (base_link) sits on the road and a fix gives no height. nullopt where the map has none.
std::optional<double> groundHeight(const TileMap& map, const Eigen::Vector2d& xy) {
  constexpr double kRadius = 4.0;
  std::vector<float> heights;
  for (const std::size_t tile : map.tilesWithin(xy, kRadius)) {
    const PointCloud cloud = map.load(tile);
    for (const Eigen::Vector3f& p : cloud.points)
      if ((p.head<2>().cast<double>() - xy).squaredNorm() <= kRadius * kRadius) heights.push_back(p.z());
  }
  if (heights.empty()) return std::nullopt;
  auto low = heights.begin() + static_cast<std::ptrdiff_t>(heights.size() / 10);
  std::nth_element(heights.begin(), low, heights.end());
  return *low;
}

}  // namespace

ScanOutcome NdtPoseSource::searchHeading(const PointCloud& scan, Stamp stamp, const Eigen::Vector2d& position, const HeadingSearch& search) {
  ++counters_.scans;
  ++counters_.heading_searches;
  ScanOutcome out;
  map_.update(position);
  const auto target = map_.target();
  if (!target) {
    ++counters_.no_map;
    out.detail = "no map tile within reach of the position to search the heading at";
    return out;
  }
  const double z = groundHeight(map_.map(), position).value_or(0.0);
  const PointCloud cloud = preprocessScan(scan, config_.preprocess, search.vx, 0.0);
  out.points_used = cloud.size();
  if (cloud.empty()) {
    ++counters_.empty_scan;
    out.detail = "no point left after preprocessing";
    return out;
  }
  const int n = std::max(1, search.candidates);
  bool found = false;
  int tried = 0;
  for (int k = 0; k < n; ++k) {
    const double yaw = -M_PI + 2.0 * M_PI * k / n;
    if (search.near && std::abs(wrapAngle(yaw - *search.near)) > search.within) continue;
    ++tried;
    const Eigen::Isometry3d base = Eigen::Translation3d(position.x(), position.y(), z) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ());
    const AlignResult r = align(*target, cloud, base.matrix() * base_to_lidar_, config_.ndt);
    counters_.align_ms_total += r.elapsed_ms;
    if (!r.accepted() || (found && r.nvtl <= out.alignment.nvtl)) continue;
    found = true;
    out.alignment = r;
  }
  if (!found) {
    out.detail = "none of " + std::to_string(tried) + " headings searched gave an accepted match";
    return out;
  }
  producePose(out, stamp);
  ++counters_.poses;
  return out;
}

}  // namespace coloc::ndt
