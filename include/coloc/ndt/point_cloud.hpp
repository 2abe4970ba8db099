#pragma once
// coloc's own point cloud: plain vectors, so that public headers need no PCL. Conversions to PCL types
// live inside ndt/ only.
#include <Eigen/Core>
#include <vector>

namespace coloc::ndt {

struct PointCloud {
  std::vector<Eigen::Vector3f> points;
  /// Seconds since the start of the sweep, one per point, for deskewing; empty if the sensor gave none.
  std::vector<float> times;

  std::size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
  bool hasTimes() const { return !times.empty() && times.size() == points.size(); }
};

/// The cloud with every point moved by `transform` (times kept).
PointCloud transformed(const PointCloud& cloud, const Eigen::Matrix4d& transform);

}  // namespace coloc::ndt
