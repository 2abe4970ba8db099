#include <gtest/gtest.h>

#include <cmath>

#include "drive.hpp"

namespace coloc::fusion {
namespace {

using namespace coloc::testing;

// The true planar position `offset` seconds after tick k on the test drive's circle.
Eigen::Vector2d truthAfterTick(const Drive& d, int k, double offset) {
  const double t = k * toSeconds(kTick) + offset, yaw0 = 0.3, r = d.speed / d.yaw_rate;
  const double yaw = yaw0 + d.yaw_rate * t;
  return {r * (std::sin(yaw) - std::sin(yaw0)), -r * (std::cos(yaw) - std::cos(yaw0))};
}

// Precise fixes stamped 8 ms after every `every`-th tick up to tick `until` (a sensor out of step with
// the filter), each delivered `late` ticks after its stamp; returns the position error at tick `ticks`.
double offTickFixes(bool align, int late, int every, int until, int ticks, Eigen::Vector2d* final_position = nullptr) {
  EkfConfig config = quietConfig();
  config.pose_time_alignment = align;
  Localizer localizer = startedLocalizer(config);
  const Drive drive;
  constexpr double kOffset = 0.008;
  std::vector<std::pair<int, PoseMeasurement>> due;  // (tick to deliver at, fix)
  for (int k = 1; k <= ticks; ++k) {
    driveTick(localizer, drive, k);
    if (k % every == 0 && k <= until) {
      const Eigen::Vector2d p = truthAfterTick(drive, k, kOffset);
      due.push_back({k + 1 + late, fix2d(kStart + k * kTick + fromSeconds(kOffset), p.x(), p.y(), 1e-4)});
    }
    for (auto& [at, fix] : due)
      if (at == k) { EXPECT_TRUE(localizer.feedPose("rsu", fix).applied()); }
  }
  const Estimate e = *localizer.estimate();
  if (final_position) *final_position = e.state.head<2>();
  return (e.state.head<2>() - drive.truth(ticks).head<2>()).norm();
}

TEST(TimeAlignment, APoseStampedBetweenTicksIsCarriedToItsTick) {
  // 8 m/s x 8 ms = 6.4 cm along the track, every time: Autoware's rounding leaves that as a bias.
  // Error one tick after the last of 40 fixes (the odometry is 1 % off, so dead reckoning adds a little).
  const double aligned = offTickFixes(true, 0, 5, 200, 201), rounded = offTickFixes(false, 0, 5, 200, 201);
  EXPECT_LT(aligned, 0.015);
  EXPECT_GT(rounded, 0.04);
  EXPECT_LT(aligned, 0.3 * rounded) << "aligned " << aligned << " rounded " << rounded;
}

TEST(TimeAlignment, LateEqualsOnTimeWithOffTickStamps) {
  // One off-tick fix at tick 100, delivered at once or 7 ticks late: the same estimate at tick 150.
  Eigen::Vector2d on_time, late;
  offTickFixes(true, 0, 100, 100, 150, &on_time);
  offTickFixes(true, 7, 100, 100, 150, &late);
  EXPECT_NEAR((on_time - late).norm(), 0.0, 1e-9);
}

}  // namespace
}  // namespace coloc::fusion
