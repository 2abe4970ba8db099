#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <tuple>
#include <random>

#include "coloc/ndt/preprocess.hpp"

namespace coloc::ndt {
namespace {

TEST(Preprocess, VoxelDownsampleKeepsOneCentroidPerVoxel) {
  PointCloud cloud;
  cloud.points = {{0.1f, 0.1f, 0.1f}, {0.3f, 0.5f, 0.1f}, {1.5f, 0.2f, 0.2f}, {-0.5f, 0.0f, 0.0f}};
  const PointCloud out = voxelDownsample(cloud, 1.0);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_TRUE(out.points[0].isApprox(Eigen::Vector3f(0.2f, 0.3f, 0.1f)));  // first two share a voxel
  EXPECT_TRUE(out.points[1].isApprox(Eigen::Vector3f(1.5f, 0.2f, 0.2f)));
  EXPECT_TRUE(out.points[2].isApprox(Eigen::Vector3f(-0.5f, 0.0f, 0.0f)));  // negative side is its own voxel
}

// Voxel coordinates beyond 2^20 on an axis (a map in projected coordinates at a fine voxel) were once
// packed 21 bits an axis into one key, and voxels far apart could share it: these two did. And points
// that are not finite have no voxel.
TEST(Preprocess, VoxelDownsampleKeepsFarApartVoxelsApartAndLeavesOutNonFinitePoints) {
  PointCloud cloud;
  const float nan = std::nanf("");
  cloud.points = {{0.05f, 0.05f, 104857.65f}, {nan, 0.0f, 0.0f}, {0.05f, 0.15f, -104857.55f},
                  {0.0f, std::numeric_limits<float>::infinity(), 0.0f}, {0.07f, 0.05f, 104857.65f}};
  const PointCloud out = voxelDownsample(cloud, 0.1);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_NEAR(out.points[0].z(), 104857.65, 0.01);
  EXPECT_NEAR(out.points[1].z(), -104857.55, 0.01);
  for (const auto& p : out.points) EXPECT_TRUE(p.allFinite());
}

TEST(Preprocess, CapTakesARepeatableSubsetOfTheRequestedSize) {
  PointCloud cloud;
  for (int i = 0; i < 5000; ++i) cloud.points.emplace_back(static_cast<float>(i), 0.0f, 0.0f);
  const PointCloud a = capPoints(cloud, 1500, 7), b = capPoints(cloud, 1500, 7), c = capPoints(cloud, 1500, 8);
  EXPECT_EQ(a.size(), 1500u);
  EXPECT_EQ(a.points, b.points);
  EXPECT_NE(a.points, c.points);
  // Spread over the whole cloud, not its first points.
  EXPECT_GT(a.points.back().x(), 4500.0f);
  EXPECT_EQ(capPoints(cloud, 0, 1).size(), 5000u);
}

TEST(Preprocess, CropKeepsTheRangeBand) {
  PointCloud cloud;
  cloud.points = {{0.5f, 0, 0}, {5, 0, 0}, {0, 59, 0}, {70, 0, 0}};
  const PointCloud out = cropRange(cloud, 1.0, 60.0);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out.points[1].y(), 59.0f);
}

TEST(Preprocess, DeskewUndoesTheMotionDuringTheSweep) {
  // A wall at x = 10 seen while driving at 10 m/s and turning at 0.5 rad/s: a point sampled at time t
  // is seen from where the sensor was then. Deskewing must put every point back on the wall.
  const double vx = 10.0, wz = 0.5;
  PointCloud scan;
  for (int i = 0; i <= 100; ++i) {
    const double t = 0.001 * i;  // 0..0.1 s
    const Eigen::Vector2d wall(10.0, -5.0 + 0.1 * i);
    const double yaw = wz * t;
    const Eigen::Vector2d sensor(vx * std::sin(yaw) / wz, vx * (1 - std::cos(yaw)) / wz);
    const Eigen::Vector2d d = wall - sensor;
    const Eigen::Vector2d local(std::cos(yaw) * d.x() + std::sin(yaw) * d.y(), -std::sin(yaw) * d.x() + std::cos(yaw) * d.y());
    scan.points.emplace_back(static_cast<float>(local.x()), static_cast<float>(local.y()), 0.0f);
    scan.times.push_back(static_cast<float>(t));
  }
  double skewed = 0.0;
  for (const auto& p : scan.points) skewed = std::max(skewed, std::abs(p.x() - 10.0));
  EXPECT_GT(skewed, 0.5);  // the raw scan is visibly bent
  const PointCloud fixed = deskew(scan, vx, wz);
  for (const auto& p : fixed.points) EXPECT_NEAR(p.x(), 10.0, 1e-4);
}

TEST(Preprocess, DeskewWithoutTimesLeavesTheScanAlone) {
  PointCloud cloud;
  cloud.points = {{1, 2, 3}};
  EXPECT_EQ(deskew(cloud, 10.0, 1.0).points, cloud.points);
}

// preprocessScan crops, deskews and downsamples in one pass; it must give the bytes of the steps one
// after the other, whatever the scan (times or not, points out of range or not finite) and settings.
TEST(Preprocess, TheOnePassPreprocessingGivesTheBytesOfItsStepsOneAfterTheOther) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> coordinate(-70.0f, 70.0f);
  PointCloud scan;
  for (int firing = 0; firing < 400; ++firing)
    for (int laser = 0; laser < 16; ++laser) {
      scan.points.emplace_back(coordinate(rng), coordinate(rng), 0.1f * coordinate(rng));
      scan.times.push_back(0.1f * firing / 400.0f);  // the lasers of a firing share its time
    }
  scan.points[17].x() = std::nanf("");
  scan.points[18] = {0.2f, 0.1f, 0.0f};  // inside min_range
  PointCloud without_times = scan;
  without_times.times.clear();
  for (const PointCloud* cloud : {&scan, &without_times})
    for (bool deskew_on : {true, false})
      for (double voxel : {3.0, 0.5, 0.0}) {
        PreprocessConfig config;
        config.deskew = deskew_on;
        config.voxel_size = voxel;
        config.max_points = 300;
        PointCloud steps = cropRange(*cloud, config.min_range, config.max_range);
        if (config.deskew) steps = deskew(steps, 8.0, 0.3);
        steps = capPoints(voxelDownsample(steps, config.voxel_size), config.max_points, config.seed);
        const PointCloud once = preprocessScan(*cloud, config, 8.0, 0.3);
        const std::string what = std::string(cloud->hasTimes() ? "times" : "no times") + (deskew_on ? ", deskew" : "") + ", voxel " + std::to_string(voxel);
        ASSERT_EQ(once.points.size(), steps.points.size()) << what;
        ASSERT_EQ(once.times.size(), steps.times.size()) << what;
        for (std::size_t i = 0; i < steps.size(); ++i) {
          EXPECT_EQ(once.points[i], steps.points[i]) << what << ", point " << i;
          if (steps.hasTimes()) {
            EXPECT_EQ(once.times[i], steps.times[i]) << what << ", point " << i;
          }
        }
      }
}

