#pragma once
// A received fix sample (the generated ROS 2 message class) as an RsuFix: position, a yaw when the
// sender gave it a finite variance, and what the message said beside them (frame, covariance, the
// stamp's nanosec field) for the checks. Shared by the DDS subscriber and the fuzz target of it.
#include <string>

#include "Odometry.h"
#include "PoseWithCovarianceStamped.h"
#include "coloc/rsu_client/rsu_fix.hpp"

namespace coloc::rsu_client {

/// An unaddressed fix (the /rsu/<id>/fix topic).
RsuFix fixFromSample(const geometry_msgs::msg::PoseWithCovarianceStamped& msg, const std::string& rsu_id);
/// An addressed fix (/rsu/<id>/addressed_fix): the same pose, and the vehicle it is for in
/// child_frame_id (the station id in decimal; kept as sent for the checks when it is not one).
RsuFix fixFromSample(const nav_msgs::msg::Odometry& msg, const std::string& rsu_id);

}  // namespace coloc::rsu_client
