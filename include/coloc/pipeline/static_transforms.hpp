#pragma once
// The vehicle's fixed frames as a log's /tf_static gives them (tf2_msgs/TFMessage): a tree of
// parent -> child transforms, from which the LiDAR's mounting on the vehicle is looked up, so that a
// recorded log carries its own extrinsic calibration instead of the user copying it into the config.
#include <Eigen/Geometry>
#include <map>
#include <optional>
#include <string>
#include <utility>

#include "coloc/core/types.hpp"
#include "coloc/io/ros_messages.hpp"

namespace coloc::pipeline {

class StaticTransforms {
 public:
  /// Adds `t` (child_frame_id in header.frame_id). Throws coloc::Error naming the two frames and the
  /// reason, the tree unchanged: an empty frame name, a frame its own parent, a translation or rotation
  /// that is not finite, a rotation that is not a unit quaternion (norm off 1 by more than 1e-3; within
  /// that it is normalised, as tf2 does), a frame given a second parent, or a loop. The same frame sent
  /// again with the same parent replaces the earlier transform (a static broadcaster restarted).
  void add(const io::TransformStamped& t);

  /// Where `frame` is in `base` (a point p of `frame` is `T * p` in `base`), through their common
  /// ancestor; nullopt when the tree does not connect them. Identity for a frame in itself.
  std::optional<Eigen::Isometry3d> lookup(const std::string& base, const std::string& frame) const;

  bool empty() const { return parent_.empty(); }
  std::size_t size() const { return parent_.size(); }

 private:
  /// `frame` in its tree's root, and that root's name.
  std::pair<Eigen::Isometry3d, std::string> inRoot(const std::string& frame) const;

  std::map<std::string, std::pair<std::string, Eigen::Isometry3d>> parent_;  ///< child -> (parent, child in parent)
};

/// [x, y, z, roll, pitch, yaw] of a pose, as ndt.lidar_pose is written (the inverse of how the NDT
/// pose source builds the LiDAR's transform from it).
Vector6d poseVector(const Eigen::Isometry3d& pose);

}  // namespace coloc::pipeline
