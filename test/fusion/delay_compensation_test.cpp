#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "drive.hpp"

namespace coloc::fusion {
namespace {

using namespace coloc::testing;

class DelayCompensation : public ::testing::TestWithParam<int> {};

TEST_P(DelayCompensation, LateMeasurementGivesTheSameEstimateAsOnTime) {
  const int late = GetParam();
  const Drive drive;
  Localizer on_time = startedLocalizer(), delayed = startedLocalizer();
  const int stamp_tick = 30, end_tick = stamp_tick + late + 10;
  for (int k = 1; k <= end_tick; ++k) {
    driveTick(on_time, drive, k);
    driveTick(delayed, drive, k);
    if (k == stamp_tick) { EXPECT_TRUE(on_time.feedPose("ndt", ndtPoseAt(drive, stamp_tick)).applied()); }
    if (k == stamp_tick + late) {
      const Verdict v = delayed.feedPose("ndt", ndtPoseAt(drive, stamp_tick));
      EXPECT_TRUE(v.applied()) << v.message();
    }
  }
  expectSameEstimate(on_time, delayed, 1e-9);
}

INSTANTIATE_TEST_SUITE_P(TicksLate, DelayCompensation, ::testing::Values(1, 2, 5, 17, 30, 46));

TEST(DelayCompensation, LateMeasurementMatchesOnTimeForTwistsToo) {
  const Drive drive;
  Localizer on_time = startedLocalizer(), delayed = startedLocalizer();
  for (int k = 1; k <= 40; ++k) {
    on_time.advanceTo(kStart + k * kTick);
    delayed.advanceTo(kStart + k * kTick);
    on_time.feedTwist("odom", twist(kStart + k * kTick, 8.0 + 0.01 * k, 0.2));
    if (k >= 8) delayed.feedTwist("odom", twist(kStart + (k - 7) * kTick, 8.0 + 0.01 * (k - 7), 0.2));
  }
  for (int k = 34; k <= 40; ++k) delayed.feedTwist("odom", twist(kStart + k * kTick, 8.0 + 0.01 * k, 0.2));
  for (int k = 41; k <= 45; ++k) {
    on_time.advanceTo(kStart + k * kTick);
    delayed.advanceTo(kStart + k * kTick);
  }
  expectSameEstimate(on_time, delayed, 1e-9);
}

TEST(DelayCompensation, DelayAtTheWindowEdgeIsAcceptedAndOneTickBeyondIsRejected) {
  const Drive drive;
  Localizer localizer = startedLocalizer();
  for (int k = 1; k <= 80; ++k) driveTick(localizer, drive, k);
  const int window = localizer.config().history_steps;
  const Stamp newest = kStart + 80 * kTick;
  const Verdict at_edge = localizer.feedPose("rsu", fix2d(newest - window * kTick, 0, 0, 1.0e3));
  EXPECT_TRUE(at_edge.applied()) << at_edge.message();
  // Half a tick further still rounds to the edge tick; one nanosecond more does not.
  EXPECT_TRUE(localizer.feedPose("rsu", fix2d(newest - window * kTick - kTick / 2, 0, 0, 1.0e3)).applied());
  const Verdict beyond_rounding = localizer.feedPose("rsu", fix2d(newest - window * kTick - kTick / 2 - 1, 0, 0, 1.0e3));
  EXPECT_EQ(beyond_rounding.reason, Reason::kTooOld) << beyond_rounding.message();
  const Verdict one_beyond = localizer.feedPose("rsu", fix2d(newest - (window + 1) * kTick, 0, 0, 1.0e3));
  EXPECT_EQ(one_beyond.reason, Reason::kTooOld);
  EXPECT_NE(one_beyond.message().find("history reaches back 1.000000000 s"), std::string::npos) << one_beyond.message();
  EXPECT_EQ(localizer.counters(*localizer.findSource("rsu")).too_old, 2u);
}

TEST(DelayCompensation, FixAtTheWindowEdgeIsAppliedInOneStepWithItsWholeInformation) {
  const Drive drive;
  Localizer localizer = startedLocalizer();
  for (int k = 1; k <= 60; ++k) driveTick(localizer, drive, k);
  EXPECT_TRUE(localizer.feedPose("ndt", ndtPoseAt(drive, 60 - 50)).applied());
  EXPECT_EQ(localizer.counters(*localizer.findSource("ndt")).smoothing_shortened, 1u);
}

TEST(DelayCompensation, OutOfOrderFixesGiveTheSameEstimateAsInOrder) {
  const Drive drive;
  Localizer in_order = startedLocalizer(), out_of_order = startedLocalizer(), on_time = startedLocalizer();
  for (int k = 1; k <= 70; ++k) {
    for (Localizer* l : {&in_order, &out_of_order, &on_time}) driveTick(*l, drive, k);
    if (k == 40 || k == 44) on_time.feedPose("rsu", rsuFixAt(drive, k));
    if (k == 50) {
      in_order.feedPose("rsu", rsuFixAt(drive, 40));
      in_order.feedPose("rsu", rsuFixAt(drive, 44));
      EXPECT_TRUE(out_of_order.feedPose("rsu", rsuFixAt(drive, 44)).applied());
      EXPECT_TRUE(out_of_order.feedPose("rsu", rsuFixAt(drive, 40)).applied());
    }
  }
  expectSameEstimate(in_order, out_of_order, 1e-9);
  expectSameEstimate(on_time, out_of_order, 1e-9);
}

TEST(DelayCompensation, BurstOfDelayedFixesGivesTheSameEstimateAsOnTimeDelivery) {
  const Drive drive;
  Localizer on_time = startedLocalizer(), burst = startedLocalizer();
  std::vector<int> fix_ticks;
  for (int k = 52; k <= 70; k += 2) fix_ticks.push_back(k);  // 10 Hz fixes held back by a stalled link
  for (int k = 1; k <= 90; ++k) {
    driveTick(on_time, drive, k);
    driveTick(burst, drive, k);
    if (std::find(fix_ticks.begin(), fix_ticks.end(), k) != fix_ticks.end()) on_time.feedPose("rsu", rsuFixAt(drive, k));
    if (k == 72) {
      for (int f : fix_ticks) EXPECT_TRUE(burst.feedPose("rsu", rsuFixAt(drive, f)).applied());
    }
  }
  expectSameEstimate(on_time, burst, 1e-9);
  // The burst overflowed the smoothing queue: the oldest fixes were folded, not dropped.
  EXPECT_GT(burst.counters(*burst.findSource("rsu")).smoothing_shortened, 0u);
  EXPECT_EQ(burst.counters(*burst.findSource("rsu")).applied, fix_ticks.size());
}

TEST(DelayCompensation, FixStampedAheadWithinToleranceWaitsForItsTickThenEqualsOnTime) {
  const Drive drive;
  Localizer early = startedLocalizer(), on_time = startedLocalizer();
  for (int k = 1; k <= 30; ++k) {
    driveTick(early, drive, k);
    driveTick(on_time, drive, k);
  }
  // Stamped 15 ms after the newest tick: nearest to the next tick, which does not exist yet.
  PoseMeasurement fix = rsuFixAt(drive, 31);
  fix.stamp -= 5'000'000;
  const Verdict v = early.feedPose("rsu", fix);
  EXPECT_EQ(v.outcome, Outcome::kPending) << v.message();
  EXPECT_EQ(early.counters(*early.findSource("rsu")).pending, 1u);
  for (int k = 31; k <= 40; ++k) {
    driveTick(early, drive, k);
    driveTick(on_time, drive, k);
    if (k == 31) on_time.feedPose("rsu", fix);
  }
  EXPECT_EQ(early.counters(*early.findSource("rsu")).pending, 0u);
  EXPECT_EQ(early.counters(*early.findSource("rsu")).applied, 1u);
  expectSameEstimate(early, on_time, 1e-9);
}

TEST(DelayCompensation, DelayedFixStillImprovesTheCurrentEstimate) {
  const Drive drive;
  Localizer with_fix = startedLocalizer(), without = startedLocalizer();
  for (int k = 1; k <= 60; ++k) {
    driveTick(with_fix, drive, k);
    driveTick(without, drive, k);
  }
  with_fix.feedPose("rsu", rsuFixAt(drive, 45));
  const Eigen::Vector3d truth = drive.truth(60);
  const Estimate a = *with_fix.estimate(), b = *without.estimate();
  const double error_with = (a.pose.position.head<2>() - truth.head<2>()).norm();
  const double error_without = (b.pose.position.head<2>() - truth.head<2>()).norm();
  EXPECT_LT(error_with, 0.6 * error_without);
  EXPECT_LT(a.state_covariance(0, 0), b.state_covariance(0, 0));
}

}  // namespace
}  // namespace coloc::fusion

