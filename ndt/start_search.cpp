// NDT from many starting poses, the best match kept: for a vehicle whose position is known (a roadside
// fix, GNSS) and whose heading is not, headings spread around the circle (NDT's basin in yaw is a few
// tens of degrees, so a dozen or more starts find the true heading where the scene constrains it); and
// around a pose given by hand, offsets on rings, to tell whether the map matches better elsewhere.
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

ScanOutcome NdtPoseSource::matchFromEach(const PointCloud& scan, Stamp stamp, const Eigen::Vector2d& near, double vx,
                                          const std::vector<Eigen::Matrix4d>& bases, ScanOutcome* first, bool as_scan,
                                          std::vector<Landing>* landings) {
  ++counters_.searches;
  if (as_scan) ++counters_.scans;
  ScanOutcome out;
  map_.update(near);
  const auto target = map_.target();
  if (!target) {
    if (as_scan) ++counters_.no_map;
    out.detail = "no map tile within reach of the place to search at";
    return out;
  }
  const PointCloud cloud = preprocessScan(scan, config_.preprocess, vx, 0.0);
  out.points_used = cloud.size();
  if (cloud.empty()) {
    if (as_scan) ++counters_.empty_scan;
    out.detail = "no point left after preprocessing";
    return out;
  }
  bool found = false;
  for (std::size_t k = 0; k < bases.size(); ++k) {
    const AlignResult r = align(*target, cloud, bases[k] * base_to_lidar_, config_.ndt);
    counters_.align_ms_total += r.elapsed_ms;
    if (k == 0 && first) {
      first->alignment = r;
      first->points_used = cloud.size();
      if (r.accepted()) producePose(*first, stamp);
    }
    if (!r.accepted()) continue;
    if (landings && k > 0) landings->push_back({Eigen::Matrix4d(r.transform * base_to_lidar_.inverse()).block<2, 1>(0, 3), r.nvtl});
    if (found && r.nvtl <= out.alignment.nvtl) continue;
    found = true;
    out.alignment = r;
  }
  if (!found) {
    out.detail = "none of " + std::to_string(bases.size()) + " starting poses gave an accepted match";
    return out;
  }
  producePose(out, stamp);
  if (as_scan) ++counters_.poses;
  return out;
}

ScanOutcome NdtPoseSource::searchHeading(const PointCloud& scan, Stamp stamp, const Eigen::Vector2d& position, const HeadingSearch& search) {
  const double z = groundHeight(map_.map(), position).value_or(0.0);
  std::vector<Eigen::Matrix4d> bases;
  const int n = std::max(1, search.candidates);
  for (int k = 0; k < n; ++k) {
    const double yaw = -M_PI + 2.0 * M_PI * k / n;
    if (search.near && std::abs(wrapAngle(yaw - *search.near)) > search.within) continue;
    bases.push_back((Eigen::Translation3d(position.x(), position.y(), z) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())).matrix());
  }
  // The scan the search starts the filter from is this source's scan, its pose the start's.
  return matchFromEach(scan, stamp, position, search.vx, bases, nullptr, true);
}

ScanOutcome NdtPoseSource::searchAround(const PointCloud& scan, Stamp stamp, const Pose& around, const std::vector<double>& radii, int directions,
                                        double vx, ScanOutcome& at_pose, std::vector<Landing>* landings) {
  const Eigen::Matrix4d center = (Eigen::Translation3d(around.position) * around.orientation.normalized()).matrix();
  std::vector<Eigen::Matrix4d> bases = {center};
  for (const double r : radii)
    for (int k = 0; k < directions; ++k) {
      const double a = 2.0 * M_PI * k / directions;
      Eigen::Matrix4d moved = center;
      moved(0, 3) += r * std::cos(a);
      moved(1, 3) += r * std::sin(a);
      bases.push_back(moved);
    }
  at_pose = ScanOutcome{};
  at_pose.detail = "no accepted match from the pose itself";
  return matchFromEach(scan, stamp, around.position.head<2>(), vx, bases, &at_pose, false, landings);
}

}  // namespace coloc::ndt
