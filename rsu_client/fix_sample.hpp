#pragma once
// A received fix sample (the generated ROS 2 message class) as an RsuFix: position, a yaw when the
// sender gave it a finite variance, and what the message said beside them (frame, covariance, the
// stamp's nanosec field) for the checks. Shared by the DDS subscriber and the fuzz target of it.
#include <string>

#include "PoseWithCovarianceStamped.h"
#include "coloc/rsu_client/rsu_fix.hpp"

namespace coloc::rsu_client {

RsuFix fixFromSample(const geometry_msgs::msg::PoseWithCovarianceStamped& msg, const std::string& rsu_id);

}  // namespace coloc::rsu_client
