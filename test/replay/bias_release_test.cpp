// The pipeline's release of NDT's followed bias before a roadside fix (ndt.quality_floor: noise with
// fusion.map_match_bias_sd): NDT's poses, taken at their place's noise, hold the filter tight on NDT's
// bias; the first fix that tells the bias apart must be able to move the position by it.
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "coloc/ndt/pcd_file.hpp"
#include "coloc/ndt/tile_map.hpp"
#include "coloc/pipeline/config.hpp"
#include "coloc/pipeline/ndt_quality_map.hpp"
#include "coloc/pipeline/pipeline.hpp"
#include "measurements.hpp"
#include "one_rsu.hpp"
#include "real_data.hpp"
#include "temp_dir.hpp"

namespace coloc::pipeline {
namespace {

using coloc::testing::kStart;

constexpr Duration kScanPeriod = 100'000'000;
constexpr int kScans = 10;


struct Drive {
  Eigen::Vector2d before_fix;  ///< the estimate at the fix's stamp, before the fix
  Eigen::Vector2d after_fix;   ///< the estimate at the fix's stamp, with it
  double variance_before = 0.0;
  std::uint64_t fixes_applied = 0;
};

// A standing vehicle: the pair's scan every 0.1 s for 1 s, twists at 50 Hz reading 0, then one fix
// `offset` from where NDT put the vehicle, arriving `delay` after its stamp. `bias_sd` is
// fusion.map_match_bias_sd (0: the bias is not modelled and nothing is released).
Drive standingDrive(const std::string& quality_map, double bias_sd, const Eigen::Vector2d& offset, Duration delay) {
  Config config = parseConfig(
      "pipeline:\n  initial_pose: [0.3, 0.3, 0.0, 0.0]\n  travel_check_window: 0\n  fix_agreement_window: 0\n"
      "ndt:\n  voxel_size: 1.0\n  covariance: fixed\n  fixed_covariance: [1e-9, 1e-9, 0.0225, 0.000625, 0.000625, 1e-9]\n"
      "  quality_map: " + quality_map + "\n  quality_floor: noise\n"
      "fusion:\n  map_match_bias_sd: " + std::to_string(bias_sd) + "\n",
      "test.yaml");
  config.rsu.checks.station_id = 1001;
  const Eigen::Vector2d here = testing::wherePairsScansMatch();
  Pipeline pipe(config, PipelineOptions{ndt::TileMap::open(testing::realData("hdl32e_pair/target.pcd"), config.ndt.map_tile_size),
                                        testing::oneRsu(here + Eigen::Vector2d(5.0, 0.0), 30.0, "rsu_a", rsu_client::CovariancePlacement::kStandardDeviation), false, {}, nullptr, nullptr});
  const fusion::SourceId odom = pipe.addTwistSource("odom");
  const ndt::PointCloud scan = ndt::loadPcd(testing::realData("hdl32e_pair/source.pcd"));
  for (int k = 0; k <= 5 * kScans; ++k) pipe.pushTwist(odom, testing::twist(kStart + k * 20'000'000, 0.0, 0.0, 0.0025, 2.5e-5), kStart + k * 20'000'000);
  for (int i = 0; i < kScans; ++i) pipe.pushScan(scan, kStart + i * kScanPeriod, kStart + i * kScanPeriod + 30'000'000);
  const Stamp fix_stamp = kStart + kScans * kScanPeriod - 50'000'000;
  pipe.runUntil(fix_stamp);
  Drive d;
  const fusion::Estimate before = *pipe.estimate();
  d.before_fix = before.pose.position.head<2>();
  d.variance_before = before.pose_covariance(0, 0);
  const Eigen::Vector2d at = d.before_fix + offset;
  pipe.pushFix({fix_stamp, "rsu_a", at.x(), at.y(), std::nullopt, std::nullopt, 1001u}, fix_stamp + delay);
  std::optional<fusion::Estimate> settled;
  pipe.onPoseSettled([&](const std::string& source, const fusion::Estimate& e) {
    if (source == "/rsu/rsu_a/fix") settled = e;
  });
  pipe.runUntil(kStart + (kScans + 3) * kScanPeriod);
  EXPECT_TRUE(settled.has_value()) << "the fix reached the filter";
  if (settled) d.after_fix = settled->pose.position.head<2>();
  for (const fusion::SourceReport& s : pipe.report().sources)
    if (s.name == "/rsu/rsu_a/fix") d.fixes_applied = s.counters.applied;
  return d;
}

// A quality map whose cell around the scans holds NDT 5 cm off on the reference drive with 2 mm of
// scan-to-scan noise: the bias's spread there is about 25 cm^2.
std::string qualityMap(const testing::TempDir& dir) {
  const Eigen::Vector2d here = testing::wherePairsScansMatch();
  std::vector<NdtQualitySample> samples;
  for (int i = 0; i < 10; ++i) {
    const double sign = i % 2 ? 1.0 : -1.0;
    samples.push_back({here + Eigen::Vector2d(0.3 * i - 1.5, 0.0), Eigen::Vector2d(0.05 + 0.002 * sign, 0.002 * sign), 0.0, 0.0005 * sign});
  }
  const std::string path = dir / "quality.yaml";
  std::ofstream(path) << NdtQualityMap::fromErrors(samples, 10.0, 5, 0.0).toYaml();
  return path;
}

TEST(BiasRelease, TheFirstFixAfterNdtsFollowedBiasMovesThePositionByMostOfItsDisagreement) {
  testing::TempDir dir;
  const std::string map = qualityMap(dir);
  const Eigen::Vector2d offset(0.03, -0.02);  // the fix 3.6 cm from where NDT holds the filter
  const Drive released = standingDrive(map, 0.1, offset, 0);
  ASSERT_EQ(released.fixes_applied, 1u);
  EXPECT_LT(released.variance_before, 1e-4) << "NDT at its place's noise held the filter within a centimetre";
  // The bias's spread (about 25 cm^2) against the fix's VLP-32C variance (0.46 cm^2, its published
  // figure as a standard deviation): the position goes to within a few percent of the fix.
  const double moved = (released.after_fix - released.before_fix).dot(offset) / offset.squaredNorm();
  EXPECT_GT(moved, 0.9) << "moved " << moved << " of the way to the fix";
  EXPECT_LT(moved, 1.0 + 1e-9);

  // With the bias not modelled, nothing is released: the same fix moves the held position by no more
  // than its variance's share against the fix's (a Kalman gain of 0.15 here).
  const Drive held = standingDrive(map, 0.0, offset, 0);
  ASSERT_EQ(held.fixes_applied, 1u);
  const double held_moved = (held.after_fix - held.before_fix).dot(offset) / offset.squaredNorm();
  const double fix_variance = 0.00681 * 0.00681;
  EXPECT_LT(held_moved, held.variance_before / (held.variance_before + fix_variance) + 0.01) << "held moved " << held_moved;
}

TEST(BiasRelease, AReleaseBeforeALateFixGivesTheSameEstimateAsBeforeAnOnTimeOne) {
  // The release is kept with the fix's tick: a fix 150 ms late lets the bias in where it was measured.
  testing::TempDir dir;
  const std::string map = qualityMap(dir);
  const Drive on_time = standingDrive(map, 0.1, Eigen::Vector2d(0.03, -0.02), 0);
  const Drive late = standingDrive(map, 0.1, Eigen::Vector2d(0.03, -0.02), 150'000'000);
  ASSERT_EQ(late.fixes_applied, 1u);
  const Eigen::Vector2d offset(0.03, -0.02);
  EXPECT_GT((late.after_fix - late.before_fix).dot(offset) / offset.squaredNorm(), 0.9) << "released although late";
  EXPECT_NEAR((on_time.after_fix - late.after_fix).norm(), 0.0, 1e-9);
}

}  // namespace
}  // namespace coloc::pipeline
