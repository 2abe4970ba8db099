#pragma once
// The paper's roadside perception (Sections III-B and III-D): background filtering of the current frame
// against a reference frame with a k-d tree, only near the vehicle's reference position; clustering;
// the points below 0.8 m, at most the 500 lowest; L-shape fit; the true-size box on the alignment
// point; the result in the map frame, stamped with the frame's capture time.
#include <Eigen/Core>
#include <memory>
#include <vector>

#include "coloc/core/time.hpp"
#include "coloc/sim/lshape_fit.hpp"

namespace coloc::sim {

struct RoadsidePerceptionConfig {
  double background_distance = 0.15;  ///< m; a point this close to the reference frame is background
  double search_radius = 8.0;         ///< m around the vehicle's reference position; beyond is background
  double cluster_distance = 0.6;      ///< m, Euclidean clustering
  bool height_cut = true;             ///< keep only points below cut_height (chassis, no mirrors)
  double cut_height = 0.8;            ///< m above the road
  int max_points = 500;               ///< the lowest this many go to the fit
  bool align_true_size = true;        ///< false: report the fitted rectangle's centre (the plain L-shape)
  LShapeConfig lshape;
};

/// Where the RSU's LiDAR stands: map position of the sensor (z = height above the road) and heading.
struct RsuMount {
  Eigen::Vector3d position = Eigen::Vector3d(0.0, 0.0, 2.0);
  double yaw = 0.0;
};

struct VehicleDetection {
  bool found = false;
  Stamp stamp = 0;                 ///< the frame's capture time
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  ///< vehicle centre, map frame
  double yaw = 0.0;                ///< map frame
  Eigen::Vector2d alignment_point = Eigen::Vector2d::Zero();
  std::size_t foreground_points = 0, fit_points = 0;
  double processing_ms = 0.0;      ///< measured, the whole pipeline
};

class RoadsidePerception {
 public:
  /// `reference_frame`: a frame of the empty scene, in the sensor frame.
  RoadsidePerception(const std::vector<Eigen::Vector3f>& reference_frame, const RsuMount& mount,
                     const RoadsidePerceptionConfig& config = {});
  ~RoadsidePerception();
  RoadsidePerception(RoadsidePerception&&) noexcept;
  RoadsidePerception& operator=(RoadsidePerception&&) noexcept;

  /// Detects the vehicle in `frame` (sensor frame). `reference_position` is where the vehicle is
  /// expected (map frame, e.g. from its CAM), `heading_prior` its heading, `length` and `width` its
  /// true dimensions from the CAM.
  VehicleDetection detect(const std::vector<Eigen::Vector3f>& frame, Stamp stamp, const Eigen::Vector2d& reference_position,
                          double heading_prior, double length, double width) const;

  const RoadsidePerceptionConfig& config() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace coloc::sim
