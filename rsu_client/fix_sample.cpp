#include "fix_sample.hpp"

#include <cmath>

#include "coloc/core/time.hpp"
#include "coloc/core/types.hpp"

namespace coloc::rsu_client {

RsuFix fixFromSample(const geometry_msgs::msg::PoseWithCovarianceStamped& msg, const std::string& rsu_id) {
  RsuFix fix;
  fix.rsu_id = rsu_id;
  fix.stamp = fromRosTime(msg.header().stamp().sec(), msg.header().stamp().nanosec());
  fix.x = msg.pose().pose().position().x();
  fix.y = msg.pose().pose().position().y();
  const double yaw_variance = msg.pose().covariance()[35];
  if (std::isfinite(yaw_variance) && yaw_variance > 0.0) {
    const auto& q = msg.pose().pose().orientation();
    fix.yaw = rollPitchYaw(Eigen::Quaterniond(q.w(), q.x(), q.y(), q.z()))[2];
  }
  SentFields sent;
  sent.frame_id = msg.header().frame_id();
  sent.nanosec = msg.header().stamp().nanosec();
  for (int i = 0; i < 36; ++i) sent.covariance(i / 6, i % 6) = msg.pose().covariance()[i];
  fix.sent = std::move(sent);
  return fix;
}

}  // namespace coloc::rsu_client
