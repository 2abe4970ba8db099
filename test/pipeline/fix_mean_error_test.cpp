// Through the pipeline: a car passes an RSU 8 m to its left, whose fixes are pulled 3 cm towards the
// RSU's side of the road, coming and going alike (a far car's fit drawn to the side it shows). A
// calibration by range that measured that mean in the vehicle's frame takes it off by the vehicle's
// heading, and the estimate sits on the track; without the mean, 3 cm to the RSU's side.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "coloc/pipeline/pipeline.hpp"
#include "one_rsu.hpp"
#include "pass_by_rsu.hpp"

namespace coloc::pipeline {
namespace {

double meanLeftOfTrack(double left_mean) {
  const rsu_client::RsuRegistry one = coloc::testing::oneRsu(Eigen::Vector2d(0.0, 8.0), 60.0);
  std::vector<rsu_client::RsuInfo> entries = one.rsus();
  entries[0].calibrated_variance = 0.0001;
  entries[0].calibrated_error_by_range = {{5.0, 0.01, 0.01, 0.0, left_mean}, {50.0, 0.01, 0.01, 0.0, left_mean}};
  Config config;
  config.rsu.checks.station_id = 1001;
  return coloc::testing::meanLeftOfTrackPassingRsu(config, rsu_client::RsuRegistry(entries, one.placement()),
                                                   [](const Eigen::Vector2d& truth) -> Eigen::Vector2d { return truth + Eigen::Vector2d(0.0, 0.03); });
}

TEST(FixMeanError, ACalibratedMeanInTheVehiclesFrameIsTakenOffEveryFixComingAndGoing) {
  EXPECT_NEAR(meanLeftOfTrack(0.0), 0.03, 0.005);   // no mean measured: the pull is followed
  EXPECT_NEAR(meanLeftOfTrack(0.03), 0.0, 0.005);   // taken off, before and after the RSU alike
}

}  // namespace
}  // namespace coloc::pipeline
