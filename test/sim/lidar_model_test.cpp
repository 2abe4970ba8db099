#include <gtest/gtest.h>

#include <cmath>

#include "coloc/sim/lidar_model.hpp"

namespace coloc::sim {
namespace {

// A roadside LiDAR 2 m above the road, a car-sized box at `distance` straight ahead: how many returns
// come from the car's lower part (0.15 m to 0.8 m above the road), where the L-shape fit works?
int lowReturns(const LidarSpec& spec, double distance) {
  RayCaster world;
  world.addMesh(groundRectangle({-100, -100}, {100, 100}));
  const int car = world.addMesh(box({static_cast<float>(distance), 0.0f, 0.0f}, {4.5f, 1.8f, 1.5f}, 0.3f));
  world.commit();
  LidarSpec quiet = spec;
  quiet.range_noise = 0.0;
  std::mt19937_64 rng(1);
  const auto points = scanSweep(quiet, world, [](double) { return Eigen::Isometry3d(Eigen::Translation3d(0, 0, 2.0)); }, rng);
  int n = 0;
  for (const LidarPoint& p : points) {
    const double z = p.position.z() + 2.0;
    if (p.mesh == car && z >= 0.15 && z <= 0.8) ++n;
  }
  return n;
}

TEST(LidarModel, Vlp16At2mSeesNoLowVehiclePartFrom40mOn) {
  // The reason its useful roadside range is 30 m: between its -3 and -1 deg beams lies a gap.
  EXPECT_GT(lowReturns(vlp16(), 20.0), 0);
  EXPECT_GT(lowReturns(vlp16(), 28.0), 0);
  for (double d : {40.0, 45.0, 50.0}) EXPECT_EQ(lowReturns(vlp16(), d), 0) << "at " << d << " m";
}

TEST(LidarModel, Vlp32cStillSeesTheLowPartAt50m) { EXPECT_GT(lowReturns(vlp32c(), 50.0), 0); }

TEST(LidarModel, BeamTablesAreVelodynesCalibration) {
  const LidarSpec a = vlp16(), b = vlp32c();
  ASSERT_EQ(a.vertical_deg.size(), 16u);
  ASSERT_EQ(b.vertical_deg.size(), 32u);
  ASSERT_EQ(b.azimuth_offset_deg.size(), 32u);
  EXPECT_EQ(b.vertical_deg[0], -25.0);
  EXPECT_EQ(b.vertical_deg[29], 15.0);
  EXPECT_EQ(a.vertical_deg[14], -1.0);
}

TEST(LidarModel, SweepHasTheRightSizeTimesAndNoise) {
  RayCaster world;
  world.addMesh(groundRectangle({-200, -200}, {200, 200}));
  world.commit();
  std::mt19937_64 rng(7);
  const LidarSpec spec = vlp16();
  const auto points = scanSweep(spec, world, [](double) { return Eigen::Isometry3d(Eigen::Translation3d(0, 0, 1.8)); }, rng);
  // Of the 8 downward beams, the 7 from -15 to -3 deg reach the ground within 100 m at every one of the
  // 1,800 azimuths; the -1 deg beam would need 103 m.
  EXPECT_EQ(points.size(), 7u * 1800u);
  float latest = 0.0f;
  double sum_sq = 0.0;
  for (const LidarPoint& p : points) {
    latest = std::max(latest, p.time);
    sum_sq += std::pow(p.position.z() + 1.8, 2) / std::pow(p.position.normalized().z(), 2);  // range error, squared
  }
  EXPECT_LT(latest, 0.1f);
  EXPECT_GT(latest, 0.099f);
  EXPECT_NEAR(std::sqrt(sum_sq / points.size()), spec.range_noise, 0.002);
}

TEST(LidarModel, SameSeedSameScan) {
  RayCaster world;
  world.addMesh(box({10, 0, 0}, {2, 10, 5}));
  world.commit();
  std::mt19937_64 a(3), b(3);
  const auto still = [](double) { return Eigen::Isometry3d::Identity(); };
  const auto pa = scanSweep(vlp16(), world, still, a), pb = scanSweep(vlp16(), world, still, b);
  ASSERT_EQ(pa.size(), pb.size());
  for (std::size_t i = 0; i < pa.size(); ++i) EXPECT_EQ(pa[i].position, pb[i].position);
}

TEST(LidarModel, MovingSensorScanCarriesMotionDistortion) {
  // Driving at 20 m/s towards a wall 30 m ahead: the last firings see it 2 m closer than the first.
  RayCaster world;
  world.addMesh(box({30, 0, 0}, {1, 200, 10}));
  world.commit();
  std::mt19937_64 rng(1);
  LidarSpec spec = vlp16();
  spec.range_noise = 0.0;
  const auto points = scanSweep(spec, world, [](double t) { return Eigen::Isometry3d(Eigen::Translation3d(20.0 * t, 0, 1)); }, rng);
  double first = 0, last = 0;
  for (const LidarPoint& p : points) {
    if (std::abs(p.position.y()) > 0.5 || p.laser != 14) continue;  // the -1 deg beam straight ahead
    (p.time < 0.05f ? first : last) = p.position.x();
  }
  EXPECT_NEAR(first, 29.5, 0.05);
  EXPECT_NEAR(last, 27.5, 0.05);
}

}  // namespace
}  // namespace coloc::sim
