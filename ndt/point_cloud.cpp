#include "coloc/ndt/point_cloud.hpp"

namespace coloc::ndt {

PointCloud transformed(const PointCloud& cloud, const Eigen::Matrix4d& transform) {
  PointCloud out;
  out.times = cloud.times;
  out.points.reserve(cloud.size());
  const Eigen::Matrix3f R = transform.topLeftCorner<3, 3>().cast<float>();
  const Eigen::Vector3f t = transform.topRightCorner<3, 1>().cast<float>();
  for (const Eigen::Vector3f& p : cloud.points) out.points.push_back(R * p + t);
  return out;
}

}  // namespace coloc::ndt
