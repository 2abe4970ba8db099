// NDT's travel held against the odometry's: a pose is widened by how far its travel over the last
// second disagrees beyond the tolerance, and not by one bad match at a chord's other end.
#include "travel_check.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

namespace coloc::pipeline {
namespace {

constexpr Stamp kStart = 1'700'000'000'000'000'000LL;

Stamp at(double t) { return kStart + static_cast<Stamp>(std::llround(t * 1e9)); }

// A drive at `speed` along a heading of 30 deg: odometry at 50 Hz with 5 cm/s of white noise, NDT
// poses at 10 Hz with 1 cm of noise plus `slide(t)` along the road. Returns each pose's excess.
template <typename Slide>
std::vector<std::optional<Eigen::Vector2d>> drive(double speed, double seconds, Slide slide, TravelCheckConfig config = {}) {
  TravelCheck check(config);
  std::mt19937 rng(7);
  std::normal_distribution<double> odometry_noise(0.0, 0.05), pose_noise(0.0, 0.01);
  const double heading = 30.0 * M_PI / 180.0;
  const Eigen::Vector2d along(std::cos(heading), std::sin(heading));
  std::vector<std::optional<Eigen::Vector2d>> out;
  for (int k = 0; k * 0.02 <= seconds; ++k) {
    const double t = k * 0.02;
    check.addSpeed(at(t), speed + odometry_noise(rng));
    if (k % 5 == 0 && t >= 0.1) {
      const double taken = t - 0.1;  // matched a sweep after its stamp
      const Eigen::Vector2d p = (speed * taken + slide(taken)) * along + Eigen::Vector2d(pose_noise(rng), pose_noise(rng));
      out.push_back(check.check(at(taken), p, heading));
    }
  }
  return out;
}

TEST(TravelCheck, APoseWithNothingToCompareYetIsUnverified) {
  const auto excess = drive(10.0, 3.0, [](double) { return 0.0; });
  ASSERT_GT(excess.size(), 20u);
  // Chords start at poses one to two windows (0.5 s) old, at least two of them: the first six poses
  // have fewer.
  for (int i = 0; i < 6; ++i) EXPECT_FALSE(excess[i].has_value()) << i;
  for (std::size_t i = 6; i < excess.size(); ++i) EXPECT_TRUE(excess[i].has_value()) << i;
}

// A LiDAR at 1 Hz (or an NDT that drops scans it cannot keep up with) has no two poses 0.5-1 s back:
// the window widens to two of its intervals, and its poses are verified and held as at 10 Hz.
TEST(TravelCheck, ASlowPoseStreamIsVerifiedOverAWindowOfItsOwnPace) {
  TravelCheck check;
  const Eigen::Vector2d along(1.0, 0.0);
  std::vector<std::optional<Eigen::Vector2d>> excess;
  for (int k = 0; k * 0.02 <= 20.0; ++k) {
    const double t = k * 0.02;
    check.addSpeed(at(t), 10.0);
    if (k % 50 == 0) {
      const double slide = t >= 15.0 ? 0.5 : 0.0;  // from 15 s on NDT is half a metre ahead
      excess.push_back(check.check(at(t), (10.0 * t + slide) * along, 0.0));
    }
  }
  ASSERT_EQ(excess.size(), 21u);
  EXPECT_EQ(check.window(), at(2.0) - at(0.0));
  // Verified once two intervals' worth of poses are one to two windows old (from the fifth pose on).
  for (int i = 0; i < 4; ++i) EXPECT_FALSE(excess[i].has_value()) << i;
  for (int i = 5; i < 15; ++i) {
    ASSERT_TRUE(excess[i].has_value()) << i;
    EXPECT_EQ(excess[i]->norm(), 0.0) << i;
  }
  // The slide is seen at once, by its excess beyond the tolerance (3 cm + 0.5 % of a 20-40 m chord).
  ASSERT_TRUE(excess[15].has_value());
  EXPECT_NEAR(excess[15]->norm(), 0.5 - 0.03 - 0.005 * 30.0, 0.06);
}

TEST(TravelCheck, NdtThatTravelsWithTheOdometryIsAlmostNeverWidened) {
  // NDT's 1 cm at both ends and the odometry's 5 cm/s over the chord are within the 3 cm tolerance
  // but for a rare draw, and then by millimetres.
  for (const double speed : {0.0, 2.0, 10.0, 20.0}) {
    const auto excess = drive(speed, 30.0, [](double) { return 0.0; });
    int widened = 0, compared = 0;
    for (const auto& e : excess)
      if (e) {
        ++compared;
        widened += e->norm() > 0.0;
        EXPECT_LT(e->norm(), 0.01) << speed << " m/s";
      }
    EXPECT_LT(widened, compared / 20) << speed << " m/s";
  }
}

TEST(TravelCheck, NdtSlidingAlongTheRoadIsWidenedByItsSlideBeyondTheTolerance) {
  // From 3 s on NDT slides ahead at 0.5 m/s (a scene alike along the road, a map out of date): over
  // a chord of 0.5-1 s at 10 m/s that is 25-50 cm where the tolerance is 3 + 0.5 % of 5-10 m.
  const auto excess = drive(10.0, 6.0, [](double t) { return t > 3.0 ? 0.5 * (t - 3.0) : 0.0; });
  const double heading = 30.0 * M_PI / 180.0;
  const Eigen::Vector2d along(std::cos(heading), std::sin(heading));
  int widened = 0;
  for (std::size_t i = 40; i < excess.size(); ++i) {  // from 4 s: the whole chord span slides
    ASSERT_TRUE(excess[i].has_value());
    const double norm = excess[i]->norm();
    // The median chord is 0.75 s: 37.5 cm of slide, less the tolerance of 3 + 3.75 cm.
    EXPECT_NEAR(norm, 0.375 - 0.0675, 0.04) << i;
    EXPECT_GT(std::abs(excess[i]->dot(along)), 0.99 * norm) << "widened along the slide";
    widened += norm > 0.0;
  }
  EXPECT_GT(widened, 15);
}

// A corner at speed: 15 m/s round a 12 m radius (72 deg/s). A chord of 0.5-1 s turns 36-72 deg and is
// 2-7 % shorter than the arc the odometry measured; NDT following the road exactly is not widened.
TEST(TravelCheck, ACornerTakenAtSpeedIsNotTakenForADisagreement) {
  TravelCheck check;
  const double speed = 15.0, radius = 12.0, rate = speed / radius;
  std::vector<std::optional<Eigen::Vector2d>> excess;
  for (int k = 0; k * 0.02 <= 3.0; ++k) {
    const double t = k * 0.02;
    check.addSpeed(at(t), speed);
    if (k % 5 == 0) {
      const double yaw = rate * t;
      excess.push_back(check.check(at(t), radius * Eigen::Vector2d(std::sin(yaw), 1.0 - std::cos(yaw)), yaw));
    }
  }
  int compared = 0;
  for (const auto& e : excess) {
    if (!e) continue;
    ++compared;
    EXPECT_LT(e->norm(), 1e-3);
  }
  EXPECT_GT(compared, 15);
}

// Into a corner from a straight: the turn is not spread evenly over a chord that starts on the
// straight, and its chord does not lie along its mean heading (15 m/s, the yaw rate rising over 0.3 s
// from 1 s on to a 12 m radius's 72 deg/s). With the odometry's yaw rate the check follows its path,
// its gyro's bias (0.02 rad/s) taken out by NDT's headings at the chord's ends; without it, it takes
// NDT following the road exactly for a disagreement of a metre.
TEST(TravelCheck, ACornerEnteredFromAStraightIsFollowedByTheOdometrysYawRate) {
  const double speed = 15.0, rate = speed / 12.0, entry = 1.0, gyro_bias = 0.02;
  const auto yawRate = [&](double t) { return rate * std::clamp((t - entry) / 0.3, 0.0, 1.0); };
  for (const bool yaw_rates : {true, false}) {
    TravelCheck check;
    Eigen::Vector2d p = Eigen::Vector2d::Zero();
    double yaw = 0.0, worst = 0.0;
    int compared = 0;
    constexpr int kFine = 200;  // the truth integrated at 0.1 ms
    for (int k = 0; k * 0.02 <= 2.2; ++k) {
      const double t = k * 0.02;
      check.addSpeed(at(t), speed);
      if (yaw_rates) check.addYawRate(at(t), yawRate(t) + gyro_bias);
      if (k % 5 == 0) {
        if (const auto e = check.check(at(t), p, yaw)) ++compared, worst = std::max(worst, e->norm());
      }
      for (int f = 0; f < kFine; ++f) {
        const double tf = t + (f + 0.5) * 0.02 / kFine;
        const double mid = yaw + 0.5 * yawRate(tf) * 0.02 / kFine;
        p += speed * 0.02 / kFine * Eigen::Vector2d(std::cos(mid), std::sin(mid));
        yaw += yawRate(tf) * 0.02 / kFine;
      }
    }
    EXPECT_GT(compared, 10);
    std::printf("into a corner at 15 m/s, %s: the worst excess %.3f m\n", yaw_rates ? "the odometry's path" : "an arc between NDT's headings", worst);
    if (yaw_rates) {
      EXPECT_LT(worst, 0.005) << "the odometry's path";
    } else {
      EXPECT_GT(worst, 0.3) << "an arc between NDT's headings";
    }
  }
}

TEST(TravelCheck, OneBadMatchAtAChordsStartDoesNotWidenThePosesAfterIt) {
  // The first match after a start 37 cm ahead (site C's twin drive started from a roadside fix), the
  // rest good: chords from the bad one disagree, their median does not.
  const auto excess = drive(10.0, 4.0, [](double t) { return t < 0.01 ? 0.37 : 0.0; });
  for (const auto& e : excess) {
    if (!e) continue;
    EXPECT_EQ(e->norm(), 0.0);
  }
}

TEST(TravelCheck, NonFiniteOrOutOfOrderPosesAreNeitherComparedNorKept) {
  TravelCheck check;
  for (int k = 0; k <= 100; ++k) check.addSpeed(at(0.02 * k), 10.0);
  // Yaw rates that are not finite are not integrated: the odometry's path stays straight.
  for (int k = 0; k <= 100; ++k) check.addYawRate(at(0.02 * k), k % 2 ? std::nan("") : 0.0);
  check.addYawRate(at(2.5), std::numeric_limits<double>::infinity());
  EXPECT_FALSE(check.check(at(0.1), Eigen::Vector2d(1.0, 0.0), 0.0).has_value());
  EXPECT_FALSE(check.check(at(0.2), Eigen::Vector2d(2.0, 0.0), 0.0).has_value());
  EXPECT_FALSE(check.check(at(0.9), Eigen::Vector2d(std::nan(""), 0.0), 0.0).has_value());
  EXPECT_FALSE(check.check(at(0.15), Eigen::Vector2d(1.5, 0.0), 0.0).has_value()) << "older than the last kept";
  const auto e = check.check(at(0.8), Eigen::Vector2d(8.0, 0.0), 0.0);
  ASSERT_TRUE(e.has_value());
  EXPECT_EQ(e->norm(), 0.0);
}

TEST(TravelCheck, AWindowOfZeroTurnsTheCheckOff) {
  TravelCheckConfig off;
  off.window = 0.0;
  const auto excess = drive(10.0, 4.0, [](double t) { return t > 1.0 ? 2.0 * t : 0.0; }, off);
  for (const auto& e : excess) {
    ASSERT_TRUE(e.has_value());
    EXPECT_EQ(e->norm(), 0.0);
  }
}

// NDT's heading held against the gyro's turn (travel_check_turn_tolerance): a scan matched a few
// milliradians off is widened in yaw by the whole turn it disagrees by, which its x and y check does
// not see; the gyro's own noise over a chord stays within the tolerance, and with the check off
// nothing is widened.
TEST(TravelCheck, AHeadingThatStepsAgainstTheGyrosTurnIsWidenedByTheWholeTurn) {
  const auto run = [](double tolerance, std::vector<double>& turns) {
    TravelCheckConfig config;
    config.turn_tolerance = tolerance;
    TravelCheck check(config);
    std::mt19937 rng(5);
    std::normal_distribution<double> gyro_noise(0.0, 0.005), yaw_noise(0.0, 3e-4);
    for (int k = 0; k * 0.02 <= 4.0; ++k) {
      const double t = k * 0.02, rate = 0.1;  // a gentle bend, 10 m/s
      check.addSpeed(at(t), 10.0);
      check.addYawRate(at(t), rate + gyro_noise(rng));
      if (k % 5 == 0) {
        const double yaw = rate * t + yaw_noise(rng) + (t >= 2.0 && t < 2.45 ? 0.006 : 0.0);  // NDT's heading 6 mrad off for 0.4 s
        const Eigen::Vector2d p = (10.0 / rate) * Eigen::Vector2d(std::sin(rate * t), 1.0 - std::cos(rate * t));
        check.check(at(t), p, yaw);
        turns.push_back(check.turnDisagreement());
      }
    }
  };
  std::vector<double> on, off;
  run(0.002, on);
  run(0.0, off);
  for (std::size_t i = 0; i < off.size(); ++i) EXPECT_EQ(off[i], 0.0) << i;
  ASSERT_EQ(on.size(), 41u);
  for (std::size_t i = 0; i < on.size(); ++i) {
    const double t = 0.1 * static_cast<double>(i);
    if (t >= 2.0 - 1e-9 && t < 2.45) {
      EXPECT_NEAR(on[i], 0.006, 0.0015) << "the step, whole, at " << t << " s";
    } else if (t < 1.95 || t > 3.55) {
      EXPECT_EQ(on[i], 0.0) << "the gyro's noise within the tolerance at " << t << " s";
    }
  }
}

}  // namespace
}  // namespace coloc::pipeline
