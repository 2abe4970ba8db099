#include "coloc/roadside/lshape_fit.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "coloc/core/error.hpp"

namespace coloc::roadside {

namespace {

double variance(const std::vector<double>& v) {
  if (v.empty()) return 0.0;
  double mean = 0.0;
  for (double x : v) mean += x;
  mean /= static_cast<double>(v.size());
  double s = 0.0;
  for (double x : v) s += (x - mean) * (x - mean);
  return s / static_cast<double>(v.size());
}

// The criterion at one angle; projections c1, c2 keep their pairing per point.
double score(const std::vector<double>& c1, const std::vector<double>& c2, const LShapeConfig& config) {
  const auto [min1, max1] = std::minmax_element(c1.begin(), c1.end());
  const auto [min2, max2] = std::minmax_element(c2.begin(), c2.end());
  if (config.criterion == LShapeCriterion::kArea) return -(*max1 - *min1) * (*max2 - *min2);
  double closeness = 0.0;
  std::vector<double> e1, e2;
  for (std::size_t i = 0; i < c1.size(); ++i) {
    // Distance of the point to the nearer edge of each pair, element by element.
    const double d1 = std::min(*max1 - c1[i], c1[i] - *min1);
    const double d2 = std::min(*max2 - c2[i], c2[i] - *min2);
    if (config.criterion == LShapeCriterion::kCloseness) {
      closeness += 1.0 / std::max(std::min(d1, d2), config.closeness_floor);
    } else {
      (d1 < d2 ? e1 : e2).push_back(d1 < d2 ? d1 : d2);
    }
  }
  return config.criterion == LShapeCriterion::kCloseness ? closeness : -variance(e1) - variance(e2);
}

// Where an edge lies: the outermost projection, or the median of the points within `band` of it if
// they spread at least `min_spread` along the edge (`along` are the same points' other projection).
double edgeOffset(const std::vector<double>& across, const std::vector<double>& along, double extreme, double band) {
  constexpr double kMinSpread = 0.3;  // m: a face, not the end of the perpendicular one
  constexpr std::size_t kMinPoints = 5;
  if (band <= 0.0) return extreme;
  std::vector<double> near;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (std::size_t i = 0; i < across.size(); ++i)
    if (std::abs(across[i] - extreme) <= band) {
      near.push_back(across[i]);
      lo = std::min(lo, along[i]);
      hi = std::max(hi, along[i]);
    }
  if (near.size() < kMinPoints || hi - lo < kMinSpread) return extreme;
  std::nth_element(near.begin(), near.begin() + near.size() / 2, near.end());
  return near[near.size() / 2];
}

Eigen::Vector2d intersect(const Eigen::Vector2d& n0, double c0, const Eigen::Vector2d& n1, double c1) {
  const double det = n0.x() * n1.y() - n1.x() * n0.y();
  return {(n1.y() * c0 - n0.y() * c1) / det, (n0.x() * c1 - n1.x() * c0) / det};
}

}  // namespace

FittedRectangle fitLShape(const std::vector<Eigen::Vector2d>& points, const LShapeConfig& config) {
  if (points.size() < 2) throw Error("L-shape fit: needs at least 2 points, got " + std::to_string(points.size()));
  if (!(config.angle_step_deg > 0.0)) throw Error("L-shape fit: angle step must be > 0");
  const int steps = static_cast<int>(std::floor(90.0 / config.angle_step_deg + 1e-9));
  double best = -std::numeric_limits<double>::infinity(), best_angle = 0.0;
  std::vector<double> c1(points.size()), c2(points.size());
  for (int k = 0; k <= steps; ++k) {  // integer steps: the last angle, pi/2, is tested too
    const double theta = std::min(k * config.angle_step_deg, 90.0) * M_PI / 180.0;
    const Eigen::Vector2d e1(std::cos(theta), std::sin(theta)), e2(-std::sin(theta), std::cos(theta));
    for (std::size_t i = 0; i < points.size(); ++i) {
      c1[i] = points[i].dot(e1);
      c2[i] = points[i].dot(e2);
    }
    const double q = score(c1, c2, config);
    if (q > best) {
      best = q;
      best_angle = theta;
    }
  }
  const Eigen::Vector2d e1(std::cos(best_angle), std::sin(best_angle)), e2(-std::sin(best_angle), std::cos(best_angle));
  for (std::size_t i = 0; i < points.size(); ++i) {
    c1[i] = points[i].dot(e1);
    c2[i] = points[i].dot(e2);
  }
  const auto [lo1, hi1] = std::minmax_element(c1.begin(), c1.end());
  const auto [lo2, hi2] = std::minmax_element(c2.begin(), c2.end());
  const double min1 = edgeOffset(c1, c2, *lo1, config.edge_band), max1 = edgeOffset(c1, c2, *hi1, config.edge_band);
  const double min2 = edgeOffset(c2, c1, *lo2, config.edge_band), max2 = edgeOffset(c2, c1, *hi2, config.edge_band);
  FittedRectangle r;
  r.angle = best_angle;
  r.corners = {intersect(e1, min1, e2, min2), intersect(e2, min2, e1, max1), intersect(e1, max1, e2, max2),
               intersect(e2, max2, e1, min1)};
  r.center = 0.25 * (r.corners[0] + r.corners[1] + r.corners[2] + r.corners[3]);
  return r;
}

AlignedBox alignTrueSizeBox(const FittedRectangle& fit, const std::vector<Eigen::Vector2d>& points, const Eigen::Vector2d& lidar,
                            double length, double width, double heading_prior) {
  // Points along each edge (corner i to corner i+1), away from its ends: a point at a corner would
  // otherwise count for the edge that merely starts there.
  constexpr double kNearEdge = 0.1, kEndMargin = 0.2;  // m
  std::array<int, 4> support{};
  for (int e = 0; e < 4; ++e) {
    const Eigen::Vector2d p0 = fit.corners[e], d = fit.corners[(e + 1) % 4] - p0;
    const double len = d.norm();
    if (len < 2.0 * kEndMargin) continue;
    for (const Eigen::Vector2d& p : points) {
      const double along = (p - p0).dot(d) / len;
      if (along > kEndMargin && along < len - kEndMargin && std::abs((p - p0).dot(Eigen::Vector2d(-d.y(), d.x())) / len) < kNearEdge)
        ++support[e];
    }
  }
  int nearest = -1;
  for (int pass = 0; pass < 2 && nearest < 0; ++pass)  // supported corners first; any corner if none is
    for (int i = 0; i < 4; ++i) {
      const bool supported = support[i] > 0 && support[(i + 3) % 4] > 0;
      if ((pass == 0 && !supported) || (nearest >= 0 && (fit.corners[i] - lidar).norm() >= (fit.corners[nearest] - lidar).norm()))
        continue;
      nearest = i;
    }
  const Eigen::Vector2d a = fit.corners[nearest];
  // Seen: each of its edges carries a few points (one or two can be a face's noise or a rounded end).
  constexpr int kCornerSupport = 3;
  const bool corner_seen = support[nearest] >= kCornerSupport && support[(nearest + 3) % 4] >= kCornerSupport;
  // The rectangle's sides at `a` run along its two axes. Each is oriented into the rectangle; a side of
  // no extent (all points on one face) is oriented away from the LiDAR, behind the face it sees.
  const Eigen::Vector2d e1(std::cos(fit.angle), std::sin(fit.angle)), e2(-std::sin(fit.angle), std::cos(fit.angle));
  auto inward = [&](const Eigen::Vector2d& axis) {
    double extent = 0.0;
    for (const Eigen::Vector2d& c : fit.corners) extent += (c - a).dot(axis);
    if (std::abs(extent) < 1e-6) extent = (a - lidar).dot(axis);
    return Eigen::Vector2d(extent >= 0.0 ? axis : -axis);
  };
  const Eigen::Vector2d u = inward(e1), v = inward(e2);
  // The length runs along the edge closer to the heading prior.
  const Eigen::Vector2d heading(std::cos(heading_prior), std::sin(heading_prior));
  const bool u_is_length = std::abs(u.dot(heading)) >= std::abs(v.dot(heading));
  const Eigen::Vector2d along = u_is_length ? u : v, across = u_is_length ? v : u;
  AlignedBox box;
  box.alignment_point = a;
  box.corner_seen = corner_seen;
  if (!corner_seen) {
    int face = 0;
    for (int e = 1; e < 4; ++e)
      if (support[e] > support[face]) face = e;
    const Eigen::Vector2d side = fit.corners[(face + 1) % 4] - fit.corners[face];
    const bool length_face = std::abs(side.normalized().dot(heading)) >= std::sqrt(0.5);
    box.face_shortfall = std::max(0.0, (length_face ? length : width) - side.norm());
    box.width_face_alone = !length_face;
    // How obliquely the LiDAR sees that face: the angle between the line of sight to its middle and its
    // normal.
    const Eigen::Vector2d middle = 0.5 * (fit.corners[face] + fit.corners[(face + 1) % 4]);
    const Eigen::Vector2d normal(-side.y(), side.x());
    const Eigen::Vector2d sight = middle - lidar;
    if (normal.norm() > 1e-9 && sight.norm() > 1e-9)
      box.face_obliquity = std::acos(std::min(1.0, std::abs(normal.normalized().dot(sight.normalized()))));
  }
  {
    const Eigen::Vector2d next = fit.corners[(nearest + 1) % 4] - a, previous = fit.corners[(nearest + 3) % 4] - a;
    const bool next_is_length = std::abs(next.dot(along)) >= std::abs(next.dot(across));
    box.length_face_points = next_is_length ? support[nearest] : support[(nearest + 3) % 4];
    box.width_face_points = next_is_length ? support[(nearest + 3) % 4] : support[nearest];
    box.length_face_extent = next_is_length ? next.norm() : previous.norm();
    box.width_face_extent = next_is_length ? previous.norm() : next.norm();
  }
  box.along = along;
  box.across = across;
  box.center = a + 0.5 * length * along + 0.5 * width * across;
  const Eigen::Vector2d forward = along.dot(heading) >= 0.0 ? along : -along;
  box.yaw = std::atan2(forward.y(), forward.x());
  return box;
}

}  // namespace coloc::roadside
