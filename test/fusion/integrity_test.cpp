// The filter's integrity: what makes it degraded or lost, what brings it back, and how its reported
// covariance covers a disagreement it cannot yet resolve.
#include <gtest/gtest.h>

#include "drive.hpp"

#include "coloc/fusion/localizer.hpp"
#include "measurements.hpp"
#include "motion_model.hpp"

namespace coloc::fusion {
namespace {

using testing::fix2d;
using testing::kStart;
using testing::kTick;
using testing::planarPose;
using testing::twist;

struct Drive {
  Localizer filter;
  SourceId odom, ndt, rsu;
  Stamp now = kStart;
  Drive() : odom(filter.addTwistSource("odom")), ndt(filter.addPoseSource("ndt")), rsu(filter.addPoseSource("/rsu/a/fix", 0, true)) {
    filter.initialize(planarPose(kStart, 0.0, 0.0, 0.0, 0.0225, 0.0001));
  }
  // 0.1 s standing still: odometry every tick, a map-matching pose at `ndt_y` every 0.1 s.
  void step(double ndt_y) {
    for (int k = 0; k < 5; ++k) {
      now += kTick;
      filter.feedTwist(odom, twist(now, 0.0, 0.0));
      filter.advanceTo(now);
    }
    filter.feedPose(ndt, planarPose(now, 0.0, ndt_y, 0.0));
  }
};

TEST(Integrity, AFilterThatAgreesWithItsSourcesIsLocalized) {
  Drive d;
  for (int i = 0; i < 10; ++i) {
    d.step(0.0);
    d.filter.feedPose(d.rsu, fix2d(d.now, 0.01, -0.01, 0.0002));
  }
  EXPECT_EQ(d.filter.integrity().state, LocalizationState::kLocalized);
  EXPECT_EQ(d.filter.estimate()->localization, LocalizationState::kLocalized);
}

TEST(Integrity, OneAnchorFarOffDegradesAndTheReportedCovarianceCoversIt) {
  Drive d;
  d.step(0.0);
  const double sd_before = std::sqrt(d.filter.estimate()->pose_covariance(1, 1));
  const Verdict v = d.filter.feedPose(d.rsu, fix2d(d.now, 0.0, 5.0, 0.0002));
  ASSERT_EQ(v.reason, Reason::kGated);
  EXPECT_EQ(d.filter.integrity().state, LocalizationState::kDegraded);
  EXPECT_NE(d.filter.integrity().reason.find("/rsu/a/fix"), std::string::npos) << d.filter.integrity().reason;
  const Estimate e = *d.filter.estimate();
  // 5 m of disagreement: the reported deviation across is at least that, the filter's own is not.
  EXPECT_LT(sd_before, 0.2);
  EXPECT_GE(std::sqrt(e.pose_covariance(1, 1)), 5.0);
  EXPECT_LT(std::sqrt(e.state_covariance(1, 1)), 0.2);
}

TEST(Integrity, AnchorsTellingTheSameStoryAgainMakeItLost) {
  Drive d;
  d.step(0.0);
  d.filter.feedPose(d.rsu, fix2d(d.now, 0.0, 5.0, 0.0002));
  d.step(0.0);  // the map matching keeps confirming the filter
  d.filter.feedPose(d.rsu, fix2d(d.now, 0.02, 5.03, 0.0002));
  EXPECT_EQ(d.filter.integrity().state, LocalizationState::kLost);
  EXPECT_EQ(d.filter.integrity().losses, 1u);
  EXPECT_GE(std::sqrt(d.filter.estimate()->pose_covariance(1, 1)), 5.0);
}

TEST(Integrity, AnchorsThatDisagreeWithEachOtherAreOutliersNotALoss) {
  Drive d;
  d.step(0.0);
  d.filter.feedPose(d.rsu, fix2d(d.now, 0.0, 5.0, 0.0002));
  d.step(0.0);
  d.filter.feedPose(d.rsu, fix2d(d.now, 0.0, -4.0, 0.0002));  // a different story: 9 m from the first
  EXPECT_EQ(d.filter.integrity().state, LocalizationState::kDegraded);
  // The other sources go on agreeing for longer than the anchor memory: the outliers no longer count.
  for (int i = 0; i < 25; ++i) d.step(0.0);
  EXPECT_EQ(d.filter.integrity().state, LocalizationState::kLocalized);
  EXPECT_LT(std::sqrt(d.filter.estimate()->pose_covariance(1, 1)), 0.2);
}

TEST(Integrity, AnAnchorAgreeingAgainEndsItsDisagreement) {
  Drive d;
  d.step(0.0);
  d.filter.feedPose(d.rsu, fix2d(d.now, 0.0, 5.0, 0.0002));
  ASSERT_EQ(d.filter.integrity().state, LocalizationState::kDegraded);
  d.step(0.0);
  EXPECT_EQ(d.filter.feedPose(d.rsu, fix2d(d.now, 0.0, 0.01, 0.0002)).outcome, Outcome::kApplied);
  EXPECT_EQ(d.filter.integrity().state, LocalizationState::kLocalized);
}

TEST(Integrity, DeadReckoningBeyondTheLimitDegradesUntilAPoseIsApplied) {
  Drive d;
  d.step(0.0);
  for (int k = 0; k < 200; ++k) {  // 4 s of odometry alone
    d.now += kTick;
    d.filter.feedTwist(d.odom, twist(d.now, 0.0, 0.0));
    d.filter.advanceTo(d.now);
  }
  EXPECT_EQ(d.filter.integrity().state, LocalizationState::kDegraded);
  EXPECT_NE(d.filter.integrity().reason.find("no pose applied"), std::string::npos) << d.filter.integrity().reason;
  d.step(0.0);
  EXPECT_EQ(d.filter.integrity().state, LocalizationState::kLocalized);
}

TEST(Integrity, AResetFilterIsInitialisingWithNoEstimate) {
  Drive d;
  d.step(0.0);
  d.filter.reset();
  EXPECT_FALSE(d.filter.initialized());
  EXPECT_FALSE(d.filter.estimate().has_value());
  EXPECT_EQ(d.filter.integrity().state, LocalizationState::kInitialising);
  EXPECT_EQ(d.filter.feedPose(d.rsu, fix2d(d.now, 0.0, 0.0, 0.0002)).reason, Reason::kNotInitialized);
}

}  // namespace
}  // namespace coloc::fusion

