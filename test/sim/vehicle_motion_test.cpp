#include <gtest/gtest.h>

#include <cmath>

#include "coloc/core/error.hpp"
#include "coloc/sim/vehicle_motion.hpp"

namespace coloc::sim {
namespace {

TEST(Route, StraightThenQuarterCircleEndsWhereGeometrySays) {
  const Route route({0, 0}, 0.0, {{100.0, 0.0}, {M_PI / 2 * 50.0, 1.0 / 50.0}});
  Eigen::Vector2d p;
  double yaw, k;
  route.at(100.0, p, yaw, k);
  EXPECT_NEAR(p.x(), 100.0, 1e-9);
  route.at(route.length(), p, yaw, k);
  EXPECT_NEAR(p.x(), 150.0, 1e-9);
  EXPECT_NEAR(p.y(), 50.0, 1e-9);
  EXPECT_NEAR(yaw, M_PI / 2, 1e-12);
}

TEST(Drive, SpeedAndYawRateAreConsistentWithThePath) {
  const Drive drive(Route({0, 0}, 0.3, {{60.0, 0.0}, {80.0, 0.01}, {60.0, -0.005}}), {10.0, 1.5});
  EXPECT_NEAR(drive.at(0.0).speed, 0.0, 1e-12);
  EXPECT_NEAR(drive.at(drive.duration()).speed, 0.0, 1e-9);
  EXPECT_NEAR(drive.at(drive.duration()).s, drive.route().length(), 1e-9);
  // Finite differences of the pose match the reported speed and yaw rate.
  for (double t = 1.0; t < drive.duration() - 1.0; t += 1.7) {
    const double h = 1e-4;
    const VehicleState a = drive.at(t - h), b = drive.at(t + h), m = drive.at(t);
    EXPECT_NEAR((b.position - a.position).norm() / (2 * h), m.speed, 1e-4);
    EXPECT_NEAR((b.yaw - a.yaw) / (2 * h), m.yaw_rate, 1e-4);
  }
}

TEST(Drive, ShortRouteRampsUpAndDownWithoutCruising) {
  const Drive drive(Route({0, 0}, 0.0, {{20.0, 0.0}}), {15.0, 1.5});
  EXPECT_NEAR(drive.at(drive.duration() / 2).speed, std::sqrt(1.5 * 20.0), 1e-9);
}

TEST(Odometry, NoiseAndBiasHaveTheConfiguredSize) {
  RandomEngine rng(2);
  VehicleState truth;
  truth.speed = 10.0;
  truth.yaw_rate = 0.1;
  double speed = 0.0, rate = 0.0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const OdometrySample s = measureOdometry(truth, {}, rng);
    speed += s.speed;
    rate += s.yaw_rate;
  }
  EXPECT_NEAR(speed / n, 10.1, 0.002);  // 1 % scale error
  EXPECT_NEAR(rate / n, 0.102, 0.0002);  // 0.002 rad/s bias
}

TEST(Route, BadPiecesAreErrors) {
  EXPECT_THROW(Route({0, 0}, 0.0, {}), Error);
  EXPECT_THROW(Route({0, 0}, 0.0, {{-1.0, 0.0}}), Error);
}

}  // namespace
}  // namespace coloc::sim
