#include "coloc/pipeline/cam_size_correction.hpp"

#include "coloc/io/v2x_messages.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace coloc::pipeline {

Eigen::Vector2d CamSizeCorrection::apply(const Eigen::Vector2d& fix, const Eigen::Vector2d& rsu, double yaw) const {
  if (!enabled() || !fix.allFinite() || !rsu.allFinite() || !std::isfinite(yaw)) return fix;
  const Eigen::Rotation2Dd body(yaw);
  // The RSU in the body's frame: ahead (+x) shows the front, on the left (+y) the left side.
  const Eigen::Vector2d seen_from = body.inverse() * (rsu - fix);
  const double along = std::abs(seen_from.x()) > 0.5 * length ? (seen_from.x() > 0.0 ? 1.0 : -1.0) : 0.0;
  const double across = seen_from.y() > 0.0 ? 1.0 : -1.0;
  // The box's centre is half the CAM's size from the face seen; the body's is half its own.
  const double cam_length = sent_length > 0.0 ? sent_length : io::camSizeSent(length, step),
               cam_width = sent_width > 0.0 ? sent_width : io::camSizeSent(width, step);
  const Eigen::Vector2d shift(along * 0.5 * (cam_length - length), across * 0.5 * (cam_width - width));
  return fix + body * shift;
}

}  // namespace coloc::pipeline