namespace coloc::fusion {
namespace {

TEST(Start, AStartWhileMovingTakesItsSpeedAndYawRateFromTheOdometry) {
  Localizer filter;
  const TwistMeasurement moving = testing::twist(testing::kStart, 12.5, 0.05, 0.04, 0.01);
  ASSERT_TRUE(filter.initialize(testing::planarPose(testing::kStart, 0.0, 0.0, 0.0), moving).applied());
  const Estimate e = *filter.estimate();
  EXPECT_EQ(e.state[kVx], 12.5);
  EXPECT_EQ(e.state[kWz], 0.05);
  EXPECT_EQ(e.state_covariance(kVx, kVx), 0.04);
  // A twist that does not measure speed leaves it unknown, as a start without one does.
  TwistMeasurement gyro = moving;
  gyro.covariance(0, 0) = kInfinity;
  ASSERT_TRUE(filter.initialize(testing::planarPose(testing::kStart, 0.0, 0.0, 0.0), gyro).applied());
  EXPECT_EQ(filter.estimate()->state[kVx], 0.0);
  EXPECT_EQ(filter.estimate()->state_covariance(kVx, kVx), EkfConfig().initial_vx_variance);
  EXPECT_EQ(filter.estimate()->state[kWz], 0.05);
}

}  // namespace
}  // namespace coloc::fusion

