#pragma once
// The road under an RSU, from its background. Real roads are not one plane (a crown, gutters, a grade
// through the intersection: per car -0.23 to +0.29 m from the best plane on held-back real frames),
// and a pole's LiDAR is tilted. The perception cuts each vehicle at a height above the road under it,
// so that height must be the local road's.
//
// The road is found from the lowest background returns: a plane fitted robustly to the lowest return
// of each cell (a wall's foot, the road; a tree's canopy with nothing under it is an outlier), then
// each cell's own height from the returns near that plane. Fitted in the sensor frame, the plane's
// normal is the LiDAR's tilt and its distance the LiDAR's height: what commissioning reports against
// the registry's mount.
#include <Eigen/Core>
#include <optional>
#include <unordered_map>
#include <vector>

namespace coloc::roadside {

struct RoadSurfaceConfig {
  double cell = 2.0;            ///< m, the grid of local road heights
  double min_range = 3.0;       ///< m from the LiDAR: nearer returns are the pole and its mount
  double max_range = 60.0;      ///< m: farther, the returns are too sparse and the plane too long an arm
  double band = 0.5;            ///< m about the plane: returns within it are road
  int min_points = 3;           ///< returns of road a cell needs for a height of its own
  double smoothing = 2.0;       ///< m, the Gaussian's sigma between cells with returns and those without
};

/// The mount's roll and pitch (RsuMount's convention) and the LiDAR's height over the road that make
/// a ground plane fitted in the sensor frame level: the tilt to the road, a grade included.
struct Levelling {
  double roll = 0.0, pitch = 0.0, height = 0.0;
};

/// The plane z = a + b x + c y (in the frame it was fitted in), with how well it fits.
struct GroundPlane {
  double a = 0.0, b = 0.0, c = 0.0;
  std::size_t cells = 0;    ///< cells whose lowest return supported it
  double rms = 0.0;         ///< m, of those cells about it
  Eigen::Vector3d normal() const { return Eigen::Vector3d(-b, -c, 1.0).normalized(); }
  double at(const Eigen::Vector2d& xy) const { return a + b * xy.x() + c * xy.y(); }
};

/// The plane through the lowest return of each cell between min_range and max_range of the origin
/// (the LiDAR), by iteratively reweighted least squares; none if fewer than 10 cells have a return.
std::optional<GroundPlane> fitGroundPlane(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector2d& origin,
                                          const RoadSurfaceConfig& config = {});

Levelling levellingOf(const GroundPlane& sensor_plane);

/// The road's height over the map's plane, cell by cell.
class RoadSurface {
 public:
  /// A flat road at height 0.
  RoadSurface() = default;
  /// From background points in the map frame (z: height over the road datum of the mount), around the
  /// LiDAR at `lidar`; flat at 0 where nothing was seen.
  RoadSurface(const std::vector<Eigen::Vector3d>& background, const Eigen::Vector2d& lidar, const RoadSurfaceConfig& config = {});

  /// The road's height at `xy` (map frame): between the cells' own heights, bilinearly; the plane's
  /// where a cell has none.
  double height(const Eigen::Vector2d& xy) const;
  const std::optional<GroundPlane>& plane() const { return plane_; }
  /// Cells given a height (within reach of returns of the road).
  std::size_t cellsWithHeight() const { return heights_.size(); }

 private:
  double cell_ = 2.0;
  std::optional<GroundPlane> plane_;
  std::unordered_map<std::uint64_t, double> heights_;  ///< per cell (key of its integer indices)
  double cellHeight(std::int64_t i, std::int64_t j) const;
};

}  // namespace coloc::roadside
