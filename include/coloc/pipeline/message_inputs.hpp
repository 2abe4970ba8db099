#pragma once
// Decoded ROS 2 messages to the pipeline's inputs, the same way live (over DDS) and offline (from a
// log): point clouds with per-point times, twists from Odometry, TwistWithCovarianceStamped or Imu,
// covariances completed as the configuration says, and roadside fixes from PoseWithCovarianceStamped.
#include <optional>
#include <string>

#include "coloc/core/types.hpp"
#include "coloc/io/ros_messages.hpp"
#include "coloc/ndt/point_cloud.hpp"
#include "coloc/pipeline/config.hpp"
#include "coloc/rsu_client/rsu_fix.hpp"

namespace coloc::pipeline {

/// x, y, z and, when the driver provides one, each point's time within the sweep (for deskewing).
/// Throws coloc::Error naming the reason for a cloud without float x/y/z, big-endian data, or a data
/// block shorter than width x height x point_step. Non-finite points are dropped.
ndt::PointCloud toPointCloud(const io::PointCloud2& message);

/// A message's covariance as the filter gets it: the configured override if there is one, the fallback
/// when the message carries none (all zeros or all +inf), and zeros read as "not measured" if so set.
/// `used_fallback` says whether the fallback was taken.
Matrix6d completeCovariance(Matrix6d covariance, const Vector6d& fallback, const InputConfig* input, const MessageConfig& messages,
                            bool& used_fallback);

/// An IMU measures angular velocity only: its twist has +inf on the linear components.
TwistMeasurement twistFromImu(const io::Imu& imu);

/// The twist of an Odometry, TwistWithCovarianceStamped or Imu message, covariance completed.
/// Throws coloc::Error for a message of another kind.
TwistMeasurement twistFromMessage(const io::RosMessage& message, const InputConfig* input, const MessageConfig& messages,
                                  bool& used_fallback);
/// The pose of an Odometry, PoseWithCovarianceStamped or PoseStamped message, covariance completed.
PoseMeasurement poseFromMessage(const io::RosMessage& message, const InputConfig* input, const MessageConfig& messages,
                                bool& used_fallback);

/// A roadside fix as an RSU sends it (PoseWithCovarianceStamped on /rsu/<id>/fix): its stamp, x and
/// y, and its yaw only if the sender gave the yaw a finite variance.
rsu_client::RsuFix fixFromMessage(const io::StampedPose& message, const std::string& rsu_id);
/// A fix addressed to one vehicle (nav_msgs/msg/Odometry on /rsu/<id>/addressed_fix): the same, and the
/// station id its child_frame_id names (kept as sent for the checks).
rsu_client::RsuFix fixFromMessage(const io::Odometry& message, const std::string& rsu_id);
/// Either of the two, by the decoded message's type; throws coloc::Error for another type.
rsu_client::RsuFix fixFromMessage(const io::RosMessage& message, const std::string& rsu_id);

}  // namespace coloc::pipeline
