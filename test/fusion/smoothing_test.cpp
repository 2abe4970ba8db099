#include <gtest/gtest.h>

#include "coloc/core/error.hpp"
#include "drive.hpp"

namespace coloc::fusion {
namespace {

using namespace coloc::testing;

EkfConfig withPoseSmoothing(int steps) {
  EkfConfig c = quietConfig();
  c.pose_smoothing_steps = steps;
  c.max_pose_queue_size = steps;
  return c;
}

TEST(Smoothing, PoseOverFiveStepsEqualsOneUpdateWithTheSameInformation) {
  // All uses land on the measurement's own tick, so for the linear measurement model five updates
  // with 5R equal one with R once the five ticks have passed.
  const Drive drive;
  Localizer smoothed = startedLocalizer(withPoseSmoothing(5)), single = startedLocalizer(withPoseSmoothing(1));
  for (int k = 1; k <= 40; ++k) {
    driveTick(smoothed, drive, k);
    driveTick(single, drive, k);
    if (k == 20) {
      smoothed.feedPose("ndt", ndtPoseAt(drive, 18));
      single.feedPose("ndt", ndtPoseAt(drive, 18));
    }
  }
  expectSameEstimate(smoothed, single, 1e-9);
}

TEST(Smoothing, EstimateMovesGraduallyWhileAPoseIsBeingApplied) {
  const Drive drive;
  Localizer smoothed = startedLocalizer(withPoseSmoothing(5)), single = startedLocalizer(withPoseSmoothing(1));
  for (int k = 1; k <= 20; ++k) {
    driveTick(smoothed, drive, k);
    driveTick(single, drive, k);
  }
  PoseMeasurement jump = ndtPoseAt(drive, 20);
  jump.pose.position.x() += 0.3;
  smoothed.feedPose("ndt", jump);
  single.feedPose("ndt", jump);
  const double x_before = drive.truth(20).x();
  const double first_step = smoothed.estimate()->state[0] - x_before;
  const double full_step = single.estimate()->state[0] - x_before;
  EXPECT_GT(first_step, 0.0);
  // A fifth of the information: gain P / (P + 5R) instead of P / (P + R), here about 0.66 of the full step.
  EXPECT_LT(first_step, 0.8 * full_step);
}

TEST(Smoothing, ASourceRegisteredWithItsOwnStepsIsAppliedOverThemWhileTheOthersKeepTheConfigurations) {
  const Drive drive;
  // Five steps for every pose, but the "fix" source's whole: it must move the estimate as a filter
  // whose every pose is whole does, and NDT's must still come in gradually.
  Localizer mixed = startedLocalizer(withPoseSmoothing(5)), single = startedLocalizer(withPoseSmoothing(1));
  mixed.addPoseSource("fix", 1);
  single.addPoseSource("fix");
  EXPECT_EQ(mixed.addPoseSource("fix", 3), mixed.addPoseSource("fix"));  // registered again: as it was
  for (int k = 1; k <= 30; ++k) {
    driveTick(mixed, drive, k);
    driveTick(single, drive, k);
    if (k == 20) {
      PoseMeasurement jump = rsuFixAt(drive, 20);
      jump.pose.position.x() += 0.3;
      mixed.feedPose("fix", jump);
      single.feedPose("fix", jump);
      expectSameEstimate(mixed, single, 1e-12);  // whole at once, not a fifth
    }
  }
  expectSameEstimate(mixed, single, 1e-12);
  PoseMeasurement jump = ndtPoseAt(drive, 30);
  jump.pose.position.x() += 0.3;
  const double x_before = mixed.estimate()->state[0];
  mixed.feedPose("ndt", jump);
  single.feedPose("ndt", jump);
  const double first_step = mixed.estimate()->state[0] - x_before, full_step = single.estimate()->state[0] - x_before;
  EXPECT_GT(first_step, 0.0);
  EXPECT_LT(first_step, 0.8 * full_step);  // NDT's pose over the configuration's five steps
  EXPECT_THROW(mixed.addPoseSource("other", -1), Error);
}

TEST(Smoothing, QueueOverflowFoldsTheOldestPoseInsteadOfDroppingIt) {
  EkfConfig config = withPoseSmoothing(5);
  config.max_pose_queue_size = 5;
  const Drive drive;
  Localizer localizer = startedLocalizer(config), reference = startedLocalizer(withPoseSmoothing(1));
  for (int k = 1; k <= 40; ++k) {
    driveTick(localizer, drive, k);
    driveTick(reference, drive, k);
    if (k == 20)
      for (int j = 0; j < 7; ++j) {  // seven poses of one source within one tick: two more than the queue holds
        localizer.feedPose("ndt", ndtPoseAt(drive, 12 + j));
        reference.feedPose("ndt", ndtPoseAt(drive, 12 + j));
      }
  }
  EXPECT_EQ(localizer.counters(*localizer.findSource("ndt")).applied, 7u);
  EXPECT_EQ(localizer.counters(*localizer.findSource("ndt")).smoothing_shortened, 2u);
  expectSameEstimate(localizer, reference, 1e-9);
}

}  // namespace
}  // namespace coloc::fusion
