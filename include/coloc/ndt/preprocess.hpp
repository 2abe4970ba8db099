#pragma once
// Scan preprocessing before NDT, each step its own function so a caller can compose them: range crop,
// deskew by the vehicle's motion during the sweep, voxel downsampling, and a cap on the point count.
#include <cstdint>

#include "coloc/ndt/point_cloud.hpp"

namespace coloc::ndt {

struct PreprocessConfig {
  double min_range = 1.0;    ///< m; closer returns are the vehicle itself
  double max_range = 60.0;   ///< m; Autoware crops at +-60 m
  bool deskew = true;        ///< when the scan has per-point times and a twist is given
  double voxel_size = 3.0;   ///< m; Autoware's downsampling; 0 = off
  std::size_t max_points = 1500;  ///< Autoware feeds NDT at most this many; 0 = no cap
  std::uint32_t seed = 1;    ///< for the cap's random subset, so runs are repeatable
};

/// Points with min_range <= |p| <= max_range (sensor frame).
PointCloud cropRange(const PointCloud& cloud, double min_range, double max_range);

/// Moves every point into the sensor frame at time 0 of the sweep, assuming constant forward speed
/// `vx` (m/s) and yaw rate `wz` (rad/s) over the sweep. Without per-point times, returns the cloud.
PointCloud deskew(const PointCloud& cloud, double vx, double wz);

/// One point per occupied voxel: the centroid of its points. Output order follows first appearance,
/// so the result does not depend on hashing. Points that are not finite (or beyond 2e9 voxels) have no
/// voxel and are left out.
PointCloud voxelDownsample(const PointCloud& cloud, double voxel_size);

/// At most `max_points` points, a random subset drawn with `seed` (deterministic).
PointCloud capPoints(const PointCloud& cloud, std::size_t max_points, std::uint32_t seed);

/// crop -> deskew -> voxel -> cap.
PointCloud preprocessScan(const PointCloud& scan, const PreprocessConfig& config, double vx = 0.0, double wz = 0.0);

}  // namespace coloc::ndt
