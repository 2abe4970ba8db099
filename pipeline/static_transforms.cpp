#include "coloc/pipeline/static_transforms.hpp"

#include <cmath>

#include "coloc/core/error.hpp"

namespace coloc::pipeline {

void StaticTransforms::add(const io::TransformStamped& t) {
  const std::string& parent = t.header.frame_id;
  const std::string& child = t.child_frame_id;
  const auto fail = [&](const std::string& why) {
    throw Error("static transform '" + parent + "' -> '" + child + "': " + why);
  };
  if (parent.empty() || child.empty()) fail("a frame without a name");
  if (parent == child) fail("a frame cannot be its own parent");
  if (!t.translation.allFinite() || !t.rotation.coeffs().allFinite()) fail("translation or rotation not finite");
  const double norm = t.rotation.norm();
  if (std::abs(norm - 1.0) > 1e-3) fail("rotation is not a unit quaternion (norm " + std::to_string(norm) + ")");
  if (const auto known = parent_.find(child); known != parent_.end() && known->second.first != parent)
    fail("'" + child + "' already has the parent '" + known->second.first + "' (a frame has one parent)");
  // Walking up from the new parent must not reach the child: that would close a loop.
  for (std::string up = parent;;) {
    if (up == child) fail("it would close a loop");
    const auto next = parent_.find(up);
    if (next == parent_.end()) break;
    up = next->second.first;
  }
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = t.rotation.normalized().toRotationMatrix();
  pose.translation() = t.translation;
  parent_[child] = {parent, pose};
}

std::pair<Eigen::Isometry3d, std::string> StaticTransforms::inRoot(const std::string& frame) const {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  std::string at = frame;
  // add() keeps the tree free of loops, so the walk ends at a root.
  for (auto up = parent_.find(at); up != parent_.end(); up = parent_.find(at)) {
    pose = up->second.second * pose;
    at = up->second.first;
  }
  return {pose, at};
}

std::optional<Eigen::Isometry3d> StaticTransforms::lookup(const std::string& base, const std::string& frame) const {
  if (base == frame) return Eigen::Isometry3d::Identity();
  const auto [frame_in_root, frame_root] = inRoot(frame);
  const auto [base_in_root, base_root] = inRoot(base);
  if (frame_root != base_root) return std::nullopt;
  return base_in_root.inverse() * frame_in_root;
}

Vector6d poseVector(const Eigen::Isometry3d& pose) {
  Vector6d v;
  v.head<3>() = pose.translation();
  v.tail<3>() = rollPitchYaw(Eigen::Quaterniond(pose.linear()));
  return v;
}

}  // namespace coloc::pipeline
