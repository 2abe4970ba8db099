// A log's /tf_static as a tree: the LiDAR's mounting looked up through a chain of frames, and every
// transform that cannot be in the tree refused with the frames and the reason, the tree unchanged.
#include "coloc/pipeline/static_transforms.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "coloc/core/error.hpp"

namespace coloc::pipeline {
namespace {

io::TransformStamped transform(const std::string& parent, const std::string& child, const Eigen::Vector3d& t, const Eigen::Quaterniond& q) {
  io::TransformStamped out;
  out.header.frame_id = parent;
  out.child_frame_id = child;
  out.translation = t;
  out.rotation = q;
  return out;
}

Eigen::Quaterniond yawed(double yaw) { return Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())); }

std::string errorOf(StaticTransforms& tree, const io::TransformStamped& t) {
  try {
    tree.add(t);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(StaticTransforms, TheLidarIsFoundThroughAChainOfFramesAndFromASiblingBranch) {
  StaticTransforms tree;
  tree.add(transform("base_footprint", "base_link", {0.0, 0.0, 0.3}, Eigen::Quaterniond::Identity()));
  tree.add(transform("base_link", "sensor_kit", {1.0, 0.0, 1.5}, yawed(M_PI / 2)));
  tree.add(transform("sensor_kit", "velodyne", {0.2, 0.0, 0.1}, Eigen::Quaterniond::Identity()));
  tree.add(transform("base_link", "imu", {0.0, 0.5, 0.0}, Eigen::Quaterniond::Identity()));
  // velodyne's origin: 0.2 m along sensor_kit's x, which points along base_link's y.
  const auto lidar = tree.lookup("base_link", "velodyne");
  ASSERT_TRUE(lidar.has_value());
  EXPECT_LT((lidar->translation() - Eigen::Vector3d(1.0, 0.2, 1.6)).norm(), 1e-12);
  EXPECT_NEAR(poseVector(*lidar)[5], M_PI / 2, 1e-12);
  // From the footprint, 0.3 m lower; from the IMU, across the tree.
  EXPECT_LT((tree.lookup("base_footprint", "velodyne")->translation() - Eigen::Vector3d(1.0, 0.2, 1.9)).norm(), 1e-12);
  EXPECT_LT((tree.lookup("imu", "velodyne")->translation() - Eigen::Vector3d(1.0, -0.3, 1.6)).norm(), 1e-12);
  EXPECT_TRUE(tree.lookup("velodyne", "velodyne")->isApprox(Eigen::Isometry3d::Identity()));
  EXPECT_FALSE(tree.lookup("base_link", "camera").has_value());
  EXPECT_FALSE(tree.lookup("map", "velodyne").has_value());
}

TEST(StaticTransforms, PoseVectorIsTheInverseOfHowTheLidarPoseIsRead) {
  const Vector6d v = (Vector6d() << 1.2, -0.3, 1.8, 0.02, -0.01, 0.09).finished();
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = v.head<3>();
  pose.linear() = quaternionFromRollPitchYaw(v[3], v[4], v[5]).toRotationMatrix();
  EXPECT_LT((poseVector(pose) - v).norm(), 1e-12);
}

TEST(StaticTransforms, ATransformThatCannotBeInTheTreeIsRefusedNamingItsFramesAndTheTreeIsUnchanged) {
  StaticTransforms tree;
  tree.add(transform("base_link", "velodyne", {1.0, 0.0, 1.8}, Eigen::Quaterniond::Identity()));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(errorOf(tree, transform("base_link", "", {0, 0, 0}, Eigen::Quaterniond::Identity())).find("without a name"), std::string::npos);
  EXPECT_NE(errorOf(tree, transform("lidar", "lidar", {0, 0, 0}, Eigen::Quaterniond::Identity())).find("its own parent"), std::string::npos);
  EXPECT_NE(errorOf(tree, transform("base_link", "imu", {nan, 0, 0}, Eigen::Quaterniond::Identity())).find("not finite"), std::string::npos);
  EXPECT_NE(errorOf(tree, transform("base_link", "imu", {0, 0, 0}, Eigen::Quaterniond(0, 0, 0, 0))).find("not a unit quaternion"),
            std::string::npos);
  const std::string second_parent = errorOf(tree, transform("map", "velodyne", {0, 0, 0}, Eigen::Quaterniond::Identity()));
  EXPECT_NE(second_parent.find("static transform 'map' -> 'velodyne': 'velodyne' already has the parent 'base_link'"), std::string::npos)
      << second_parent;
  EXPECT_NE(errorOf(tree, transform("velodyne", "base_link", {0, 0, 0}, Eigen::Quaterniond::Identity())).find("close a loop"), std::string::npos);
  EXPECT_EQ(tree.size(), 1u);
  EXPECT_LT((tree.lookup("base_link", "velodyne")->translation() - Eigen::Vector3d(1.0, 0.0, 1.8)).norm(), 1e-12);
}

TEST(StaticTransforms, ARotationJustOffUnitIsNormalisedAndAResentFrameReplacesItsTransform) {
  StaticTransforms tree;
  const Eigen::Quaterniond q = yawed(0.3);
  tree.add(transform("base_link", "velodyne", {1.0, 0.0, 1.8}, Eigen::Quaterniond(q.coeffs() * 1.0005)));
  EXPECT_NEAR(poseVector(*tree.lookup("base_link", "velodyne"))[5], 0.3, 1e-12);
  tree.add(transform("base_link", "velodyne", {1.1, 0.0, 1.8}, q));  // the broadcaster restarted with a new calibration
  EXPECT_EQ(tree.size(), 1u);
  EXPECT_NEAR(tree.lookup("base_link", "velodyne")->translation().x(), 1.1, 1e-12);
}

}  // namespace
}  // namespace coloc::pipeline
