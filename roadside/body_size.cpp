#include "coloc/roadside/body_size.hpp"

#include <algorithm>
#include <string>
#include <vector>

#include "coloc/core/error.hpp"

namespace coloc::roadside {

namespace {

// The face from `corner` along `direction` over `extent`, with `points` returns: its side, or -1.
double measureSide(const Eigen::Vector2d& corner, const Eigen::Vector2d& direction, double extent, int points, const Eigen::Vector2d& lidar,
                   double azimuth_step, const BodySizeConfig& c) {
  if (points < c.min_points || !(extent > 0.0)) return -1.0;
  const Eigen::Vector2d sight = corner + extent * direction - lidar;
  const double range = sight.norm();
  if (!(range > 1e-6)) return -1.0;
  // Incidence on the face at its far end: between the line of sight and the face's normal.
  const double cos_incidence = std::abs(sight.dot(Eigen::Vector2d(-direction.y(), direction.x()))) / range;
  if (cos_incidence < std::cos(c.max_incidence)) return -1.0;
  // What the extent leaves out: the last azimuth step's share, half a step on average, and the far
  // corner's rounding. The corner's arc turns away from the LiDAR: its normal at angle phi from the
  // face's meets the line of sight at phi + psi, and the arc returns while that is short of grazing.
  const double psi = std::acos(std::min(1.0, cos_incidence));
  const double rounded = c.corner_radius * (1.0 - std::sin(std::max(0.0, c.arc_grazing - psi)));
  return extent + 0.5 * range * azimuth_step / cos_incidence + rounded;
}

void keep(std::deque<double>& measures, double side, int max) {
  if (!(side > 0.0) || !std::isfinite(side)) return;
  measures.push_back(side);
  while (static_cast<int>(measures.size()) > std::max(1, max)) measures.pop_front();
}

}  // namespace

void validate(const BodySizeConfig& c) {
  const auto fail = [](const char* key, const char* what) { throw Error(std::string("body size: ") + key + " must be " + what); };
  if (c.min_points < 1) fail("min_points", ">= 1");
  if (c.min_measures < 1) fail("min_measures", ">= 1");
  if (c.max_measures < c.min_measures) fail("max_measures", "at least min_measures");
  if (!(c.max_incidence > 0.0 && c.max_incidence < 0.5 * M_PI)) fail("max_incidence", "in (0, 90) deg");
  if (!(c.arc_grazing > 0.0 && c.arc_grazing < 0.5 * M_PI)) fail("arc_grazing", "in (0, 90) deg");
  if (!(c.corner_radius >= 0.0) || !std::isfinite(c.corner_radius)) fail("corner_radius", "finite and >= 0");
  if (!(c.quantile >= 0.0 && c.quantile <= 1.0)) fail("quantile", "in [0, 1]");
  if (!(c.tolerance >= 0.0) || !std::isfinite(c.tolerance)) fail("tolerance", "finite and >= 0");
  if (!std::isfinite(c.frame_tolerance)) fail("frame_tolerance", "finite");
  if (!std::isfinite(c.doubt_tolerance)) fail("doubt_tolerance", "finite");
  if (!(c.max_shortfall > 0.0) || !std::isfinite(c.max_shortfall)) fail("max_shortfall", "finite and > 0");
  if (!(c.min_seen_height >= 0.0) || !std::isfinite(c.min_seen_height)) fail("min_seen_height", "finite and >= 0");
  if (!(c.end_clearance >= 0.0) || !std::isfinite(c.end_clearance)) fail("end_clearance", "finite and >= 0");
}

Eigen::Vector2d measureBodySides(const AlignedBox& box, const Eigen::Vector2d& lidar, double azimuth_step, const BodySizeConfig& c) {
  if (!c.enabled || !box.corner_seen) return {-1.0, -1.0};
  return {measureSide(box.alignment_point, box.along, box.length_face_extent, box.length_face_points, lidar, azimuth_step, c),
          measureSide(box.alignment_point, box.across, box.width_face_extent, box.width_face_points, lidar, azimuth_step, c)};
}

void BodySizeLearner::add(const Eigen::Vector2d& sides) {
  keep(length_, sides.x(), config_.max_measures);
  keep(width_, sides.y(), config_.max_measures);
}

double BodySizeLearner::learned(const std::deque<double>& measures) const {
  if (static_cast<int>(measures.size()) < std::max(1, config_.min_measures)) return -1.0;
  std::vector<double> sorted(measures.begin(), measures.end());
  const auto k = static_cast<std::size_t>(std::clamp(config_.quantile, 0.0, 1.0) * static_cast<double>(sorted.size() - 1) + 0.5);
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(k), sorted.end());
  return sorted[k];
}

Eigen::Vector2d BodySizeLearner::size(double cam_length, double cam_width) const {
  const auto side = [&](const std::deque<double>& measures, double cam) {
    const double l = config_.enabled ? learned(measures) : -1.0;
    return l > 0.0 && l < cam - config_.tolerance ? l : cam;
  };
  return {side(length_, cam_length), side(width_, cam_width)};
}

Eigen::Vector2d BodySizeLearner::doubt(double cam_length, double cam_width) const {
  return sizeDoubt(size(cam_length, cam_width), cam_length, cam_width, config_.tolerance);
}

Eigen::Vector2d frameBodySize(const Eigen::Vector2d& measured, double cam_length, double cam_width, const BodySizeConfig& c) {
  const auto side = [&](double m, double cam) {
    const double short_by = cam - m;
    return c.enabled && c.frame_tolerance > 0.0 && m > 0.0 && short_by > c.frame_tolerance && short_by <= c.max_shortfall ? m : cam;
  };
  return {side(measured.x(), cam_length), side(measured.y(), cam_width)};
}

Eigen::Vector2d sizeDoubt(const Eigen::Vector2d& used, double cam_length, double cam_width, double tolerance) {
  const bool length_measured = used.x() != cam_length, width_measured = used.y() != cam_width;
  if (length_measured == width_measured) return Eigen::Vector2d::Constant(length_measured ? tolerance : 0.0);
  return length_measured ? Eigen::Vector2d(tolerance, cam_length - used.x()) : Eigen::Vector2d(cam_width - used.y(), tolerance);
}

Eigen::Vector2d frameDoubt(const Eigen::Vector2d& measured, const Eigen::Vector2d& used, double cam_length, double cam_width,
                           const BodySizeConfig& c) {
  if (!c.enabled || !(c.doubt_tolerance > 0.0)) return Eigen::Vector2d::Zero();
  const auto excess = [&](double m, double u, double cam) {
    const double short_by = cam - m;
    return u == cam && m > 0.0 && short_by > c.doubt_tolerance && short_by <= c.max_shortfall ? short_by : 0.0;
  };
  const double doubt = std::max(excess(measured.x(), used.x(), cam_length), excess(measured.y(), used.y(), cam_width));
  return Eigen::Vector2d::Constant(doubt);
}

Eigen::Matrix2d sizeCovariance(const Eigen::Vector2d& doubt, double yaw) {
  const Eigen::Vector2d half = 0.5 * doubt;  // half a side's error moves the centre
  const Eigen::Vector2d along(std::cos(yaw), std::sin(yaw)), across(-along.y(), along.x());
  return half.x() * half.x() * along * along.transpose() + half.y() * half.y() * across * across.transpose();
}

}  // namespace coloc::roadside