namespace coloc::fusion {
namespace {

// Map matching that holds the filter `off` metres to the side, fixes (variance `fix_var`) at the truth.
Localizer heldOff(double off, double fix_var, int fixes) {
  Localizer filter;
  const SourceId odom = filter.addTwistSource("odom"), ndt = filter.addPoseSource("ndt"), rsu = filter.addPoseSource("/rsu/a/fix", 0, true);
  filter.initialize(testing::planarPose(testing::kStart, 0.0, off, 0.0, 0.0225, 0.0001));
  Stamp now = testing::kStart;
  for (int i = 0; i < fixes && filter.integrity().state != LocalizationState::kLost; ++i) {
    for (int k = 0; k < 5; ++k) {
      now += testing::kTick;
      filter.feedTwist(odom, testing::twist(now, 0.0, 0.0));
      filter.advanceTo(now);
    }
    filter.feedPose(ndt, testing::planarPose(now, 0.0, off, 0.0, 0.0004));
    const Verdict v = filter.feedPose(rsu, testing::fix2d(now, 0.0, 0.0, fix_var));
    EXPECT_NE(v.reason, Reason::kGated) << "fix " << i;  // each just inside the gate
  }
  return filter;
}

TEST(Integrity, AnchorsAppliedButAMetreOffAgainAndAgainMakeItLost) {
  const Localizer filter = heldOff(1.2, 0.06, 12);
  EXPECT_EQ(filter.integrity().state, LocalizationState::kLost);
  EXPECT_NE(filter.integrity().reason.find("on average"), std::string::npos) << filter.integrity().reason;
}

TEST(Integrity, AMiscalibratedRsusSmallDisagreementDegradesButNeverMakesItLost) {
  // 25 cm off again and again, as an RSU whose survey is off tells it: the RSU may be the wrong one.
  Localizer filter = heldOff(0.25, 0.0004, 12);
  EXPECT_EQ(filter.integrity().state, LocalizationState::kDegraded);
  EXPECT_EQ(filter.integrity().losses, 0u);
  // The fixes pull the filter halfway (both sources 2 cm): each disagrees by about 12 cm, and the
  // reported deviation covers that.
  EXPECT_GE(std::sqrt(filter.estimate()->pose_covariance(1, 1)), 0.1);
}

}  // namespace
// The map's own error against the world is reported, never filtered: NDT's poses carry it whole and
// alike from scan to scan, so averaging them cannot remove it.
TEST(Integrity, TheMapsOwnErrorIsAddedToTheReportedCovarianceAndChangesNothingElse) {
  fusion::EkfConfig with = coloc::testing::quietConfig();
  with.map_error_sd = 0.05;
  fusion::Localizer plain = coloc::testing::startedLocalizer(), mapped = coloc::testing::startedLocalizer(with);
  const coloc::testing::Drive drive;
  for (int k = 1; k <= 100; ++k) {
    coloc::testing::driveTick(plain, drive, k);
    coloc::testing::driveTick(mapped, drive, k);
    if (k % 5 == 0) {
      plain.feedPose("ndt", coloc::testing::ndtPoseAt(drive, k));
      mapped.feedPose("ndt", coloc::testing::ndtPoseAt(drive, k));
    }
  }
  const fusion::Estimate a = *plain.estimate(), b = *mapped.estimate();
  EXPECT_EQ(a.state, b.state);
  EXPECT_EQ(a.state_covariance, b.state_covariance);
  EXPECT_DOUBLE_EQ(b.pose_covariance(0, 0), a.pose_covariance(0, 0) + 0.0025);
  EXPECT_DOUBLE_EQ(b.pose_covariance(1, 1), a.pose_covariance(1, 1) + 0.0025);
  EXPECT_DOUBLE_EQ(b.pose_covariance(0, 1), a.pose_covariance(0, 1));
  EXPECT_DOUBLE_EQ(b.pose_covariance(5, 5), a.pose_covariance(5, 5));
}

}  // namespace coloc::fusion
