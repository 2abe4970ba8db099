#include "fix_sample.hpp"

#include <cmath>

#include "coloc/core/time.hpp"
#include "coloc/core/types.hpp"

namespace coloc::rsu_client {

namespace {

RsuFix fromHeaderAndPose(const std_msgs::msg::Header& header, const geometry_msgs::msg::PoseWithCovariance& pose, const std::string& rsu_id) {
  RsuFix fix;
  fix.rsu_id = rsu_id;
  fix.stamp = fromRosTime(header.stamp().sec(), header.stamp().nanosec());
  fix.x = pose.pose().position().x();
  fix.y = pose.pose().position().y();
  const double yaw_variance = pose.covariance()[35];
  if (std::isfinite(yaw_variance) && yaw_variance > 0.0) {
    const auto& q = pose.pose().orientation();
    fix.yaw = rollPitchYaw(Eigen::Quaterniond(q.w(), q.x(), q.y(), q.z()))[2];
  }
  SentFields sent;
  sent.frame_id = header.frame_id();
  sent.nanosec = header.stamp().nanosec();
  for (int i = 0; i < 36; ++i) sent.covariance(i / 6, i % 6) = pose.covariance()[i];
  fix.sent = std::move(sent);
  return fix;
}

}  // namespace

RsuFix fixFromSample(const geometry_msgs::msg::PoseWithCovarianceStamped& msg, const std::string& rsu_id) {
  return fromHeaderAndPose(msg.header(), msg.pose(), rsu_id);
}

RsuFix fixFromSample(const nav_msgs::msg::Odometry& msg, const std::string& rsu_id) {
  RsuFix fix = fromHeaderAndPose(msg.header(), msg.pose(), rsu_id);
  fix.sent->child_frame_id = msg.child_frame_id();
  fix.station_id = parseStationId(msg.child_frame_id());
  return fix;
}

}  // namespace coloc::rsu_client