namespace coloc::fusion {
namespace {

using namespace coloc::testing;

TEST(EstimateAt, PastStampGivesThatTicksStateAndLaterStampAPredictionWithoutChangingTheFilter) {
  const Drive drive;
  EkfConfig config = quietConfig();
  config.twist_smoothing_steps = 1;  // so that nothing fed after tick 20 lands on tick 20
  Localizer localizer = startedLocalizer(config);
  Vector6d at_20 = Vector6d::Zero();
  for (int k = 1; k <= 30; ++k) {
    driveTick(localizer, drive, k);
    if (k == 20) at_20 = localizer.estimate()->state;
  }
  const Snapshot before = snapshot(localizer);
  EXPECT_TRUE(localizer.estimateAt(kStart + 20 * kTick + 3'000'000)->state.isApprox(at_20, 1e-12));
  // 50 ms past the newest tick: the motion model carried forward from there.
  const Estimate now = *localizer.estimate();
  const Estimate ahead = *localizer.estimateAt(now.stamp + 50'000'000);
  const double heading = now.state[2] + now.state[3];
  EXPECT_NEAR(ahead.state[0], now.state[0] + now.state[4] * 0.05 * std::cos(heading), 1e-9);
  EXPECT_NEAR(ahead.state[1], now.state[1] + now.state[4] * 0.05 * std::sin(heading), 1e-9);
  EXPECT_GT(ahead.state_covariance(0, 0), now.state_covariance(0, 0));
  EXPECT_FALSE(localizer.estimateAt(kStart - kNanosPerSecond).has_value());
  EXPECT_TRUE(snapshot(localizer) == before);
}

// Uphill at 8 m/s on a 5 % slope, NDT's poses (height and pitch measured) arriving 0.2 s late: the
// height at now is the road's there, not the height 0.2 s ago (8 cm lower), as Autoware carries a late
// pose's height to now; between poses it keeps following the slope.
TEST(DelayCompensation, ALatePosesHeightIsCarriedToNowAlongTheSlope) {
  const Drive drive;
  Localizer localizer = startedLocalizer();
  const double pitch = -std::atan(0.05);  // nose up: uphill
  const auto heightAt = [&](int k) { return drive.speed * k * toSeconds(kTick) * std::sin(-pitch); };
  constexpr int kLate = 10;  // ticks: 0.2 s
  for (int k = 1; k <= 200; ++k) {
    driveTick(localizer, drive, k);
    if (k % 5 == 0 && k > kLate) {
      const int stamp = k - kLate;
      PoseMeasurement m = ndtPoseAt(drive, stamp);
      m.pose.position.z() = heightAt(stamp);
      m.pose.orientation = quaternionFromRollPitchYaw(0.0, pitch, drive.truth(stamp).z());
      m.covariance(2, 2) = 0.0225;
      m.covariance(3, 3) = m.covariance(4, 4) = 0.000625;
      ASSERT_TRUE(localizer.feedPose("ndt", m).applied());
    }
    if (k > 100) {
      const Estimate e = *localizer.estimate();
      EXPECT_NEAR(e.pose.position.z(), heightAt(k), 0.01) << "tick " << k;
    }
  }
}

// Where coloc differs from Autoware on purpose: the height's variance grows every tick (Autoware's
// grows only when a pose is used), so that a gap without poses is reported as the uncertainty it is.
TEST(DelayCompensation, TheHeightsVarianceGrowsEveryTickWhileNoPoseArrives) {
  const Drive drive;
  Localizer localizer = startedLocalizer();
  for (int k = 1; k <= 50; ++k) {
    driveTick(localizer, drive, k);
    if (k % 5 == 0) {
      PoseMeasurement m = ndtPoseAt(drive, k);
      m.covariance(2, 2) = 0.0225;
      m.covariance(3, 3) = m.covariance(4, 4) = 0.000625;
      ASSERT_TRUE(localizer.feedPose("ndt", m).applied());
    }
  }
  for (int k = 51; k <= 60; ++k) driveTick(localizer, drive, k);  // the last pose's smoothing steps end
  const double before = localizer.estimate()->pose_covariance(2, 2);
  for (int k = 61; k <= 150; ++k) driveTick(localizer, drive, k);  // 1.8 s without a pose
  const double q = localizer.config().z_filter_proc_dev * toSeconds(kTick);
  EXPECT_NEAR(localizer.estimate()->pose_covariance(2, 2) - before, 90 * q * q, 1e-9);
}

}  // namespace
}  // namespace coloc::fusion
