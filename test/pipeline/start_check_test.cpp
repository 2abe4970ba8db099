// A pose given by hand is held against the map before the filter says it is localized: where the map
// cannot tell the place from another one (a street alike along its length) the filter stays degraded,
// its reported covariance covering the other place, until the roadside agrees with it or brings it back.
#include <gtest/gtest.h>

#include <cmath>

#include "coloc/pipeline/pipeline.hpp"
#include "measurements.hpp"
#include "one_rsu.hpp"

namespace coloc::pipeline {
namespace {

using coloc::testing::kStart;
using coloc::testing::kTick;
using coloc::testing::planarPose;
using coloc::testing::twist;

constexpr double kPeriod = 6.0;       // m between the street's posts
constexpr double kLidarHeight = 1.8;  // m above the road
constexpr std::uint32_t kEgo = 1001;

// A straight street along x: the road, two facades and a post every kPeriod on each side. With
// `landmark`, a kiosk at one place only, which tells that place from the others.
ndt::PointCloud street(bool landmark) {
  ndt::PointCloud map;
  for (double x = -90.0; x <= 90.0; x += 0.5) {
    for (double y = -8.0; y <= 8.0; y += 0.5) map.points.emplace_back(x, y, 0.0);
    for (double z = 0.5; z <= 6.0; z += 0.5) {
      map.points.emplace_back(x, -8.0, z);
      map.points.emplace_back(x, 8.0, z);
    }
  }
  for (double x = -90.0; x <= 90.0; x += kPeriod)
    for (double z = 0.5; z <= 4.0; z += 0.5)
      for (int k = 0; k < 4; ++k) {
        const double a = M_PI * k / 2.0;
        map.points.emplace_back(x + 0.15 * std::cos(a), -6.0 + 0.15 * std::sin(a), z);
        map.points.emplace_back(x + 0.15 * std::cos(a), 6.0 + 0.15 * std::sin(a), z);
      }
  // NVTL skips points with no voxel near them, so what tells places apart is structure that lands on
  // the wrong voxels when moved: a low, wide planter on the pavement, whose points fall on the road's
  // voxels a post away.
  if (landmark)
    for (double x = 4.0; x <= 16.0; x += 0.25)
      for (double y = 1.0; y <= 6.0; y += 0.25)
        for (double z = 0.2; z <= 0.8; z += 0.2)
          if (x < 4.1 || x > 15.9 || y < 1.1 || y > 5.9 || z > 0.7) map.points.emplace_back(x, y, z);
  return map;
}

// What the vehicle's LiDAR sees standing at the origin, heading along x: the map within 40 m.
ndt::PointCloud scanAtOrigin(const ndt::PointCloud& map) {
  ndt::PointCloud scan;
  for (const Eigen::Vector3f& p : map.points)
    if (p.head<2>().norm() <= 40.0) scan.points.emplace_back(p.x(), p.y(), p.z() - static_cast<float>(kLidarHeight));
  return scan;
}

Config configFor() {
  Config c;
  c.rsu.checks.station_id = kEgo;
  c.ndt.source.lidar_pose << 0.0, 0.0, kLidarHeight, 0.0, 0.0, 0.0;
  c.ndt.lidar_pose_given = true;
  c.ndt.source.preprocess.deskew = false;
  return c;
}

struct Standing {
  ndt::PointCloud map;
  Pipeline pipe;
  fusion::SourceId odom;
  std::vector<fusion::Estimate> estimates;
  ndt::PointCloud scan;
  explicit Standing(bool landmark)
      : map(street(landmark)),
        pipe(configFor(), PipelineOptions{ndt::TileMap::fromCloud(map, 20.0), coloc::testing::oneRsu({0.0, 20.0}, 80.0), false, {}, nullptr, nullptr}),
        scan(scanAtOrigin(map)) {
    odom = pipe.addTwistSource("odom");
    pipe.onEstimate([this](const fusion::Estimate& e) { estimates.push_back(e); });
  }
  /// The vehicle stands at the origin: odometry at 50 Hz, scans at 10 Hz and, from `fixes_from`, the
  /// RSU's fixes at the truth (2 cm off) at 10 Hz.
  void run(Stamp from, Stamp to, Stamp fixes_from) {
    for (Stamp t = from; t <= to; t += kTick) {
      pipe.pushTwist(odom, twist(t, 0.0, 0.0), t + 2'000'000);
      const int k = static_cast<int>((t - kStart) / kTick);
      if (k % 5 == 0) pipe.pushScan(scan, t, t + 10'000'000);
      if (k % 5 == 2 && t >= fixes_from) pipe.pushFix({t, "rsu_a", 0.02 * std::sin(k), 0.02 * std::cos(k), std::nullopt, std::nullopt, kEgo}, t + 60'000'000);
      pipe.runUntil(t);
    }
  }
  const fusion::Estimate& last() const { return estimates.back(); }
};

double sdAlong(const fusion::Estimate& e) { return std::sqrt(e.pose_covariance(0, 0)); }

class HandStartInARepeatingStreet : public ::testing::TestWithParam<double> {};

TEST_P(HandStartInARepeatingStreet, IsNotLocalizedUntilTheRoadsideAgreesAndIsBroughtBackByIt) {
  const double ahead = GetParam();  // m: 0 = the true pose, kPeriod = one post ahead
  Standing car(false);
  car.pipe.pushInitialPose(planarPose(kStart, ahead, 0.0, 0.0, 0.25, 0.01), kStart);
  const Stamp fixes_from = kStart + 4'000'000'000;
  car.run(kStart, fixes_from - kTick, fixes_from);
  ASSERT_FALSE(car.estimates.empty());
  // Before any fix: degraded, however well NDT matches where the person put it, the map's doubt as
  // the reason, and a reported covariance that covers the error.
  const fusion::Estimate before = car.last();
  const std::string reason = car.pipe.report().state_reason;
  EXPECT_EQ(before.localization, fusion::LocalizationState::kDegraded) << reason;
  EXPECT_NE(reason.find("NDT matches the map"), std::string::npos) << reason;
  EXPECT_GE(3.0 * sdAlong(before), std::abs(before.pose.position.x()) - 0.1) << reason;
  for (const fusion::Estimate& e : car.estimates) EXPECT_NE(e.localization, fusion::LocalizationState::kLocalized) << toSeconds(e.stamp - kStart);
  // The roadside settles it: localized at the truth.
  car.run(fixes_from, fixes_from + 3'000'000'000, fixes_from);
  EXPECT_EQ(car.last().localization, fusion::LocalizationState::kLocalized) << car.pipe.report().state_reason;
  EXPECT_LT(car.last().pose.position.head<2>().norm(), 0.1);
  EXPECT_EQ(car.pipe.report().recoveries, ahead == 0.0 ? 0u : 1u);
}

INSTANTIATE_TEST_SUITE_P(TrueAndOnePostAhead, HandStartInARepeatingStreet, ::testing::Values(0.0, kPeriod));

TEST(HandStartCheck, AStartThatTheMapTellsFromEveryOtherPlaceIsLocalizedAtTheFirstScan) {
  Standing car(true);
  car.pipe.pushInitialPose(planarPose(kStart, 0.0, 0.0, 0.0, 0.25, 0.01), kStart);
  // Until the first scan has been held against the map, the person's word is all there is.
  car.run(kStart, kStart, kStart + 100'000'000'000);
  ASSERT_FALSE(car.estimates.empty());
  EXPECT_EQ(car.estimates.front().localization, fusion::LocalizationState::kDegraded);
  car.run(kStart + kTick, kStart + 2'000'000'000, kStart + 100'000'000'000);
  EXPECT_EQ(car.last().localization, fusion::LocalizationState::kLocalized) << car.pipe.report().state_reason;
  EXPECT_GE(car.pipe.report().start_checks, 1u);
  EXPECT_LT(sdAlong(car.last()), 0.5);
}

}  // namespace
}  // namespace coloc::pipeline
