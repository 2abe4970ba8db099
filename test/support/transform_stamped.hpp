#pragma once
// A /tf transform built field by field. GCC 12 warns that a braced TransformStamped temporary's frame
// strings may be used uninitialised (a false positive), so tests build them here.
#include <string>

#include "coloc/io/ros_messages.hpp"

namespace coloc::testing {

inline io::TransformStamped transformStamped(Stamp stamp, const std::string& parent, const std::string& child, const Eigen::Vector3d& translation,
                                             const Eigen::Quaterniond& rotation) {
  io::TransformStamped out;
  out.header.stamp = stamp;
  out.header.frame_id = parent;
  out.child_frame_id = child;
  out.translation = translation;
  out.rotation = rotation;
  return out;
}

}  // namespace coloc::testing
