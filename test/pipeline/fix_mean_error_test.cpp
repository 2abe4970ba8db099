// Through the pipeline: a car passes an RSU 8 m to its left, whose fixes are pulled 3 cm towards the
// RSU's side of the road, coming and going alike (a far car's fit drawn to the side it shows). A
// calibration by range that measured that mean in the vehicle's frame takes it off by the vehicle's
// heading, and the estimate sits on the track; without the mean, 3 cm to the RSU's side.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "coloc/pipeline/pipeline.hpp"
#include "measurements.hpp"
#include "one_rsu.hpp"

namespace coloc::pipeline {
namespace {

double meanLeftOfTrack(double left_mean) {
  using coloc::testing::kStart;
  using coloc::testing::kTick;
  const Eigen::Vector2d rsu(0.0, 8.0);
  rsu_client::RsuRegistry one = coloc::testing::oneRsu(rsu, 60.0);
  std::vector<rsu_client::RsuInfo> entries = one.rsus();
  entries[0].calibrated_variance = 0.0001;
  entries[0].calibrated_error_by_range = {{5.0, 0.01, 0.01, 0.0, left_mean}, {50.0, 0.01, 0.01, 0.0, left_mean}};
  Config config;
  config.rsu.checks.station_id = 1001;
  Pipeline pipe(config, PipelineOptions{std::nullopt, rsu_client::RsuRegistry(entries, one.placement()), false, {}, nullptr, nullptr});
  const fusion::SourceId odom = pipe.addTwistSource("odom");
  std::vector<fusion::Estimate> estimates;
  pipe.onEstimate([&](const fusion::Estimate& e) { estimates.push_back(e); });
  const auto truth = [&](Stamp t) { return Eigen::Vector2d(-40.0 + 10.0 * toSeconds(t - kStart), 0.0); };
  pipe.pushInitialPose(coloc::testing::planarPose(kStart, -40.0, 0.0, 0.0, 0.01, 0.001), kStart);
  for (Stamp t = kStart; t <= kStart + 8'000'000'000; t += kTick) {
    pipe.pushTwist(odom, coloc::testing::twist(t, 10.0, 0.0), t + 2'000'000);
    const int k = static_cast<int>((t - kStart) / kTick);
    if (k % 5 == 2) {
      const Eigen::Vector2d p = truth(t) + Eigen::Vector2d(0.0, 0.03) + 0.005 * Eigen::Vector2d(std::sin(k), std::cos(3 * k));
      pipe.pushFix({t, "rsu_a", p.x(), p.y(), std::nullopt, std::nullopt, 1001}, t + 60'000'000);
    }
    pipe.runUntil(t);
  }
  double sum = 0.0;
  int n = 0;
  for (const fusion::Estimate& e : estimates)
    if (e.stamp >= kStart + 2'000'000'000 && e.stamp <= kStart + 6'000'000'000) sum += e.pose.position.y(), ++n;
  return n ? sum / n : std::nan("");
}

TEST(FixMeanError, ACalibratedMeanInTheVehiclesFrameIsTakenOffEveryFixComingAndGoing) {
  EXPECT_NEAR(meanLeftOfTrack(0.0), 0.03, 0.005);   // no mean measured: the pull is followed
  EXPECT_NEAR(meanLeftOfTrack(0.03), 0.0, 0.005);   // taken off, before and after the RSU alike
}

}  // namespace
}  // namespace coloc::pipeline