// The downsampling looks voxels up directly near the sensor and by hash beyond; either way each voxel
// is its points' centroid, in order of first appearance, as a plain map from voxel to sum gives it.
TEST(Preprocess, VoxelDownsampleIsThePlainCentroidPerVoxelNearTheSensorAndFarFromIt) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> near(-100.0f, 100.0f), far(-5000.0f, 5000.0f);
  PointCloud cloud;
  for (int i = 0; i < 20000; ++i) {
    const bool out = i % 7 == 0;
    cloud.points.emplace_back(out ? far(rng) : near(rng), out ? far(rng) : near(rng), 0.1f * near(rng));
    cloud.times.push_back(0.01f * (i % 10));
  }
  for (float edge : {-96.0f, -95.9f, 93.0f, 96.0f, -99.1f, 98.9f}) cloud.points.emplace_back(edge, -edge, edge), cloud.times.push_back(0.0f);
  for (int repeat = 0; repeat < 2; ++repeat) {  // the second time on a table the first left behind
    const PointCloud out = voxelDownsample(cloud, 3.0);
    std::map<std::tuple<long, long, long>, std::size_t> order;
    std::vector<std::array<double, 5>> sums;  // x, y, z, time, count
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const Eigen::Vector3d p = cloud.points[i].cast<double>();
      const auto key = std::make_tuple(static_cast<long>(std::floor(p.x() / 3.0)), static_cast<long>(std::floor(p.y() / 3.0)),
                                       static_cast<long>(std::floor(p.z() / 3.0)));
      const auto [it, fresh] = order.emplace(key, sums.size());
      if (fresh) sums.push_back({0, 0, 0, 0, 0});
      auto& s = sums[it->second];
      s[0] += p.x(), s[1] += p.y(), s[2] += p.z(), s[3] += cloud.times[i], s[4] += 1;
    }
    ASSERT_EQ(out.size(), sums.size());
    for (std::size_t v = 0; v < sums.size(); ++v) {
      const auto& s = sums[v];
      EXPECT_EQ(out.points[v], Eigen::Vector3f(static_cast<float>(s[0] / s[4]), static_cast<float>(s[1] / s[4]), static_cast<float>(s[2] / s[4])))
          << "voxel " << v;
      EXPECT_EQ(out.times[v], static_cast<float>(s[3] / s[4])) << "voxel " << v;
    }
  }
}

}  // namespace
}  // namespace coloc::ndt
