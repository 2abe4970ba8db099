// Consistency over frames: a fix must agree with the RSU's track of the vehicle, carried by the CAM's velocity.
#include <gtest/gtest.h>

#include "coloc/roadside/fix_consistency.hpp"

namespace coloc::roadside {
namespace {

constexpr Stamp kFrame = 100'000'000;  // 10 Hz

TEST(FixConsistency, AFixIsConfirmedByTheTrackCarriedForwardByTheVelocity) {
  FixConsistency c(0.3);
  const Eigen::Vector2d v(10.0, 0.0);
  EXPECT_FALSE(c.agrees(0, {0.0, 0.0}, v));           // nothing to agree with yet
  EXPECT_TRUE(c.agrees(kFrame, {1.05, 0.02}, v));     // 1 m further, 5 cm of noise
  EXPECT_TRUE(c.agrees(2 * kFrame, {2.0, -0.05}, v));
}

TEST(FixConsistency, WrongFramesAreRefusedEvenWhenTheyAgreeAmongThemselvesAndTheTrackCarriesOnPastThem) {
  FixConsistency c(0.3);
  const Eigen::Vector2d v(10.0, 0.0);
  c.agrees(0, {0.0, 0.0}, v);
  EXPECT_TRUE(c.agrees(kFrame, {1.0, 0.0}, v));
  EXPECT_FALSE(c.agrees(2 * kFrame, {2.0, 0.7}, v));  // the wrong corner, 0.7 m across
  EXPECT_FALSE(c.agrees(3 * kFrame, {3.0, 0.7}, v));  // again: consistent with its predecessor, not with the track
  EXPECT_TRUE(c.agrees(4 * kFrame, {4.0, 0.02}, v));  // right again: the track, 0.3 s old, carried forward
}

TEST(FixConsistency, WithoutATrackTwoAgreeingFramesStartOne) {
  FixConsistency c(0.3, 0.5, 0.25);
  const Eigen::Vector2d v(10.0, 0.0);
  EXPECT_FALSE(c.agrees(0, {0.0, 0.0}, v));           // nothing to agree with
  EXPECT_TRUE(c.agrees(kFrame, {1.0, 0.0}, v));       // the pair starts the track
  EXPECT_FALSE(c.agrees(7 * kFrame, {7.0, 0.0}, v));  // 0.6 s later the track has lapsed, and no pair
  c.miss();
  EXPECT_FALSE(c.agrees(9 * kFrame, {9.0, 0.0}, v));  // its predecessor was a miss
  EXPECT_TRUE(c.agrees(10 * kFrame, {10.0, 0.0}, v));
}

TEST(FixConsistency, InABendTheMeanOfTheTwoVelocitiesCarriesTheFix) {
  FixConsistency c(0.05);
  c.agrees(0, {0.0, 0.0}, {10.0, 0.0});
  EXPECT_TRUE(c.agrees(kFrame, {0.5, 0.5}, {0.0, 10.0}));  // the heading turned 90 deg between the frames
}

}  // namespace
}  // namespace coloc::roadside
