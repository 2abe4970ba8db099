#pragma once
// sensor_msgs/PointCloud2 to coloc's point cloud: x, y, z and, when the driver provides one, each
// point's time within the sweep (for deskewing).
#include "coloc/io/ros_messages.hpp"
#include "coloc/ndt/point_cloud.hpp"

namespace coloc::tools {

/// Throws coloc::Error naming the reason for a cloud without float x/y/z, big-endian data, or a data
/// block shorter than width x height x point_step. Non-finite points are dropped.
ndt::PointCloud toPointCloud(const io::PointCloud2& message);

}  // namespace coloc::tools
