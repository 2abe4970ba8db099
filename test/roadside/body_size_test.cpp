// A vehicle's sides measured from the faces at its seen corner, and learned over its frames.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "coloc/core/error.hpp"
#include "coloc/roadside/body_size.hpp"

namespace coloc::roadside {
namespace {

// A box seen from the LiDAR at the origin: its corner at (20, 1), the length running away along +x,
// the width along +y; `points` returns on each face.
AlignedBox seenBox(double length_extent, double width_extent, int points) {
  AlignedBox box{};
  box.alignment_point = {20.0, 1.0};
  box.along = {1.0, 0.0};
  box.across = {0.0, 1.0};
  box.corner_seen = true;
  box.length_face_extent = length_extent;
  box.width_face_extent = width_extent;
  box.length_face_points = box.width_face_points = points;
  return box;
}

TEST(BodySize, AFaceMeasuresItsExtentHalfTheLastAzimuthStepAndTheFarCornersArcAndNothingWhereItsEndIsAtGrazingIncidence) {
  const double step = 0.2 * M_PI / 180.0;
  // The width face (along +y from (20, 1)) is seen nearly square on: its far end at (20, 2.8), 20.2 m away.
  const Eigen::Vector2d sides = measureBodySides(seenBox(4.5, 1.8, 10), Eigen::Vector2d::Zero(), step);
  const Eigen::Vector2d far_end(20.0, 2.8);
  const double cos_incidence = 20.0 / far_end.norm();
  // The far corner's arc (0.4 m) returns to 70 deg from its normal: seen at psi, to 70 deg - psi of it.
  const double arc_left = 0.4 * (1.0 - std::sin(70.0 * M_PI / 180.0 - std::acos(cos_incidence)));
  EXPECT_NEAR(sides.y(), 1.8 + 0.5 * far_end.norm() * step / cos_incidence + arc_left, 1e-12);
  // The length face runs along the line of sight: its far end at grazing incidence, not measured.
  EXPECT_LT(sides.x(), 0.0);
  // Too few returns, or no corner seen: nothing.
  EXPECT_LT(measureBodySides(seenBox(4.5, 1.8, 4), Eigen::Vector2d::Zero(), step).y(), 0.0);
  AlignedBox alone = seenBox(4.5, 1.8, 10);
  alone.corner_seen = false;
  EXPECT_LT(measureBodySides(alone, Eigen::Vector2d::Zero(), step).y(), 0.0);
}

TEST(BodySize, ASideMeasuredShorterThanTheCamsOverFiveFramesIsUsedAndTheOtherSideDoubted) {
  BodySizeLearner learner;
  for (double w : {1.70, 1.86, 1.75, 1.78}) learner.add({-1.0, w});
  EXPECT_EQ(learner.size(5.0, 2.2), Eigen::Vector2d(5.0, 2.2)) << "four frames are not enough";
  EXPECT_EQ(learner.doubt(5.0, 2.2), Eigen::Vector2d::Zero());
  learner.add({-1.0, 1.80});
  // The upper quantile of the measures: the frame that saw the face's end.
  EXPECT_DOUBLE_EQ(learner.size(5.0, 2.2).y(), 1.86);
  EXPECT_DOUBLE_EQ(learner.size(5.0, 2.2).x(), 5.0);
  // The length, not measured, is in doubt by as much as the width was overstated; the width by the tolerance.
  EXPECT_NEAR(learner.doubt(5.0, 2.2).x(), 0.34, 1e-12);
  EXPECT_NEAR(learner.doubt(5.0, 2.2).y(), 0.1, 1e-12);
  // Along the heading (here the y axis) half the length's doubt; across it half the width's.
  const Eigen::Matrix2d c = sizeCovariance(learner.doubt(5.0, 2.2), 0.5 * M_PI);
  EXPECT_NEAR(c(1, 1), 0.17 * 0.17, 1e-12);
  EXPECT_NEAR(c(0, 0), 0.05 * 0.05, 1e-12);
  EXPECT_NEAR(c(0, 1), 0.0, 1e-12);
}

TEST(BodySize, MeasuresWithinTheCamsRoundingOrLongerKeepTheCamsSize) {
  BodySizeLearner learner;
  for (double w : {1.62, 1.72, 1.74, 1.75}) learner.add({4.82, w});  // a 4.88 x 1.84 m body sent as 4.9 x 1.8, its ends short
  EXPECT_EQ(learner.size(4.9, 1.8), Eigen::Vector2d(4.9, 1.8));
  EXPECT_EQ(learner.doubt(4.9, 1.8), Eigen::Vector2d::Zero());
  // Non-finite or negative measures are skipped, not learned.
  BodySizeLearner skipped;
  for (int i = 0; i < 5; ++i) skipped.add({std::nan(""), -1.0});
  skipped.add({std::numeric_limits<double>::infinity(), 0.0});
  EXPECT_EQ(skipped.size(5.0, 2.2), Eigen::Vector2d(5.0, 2.2));
}

TEST(BodySize, OneFramesMeasureIsUsedWhereFarShorterThanTheCamsButNotSoShortItIsPartial) {
  BodySizeConfig off;
  off.frame_tolerance = 0.0;
  EXPECT_EQ(frameBodySize({-1.0, 1.85}, 5.0, 2.2, off), Eigen::Vector2d(5.0, 2.2)) << "off";
  const BodySizeConfig c;
  EXPECT_EQ(frameBodySize({-1.0, 1.85}, 5.0, 2.2, c), Eigen::Vector2d(5.0, 1.85)) << "on by default";
  EXPECT_EQ(frameBodySize({4.80, 2.0}, 5.0, 2.2, c), Eigen::Vector2d(5.0, 2.2)) << "within the frame's tolerance";
  EXPECT_EQ(frameBodySize({-1.0, 1.5}, 5.0, 2.2, c), Eigen::Vector2d(5.0, 2.2)) << "0.7 m short: a face not seen whole";
  // The width measured: the length kept is doubted by the width's excess.
  EXPECT_TRUE(sizeDoubt({5.0, 1.85}, 5.0, 2.2, 0.1).isApprox(Eigen::Vector2d(0.35, 0.1)));
  EXPECT_EQ(sizeDoubt({5.0, 2.2}, 5.0, 2.2, 0.1), Eigen::Vector2d::Zero());
}

TEST(BodySize, OneFrameFindingTheCamFarTooLargeDoubtsBothSidesUntilTheSideIsPlacedWithAMeasure) {
  // The width measured 0.36 m short of the CAM's and placed with the CAM's: both sides doubted by it.
  EXPECT_TRUE(frameDoubt({-1.0, 1.84}, {5.0, 2.2}, 5.0, 2.2).isApprox(Eigen::Vector2d(0.36, 0.36)));
  // Within the doubt's tolerance (a 1.84 m body sent as 1.8, its front measured short), or placed with
  // the station's measure already, or not seen whole: none.
  EXPECT_EQ(frameDoubt({-1.0, 1.62}, {4.9, 1.8}, 4.9, 1.8), Eigen::Vector2d::Zero());
  EXPECT_EQ(frameDoubt({-1.0, 1.84}, {5.0, 1.86}, 5.0, 2.2), Eigen::Vector2d::Zero());
  EXPECT_EQ(frameDoubt({-1.0, 1.5}, {5.0, 2.2}, 5.0, 2.2), Eigen::Vector2d::Zero());
}

TEST(BodySize, OnlyTheLatestMeasuresCount) {
  BodySizeConfig config;
  config.max_measures = 3;
  config.min_measures = 3;
  BodySizeLearner learner(config);
  for (int i = 0; i < 3; ++i) learner.add({-1.0, 2.2});  // another vehicle once behind the id, say
  for (int i = 0; i < 3; ++i) learner.add({-1.0, 1.85});
  EXPECT_DOUBLE_EQ(learner.size(5.0, 2.2).y(), 1.85);
}

TEST(BodySize, AConfigurationOutOfRangeIsRefusedNamingTheKey) {
  const auto refused = [](BodySizeConfig c, const std::string& key) {
    try {
      validate(c);
      ADD_FAILURE() << key << " out of range was taken";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  };
  BodySizeConfig c;
  EXPECT_NO_THROW(validate(c));
  c.min_measures = 0;
  refused(c, "min_measures");
  c = {};
  c.max_measures = 4;
  refused(c, "max_measures");
  c = {};
  c.quantile = std::nan("");
  refused(c, "quantile");
  c = {};
  c.tolerance = -0.1;
  refused(c, "tolerance");
  c = {};
  c.doubt_tolerance = std::numeric_limits<double>::infinity();
  refused(c, "doubt_tolerance");
  c = {};
  c.max_shortfall = 0.0;
  refused(c, "max_shortfall");
  c = {};
  c.max_incidence = M_PI;
  refused(c, "max_incidence");
  c = {};
  c.min_seen_height = -0.1;
  refused(c, "min_seen_height");
  c = {};
  c.end_clearance = std::nan("");
  refused(c, "end_clearance");
}

}  // namespace
}  // namespace coloc::roadside
