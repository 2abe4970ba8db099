#pragma once
// L-shape fitting of a vehicle's points seen from one side (Zhang, Xu, Dong, Dolan, IEEE IV 2017), and
// the paper's refinement: a box of the vehicle's true size, sent in its CAM, aligned to the fitted corner
// closest to the LiDAR (the "alignment point"), which is the corner the LiDAR sees best.
#include <Eigen/Core>
#include <array>
#include <vector>

namespace coloc::roadside {

enum class LShapeCriterion {
  kArea,       ///< smallest rectangle: biased towards the diagonal when one L is seen (kept for comparison)
  kCloseness,  ///< points close to the two nearest edges
  kVariance,   ///< small spread of the distances to the nearest edges
};

struct LShapeConfig {
  LShapeCriterion criterion = LShapeCriterion::kVariance;
  double angle_step_deg = 1.0;    ///< search resolution over [0, 90] deg, both ends included
  double closeness_floor = 0.01;  ///< m, d0 of the closeness criterion
  /// m. Zhang et al. put each edge at the outermost point; with range noise that is the noise's
  /// extreme, a few centimetres outside the surface. An edge whose points within this band spread
  /// along it (a face the LiDAR sees) goes through their median instead. 0: outermost points.
  double edge_band = 0.1;
};

struct FittedRectangle {
  std::array<Eigen::Vector2d, 4> corners;  ///< in order around the rectangle
  double angle = 0.0;                      ///< rad in [0, pi/2]: direction of the first edge
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
};

/// Needs at least 2 points; throws coloc::Error otherwise.
FittedRectangle fitLShape(const std::vector<Eigen::Vector2d>& points, const LShapeConfig& config = {});

struct AlignedBox {
  Eigen::Vector2d center;           ///< centre of the true-size box
  double yaw;                       ///< heading of its length axis, resolved with the prior
  Eigen::Vector2d alignment_point;  ///< the fitted corner closest to the LiDAR
  bool corner_seen = true;          ///< both edges at the alignment point carry points
  /// Without a seen corner: how much shorter the one face seen is than the vehicle's side it belongs to
  /// (length or width, by the heading prior), m. A face seen whole ends at the vehicle's corners and the
  /// box still rests on a true one; a partial face's end is anywhere along the body.
  double face_shortfall = 0.0;
  /// Without a seen corner: whether the one face seen is a front or rear face (across the heading
  /// prior), and how obliquely the LiDAR sees it: the angle between the line of sight to its middle and
  /// its normal, rad (0: square on).
  bool width_face_alone = false;
  double face_obliquity = 0.0;
  /// Returns along the two faces meeting at the alignment point (away from its ends): the face along
  /// the length (which places the box across it) and the one along the width (which places it along),
  /// with each face's fitted extent, m. What the fix's covariance is made of (fix_covariance.hpp).
  int length_face_points = 0, width_face_points = 0;
  double length_face_extent = 0.0, width_face_extent = 0.0;
  /// Unit vectors from the alignment point into the box, along its length and across it.
  Eigen::Vector2d along = Eigen::Vector2d::UnitX(), across = Eigen::Vector2d::UnitY();
};

/// Places a box of `length` x `width` on the alignment point and extends it along the rectangle's edges
/// from there. The alignment point is the paper's: the fitted corner closest to `lidar` (x-y), taken
/// among the corners where both adjacent edges carry points. When the far part of a face is not seen,
/// the fitted rectangle shrinks towards the LiDAR and a corner that no face reaches can come nearest;
/// the corner where the two seen faces meet is the one the LiDAR really saw. Which edge carries the
/// length, and which way the vehicle faces, come from `heading_prior` (the vehicle's or the road's
/// direction), since a rectangle alone cannot tell.
AlignedBox alignTrueSizeBox(const FittedRectangle& fit, const std::vector<Eigen::Vector2d>& points, const Eigen::Vector2d& lidar,
                            double length, double width, double heading_prior);

}  // namespace coloc::roadside
