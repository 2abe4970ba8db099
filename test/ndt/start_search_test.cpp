// NDT from many starting poses on the real HDL-32E pair (the first scan as the map): the heading of a
// vehicle whose position alone is known, and a better match than the one at a pose given wrongly.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "coloc/ndt/ndt_pose_source.hpp"
#include "coloc/ndt/pcd_file.hpp"
#include "coloc/ndt/preprocess.hpp"
#include "real_data.hpp"

namespace coloc::ndt {
namespace {

constexpr Stamp kStamp = 1'700'000'000'000'000'000LL;

struct Pair {
  PointCloud map, scan;
  Eigen::Matrix4d truth;  ///< the scan's LiDAR in the map
  double lidar_height;    ///< above the ground under it
};

Pair loadPair() {
  Pair p{loadPcd(testing::realData("hdl32e_pair/target.pcd")), loadPcd(testing::realData("hdl32e_pair/source.pcd")),
         testing::readMatrix4(testing::realData("hdl32e_pair/T_target_source.gt1.txt")), 0.0};
  // The ground under the scan's LiDAR: a low percentile of the map's points within 4 m, as the search takes it.
  std::vector<float> z;
  for (const Eigen::Vector3f& q : p.map.points)
    if ((q.head<2>().cast<double>() - p.truth.topRightCorner<2, 1>()).norm() <= 4.0) z.push_back(q.z());
  std::nth_element(z.begin(), z.begin() + z.size() / 10, z.end());
  p.lidar_height = p.truth(2, 3) - z[z.size() / 10];
  return p;
}

NdtPoseSource sourceFor(const Pair& p) {
  NdtPoseSourceConfig config;
  config.lidar_pose << 0.0, 0.0, p.lidar_height, 0.0, 0.0, 0.0;
  config.preprocess.deskew = false;
  config.preprocess.voxel_size = 1.0;  // one scan as the map is sparser than a survey: more of the scan to match
  config.preprocess.max_points = 0;
  return NdtPoseSource(TileMap::fromCloud(p.map, 20.0), config);
}

double yawOf(const Eigen::Matrix3d& r) { return std::atan2(r(1, 0), r(0, 0)); }

TEST(StartSearch, FindsTheHeadingOfAVehicleWhosePositionAloneIsKnown) {
  const Pair p = loadPair();
  NdtPoseSource ndt = sourceFor(p);
  const ScanOutcome found = ndt.searchHeading(p.scan, kStamp, p.truth.topRightCorner<2, 1>(), HeadingSearch{});
  ASSERT_TRUE(found.produced) << found.detail;
  EXPECT_NEAR(wrapAngle(rollPitchYaw(found.pose.pose.orientation)[2] - yawOf(p.truth.topLeftCorner<3, 3>())), 0.0, 1.0 * M_PI / 180.0);
  EXPECT_LT((found.pose.pose.position.head<2>() - p.truth.topRightCorner<2, 1>()).norm(), 0.2);
  EXPECT_EQ(ndt.counters().searches, 1u);
  EXPECT_EQ(ndt.counters().scans, 1u);  // one scan, however many starts
  EXPECT_EQ(ndt.counters().poses, 1u);
}

TEST(StartSearch, AMatchBetterThanTheOneAtAWrongPoseIsFoundAroundIt) {
  const Pair p = loadPair();
  NdtPoseSource ndt = sourceFor(p);
  Pose wrong;  // 5 m to the side of the truth, the base on the ground
  wrong.position = p.truth.topRightCorner<3, 1>() + Eigen::Vector3d(0.0, 5.0, -p.lidar_height);
  wrong.orientation = Eigen::Quaterniond(p.truth.topLeftCorner<3, 3>());
  ScanOutcome at_wrong;
  const ScanOutcome best = ndt.searchAround(p.scan, kStamp, wrong, {2.0, 4.0, 6.0}, 8, 0.0, at_wrong);
  ASSERT_TRUE(best.produced) << best.detail;
  EXPECT_LT((best.pose.pose.position.head<2>() - p.truth.topRightCorner<2, 1>()).norm(), 0.2);
  if (at_wrong.produced) {
    EXPECT_GT(best.alignment.nvtl, at_wrong.alignment.nvtl + 0.05);
  }
  // From the truth itself, nothing around beats it.
  Pose right = wrong;
  right.position.y() -= 5.0;
  ScanOutcome at_right;
  const ScanOutcome around_right = ndt.searchAround(p.scan, kStamp, right, {2.0, 4.0, 6.0}, 8, 0.0, at_right);
  ASSERT_TRUE(at_right.produced && around_right.produced);
  EXPECT_LT((around_right.pose.pose.position - at_right.pose.pose.position).head<2>().norm(), 1.0);
}

}  // namespace
}  // namespace coloc::ndt
