// A fix placed with the CAM's rounded size is moved back to the body's own centre, on the side and end
// the RSU sees; abeam, the end is not guessed.
#include "coloc/pipeline/cam_size_correction.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "coloc/pipeline/pipeline.hpp"
#include "measurements.hpp"
#include "one_rsu.hpp"
#include "pass_by_rsu.hpp"

namespace coloc::pipeline {
namespace {

constexpr double kLength = 4.88, kWidth = 1.84;  // sent as 4.9 x 1.8

// Where an RSU at `rsu` places the centre of a car at `centre` heading `yaw`: the corner it sees
// (the end towards it, the side towards it) plus half the CAM's length and width back from it.
Eigen::Vector2d boxCentre(const Eigen::Vector2d& centre, double yaw, const Eigen::Vector2d& rsu) {
  const Eigen::Rotation2Dd body(yaw);
  const Eigen::Vector2d seen_from = body.inverse() * (rsu - centre);
  const double sa = seen_from.x() > 0.0 ? 1.0 : -1.0, sc = seen_from.y() > 0.0 ? 1.0 : -1.0;
  const Eigen::Vector2d corner = centre + body * Eigen::Vector2d(sa * kLength / 2.0, sc * kWidth / 2.0);
  return corner - body * Eigen::Vector2d(sa * 4.9 / 2.0, sc * 1.8 / 2.0);
}

TEST(CamSizeCorrection, AFixPlacedWithTheCamsRoundedSizeIsMovedBackToTheBodysCentre) {
  const CamSizeCorrection correction{kLength, kWidth, 0.1};
  const Eigen::Vector2d centre(100.0, 50.0);
  for (double yaw : {0.0, 0.7, 2.5, -1.9})
    for (const Eigen::Vector2d& offset : {Eigen::Vector2d(20.0, 4.0), Eigen::Vector2d(-25.0, 3.0), Eigen::Vector2d(15.0, -6.0), Eigen::Vector2d(-30.0, -3.5)}) {
      const Eigen::Vector2d rsu = centre + Eigen::Rotation2Dd(yaw) * offset;
      const Eigen::Vector2d fix = boxCentre(centre, yaw, rsu);
      ASSERT_NEAR((fix - centre).norm(), std::hypot(0.01, 0.02), 1e-9);  // the bias: 1 cm along, 2 across
      EXPECT_NEAR((correction.apply(fix, rsu, yaw) - centre).norm(), 0.0, 1e-9) << "yaw " << yaw << ", RSU at " << offset.transpose();
    }
}

TEST(CamSizeCorrection, AbeamOfTheRsuOnlyTheSideIsCorrected) {
  const CamSizeCorrection correction{kLength, kWidth, 0.1};
  const Eigen::Vector2d centre(0.0, 0.0), rsu(1.0, 6.0);  // within half the body's length along it
  const Eigen::Vector2d fix = centre + Eigen::Vector2d(0.01, -0.02 * -1.0);  // placed 2 cm towards the RSU's side, 1 cm along
  const Eigen::Vector2d corrected = correction.apply(fix, rsu, 0.0);
  EXPECT_NEAR(corrected.y(), 0.0, 1e-12);
  EXPECT_NEAR(corrected.x(), 0.01, 1e-12);
}

TEST(CamSizeCorrection, WithoutTheVehiclesSizeOrWithNonFiniteInputTheFixIsTakenAsSent) {
  const Eigen::Vector2d fix(3.0, 4.0), rsu(20.0, 5.0);
  EXPECT_EQ(CamSizeCorrection{}.apply(fix, rsu, 0.3), fix);
  const CamSizeCorrection correction{kLength, kWidth, 0.1};
  EXPECT_EQ(correction.apply(fix, rsu, std::nan("")), fix);
  EXPECT_EQ(correction.apply(fix, Eigen::Vector2d(std::nan(""), 0.0), 0.3), fix);
  // A size the CAM sends exactly needs nothing.
  const CamSizeCorrection exact{4.9, 1.8, 0.1};
  EXPECT_NEAR((exact.apply(fix, rsu, 0.3) - fix).norm(), 0.0, 1e-12);
}

TEST(CamSizeCorrection, AV2xStackThatRoundsDownIsTakenAtWhatItSends) {
  // The stack sends 4.8 x 1.8 (down, not to the nearest): the box sits 4 cm towards the end seen.
  const Eigen::Vector2d centre(0.0, 0.0), rsu(20.0, 6.0);
  const Eigen::Vector2d fix = centre + Eigen::Vector2d(0.5 * (kLength - 4.8), 0.5 * (kWidth - 1.8));
  CamSizeCorrection nearest{kLength, kWidth, 0.1};
  EXPECT_GT((nearest.apply(fix, rsu, 0.0) - centre).norm(), 0.04);
  CamSizeCorrection told = nearest;
  told.sent_length = 4.8;
  told.sent_width = 1.8;
  EXPECT_NEAR((told.apply(fix, rsu, 0.0) - centre).norm(), 0.0, 1e-12);
}

// Through the pipeline: a car of 4.88 x 1.84 m passes an RSU 8 m to its left, whose fixes place it with
// its CAM's 4.9 x 1.8 (2 cm towards the RSU on every fix, 1 cm along). Given its own size, the vehicle's
// estimate sits on its track; without it, 2 cm to the RSU's side.
double meanLeftOfTrack(const Config& config) {
  const Eigen::Vector2d rsu(0.0, 8.0);
  return coloc::testing::meanLeftOfTrackPassingRsu(config, coloc::testing::oneRsu(rsu, 60.0),
                                                   [&](const Eigen::Vector2d& truth) -> Eigen::Vector2d { return boxCentre(truth, 0.0, rsu); });
}

TEST(CamSizeCorrection, AVehicleGivenItsOwnSizeIsNotPulledTowardsTheRsuByItsCamsRounding) {
  Config config;
  config.rsu.checks.station_id = 1001;
  EXPECT_NEAR(meanLeftOfTrack(config), 0.02, 0.005);  // as sent: the half of 4 cm towards the RSU
  config.rsu.vehicle_length = kLength;
  config.rsu.vehicle_width = kWidth;
  EXPECT_NEAR(meanLeftOfTrack(config), 0.0, 0.005);
}

}  // namespace
}  // namespace coloc::pipeline
