#include "speed_scale.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace coloc::pipeline {
namespace {

constexpr Stamp kStart = 1'700'000'000'000'000'000LL;

// A drive at `speed` along x: odometry at 50 Hz reading `scale` times the true speed with white noise,
// and NDT poses at 10 Hz with 2 cm of noise, each matched 105 ms after its stamp (when it reaches the
// estimator, the odometry has moved on).
SpeedScaleEstimator drive(double speed, double odometry_scale, double seconds, double jump_at = -1.0, double first_pose_off = 0.0,
                          unsigned seed = 3) {
  SpeedScaleEstimator estimator;
  std::mt19937 rng(seed);
  std::normal_distribution<double> odometry_noise(0.0, 0.05), pose_noise(0.0, 0.02);
  for (int k = 0; k * 0.02 <= seconds; ++k) {
    const double t = k * 0.02;
    estimator.addTwist(kStart + static_cast<Stamp>(t * 1e9), speed * odometry_scale + odometry_noise(rng));
    if (k % 5 == 0 && t >= 0.105) {
      const double taken = t - 0.105;
      Eigen::Vector2d p(speed * taken + pose_noise(rng), pose_noise(rng));
      if (jump_at >= 0.0 && std::abs(taken - jump_at) < 0.01) p.x() += 3.0;  // one NDT result that slipped
      if (std::abs(taken) < 0.01) p.x() += first_pose_off;
      estimator.addPose(kStart + static_cast<Stamp>(taken * 1e9), p);
    }
  }
  return estimator;
}

TEST(SpeedScale, LearnsAWheelRadiusErrorOfOnePercentToATenthOfAPercent) {
  const SpeedScaleEstimator e = drive(10.0, 1.01, 20.0);
  ASSERT_TRUE(e.usable());
  EXPECT_NEAR(e.scale(), 1.0 / 1.01, 0.001);
}

TEST(SpeedScale, AnExactOdometryStaysAtOne) {
  EXPECT_NEAR(drive(10.0, 1.0, 20.0).scale(), 1.0, 0.001);
  EXPECT_NEAR(drive(5.0, 1.0, 40.0).scale(), 1.0, 0.001);
}

TEST(SpeedScale, IsOneUntilAWholeChordWasCompared) {
  const SpeedScaleEstimator e = drive(10.0, 1.05, 0.5);  // 4 m of poses: not yet one 5 m chord
  EXPECT_FALSE(e.usable());
  EXPECT_EQ(e.scale(), 1.0);
}

TEST(SpeedScale, OneChordReadsAOnePercentErrorWithinItsNoise) {
  // 2 cm of NDT noise at each end of a 5 m chord is about 0.6 % on the first chord's ratio: better than
  // the 1 % it corrects on average, and within 1.5 % on every drive; three chords halve it.
  double sum_one = 0.0, sum_three = 0.0;
  for (unsigned seed = 1; seed <= 8; ++seed) {
    const SpeedScaleEstimator one = drive(10.0, 1.01, 0.8, -1.0, 0.0, seed), three = drive(10.0, 1.01, 1.8, -1.0, 0.0, seed);
    ASSERT_TRUE(one.usable());
    EXPECT_LT(one.comparedDistance(), 10.0);
    EXPECT_LT(std::abs(one.scale() * 1.01 - 1.0), 0.015) << "seed " << seed;
    sum_one += std::abs(one.scale() * 1.01 - 1.0);
    sum_three += std::abs(three.scale() * 1.01 - 1.0);
  }
  EXPECT_LT(sum_one / 8, 0.007);
  EXPECT_LT(sum_three / 8, 0.0035);
}

TEST(SpeedScale, ABadFirstMatchDoesNotStartTheComparedTravel) {
  // 37 cm along at the first pose (NDT's first match after a start, site C): as the start of the
  // first chord it read the scale 3 % low at 15 m; the next pose, which disagrees with it, starts it.
  const SpeedScaleEstimator e = drive(10.0, 1.01, 2.5, -1.0, 0.37);
  ASSERT_TRUE(e.usable());
  EXPECT_NEAR(e.scale(), 1.0 / 1.01, 0.004);
}

// A stretch where the scene does not hold NDT along the road (a cutting): NDT states 0.4 m there and
// its poses slide ahead, 8 % farther than the vehicle goes, for 100 m. Its chords there count by what
// NDT said of their ends, next to nothing.
TEST(SpeedScale, ChordsBetweenPosesNdtPlacesLooselyCountNextToNothing) {
  const auto drive = [](double pose_sd_floor) {
    SpeedScaleConfig config;
    config.pose_sd_floor = pose_sd_floor;
    SpeedScaleEstimator estimator(config);
    std::mt19937 rng(5);
    std::normal_distribution<double> pose_noise(0.0, 0.01);
    const double speed = 10.0;
    for (int k = 0; k * 0.02 <= 40.0; ++k) {
      const double t = k * 0.02;
      estimator.addTwist(kStart + static_cast<Stamp>(t * 1e9), speed * 1.01);
      if (k % 5 != 0) continue;
      const double x = speed * t, in_cutting = std::clamp(x - 100.0, 0.0, 100.0);
      const bool loose = x > 100.0 && x < 200.0;
      estimator.addPose(kStart + static_cast<Stamp>(t * 1e9), Eigen::Vector2d(x + 0.08 * in_cutting + pose_noise(rng), pose_noise(rng)),
                        loose ? 0.4 : 0.02);
    }
    return estimator.scale();
  };
  EXPECT_NEAR(drive(0.01), 1.0 / 1.01, 0.001);
  EXPECT_GT(std::abs(drive(0.0) - 1.0 / 1.01), 0.01) << "every chord alike: the slide is taken for a scale";
}

TEST(SpeedScale, AnNdtJumpIsNotTakenForAScale) {
  const SpeedScaleEstimator e = drive(10.0, 1.01, 20.0, 8.0);
  EXPECT_NEAR(e.scale(), 1.0 / 1.01, 0.002);
}

// The scale's doubt, which pipeline.speed_scale_uncertainty adds to each twist's speed variance: a
// wheel's 2 % until one chord was compared, then what the chords say, which shrinks with the travel
// and covers the scale's real error (20 drives, NDT stating its 2 cm honestly).
TEST(SpeedScale, ItsStandardDeviationIsThePriorUntilUsableThenShrinksWithTravelAndCoversItsError) {
  double squares = 0.0, worst = 0.0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    SpeedScaleEstimator e;
    std::mt19937 rng(seed);
    std::normal_distribution<double> odometry_noise(0.0, 0.05), pose_noise(0.0, 0.02);
    double at_two = 0.0;
    for (int k = 0; k * 0.02 <= 20.0; ++k) {
      const double t = k * 0.02;
      e.addTwist(kStart + static_cast<Stamp>(t * 1e9), 10.0 * 1.01 + odometry_noise(rng));
      if (k % 5 == 0) e.addPose(kStart + static_cast<Stamp>(t * 1e9), Eigen::Vector2d(10.0 * t + pose_noise(rng), pose_noise(rng)), 0.02);
      if (k == 10) {
        ASSERT_FALSE(e.usable());
        EXPECT_EQ(e.scaleSd(), 0.02) << "the prior before a chord was compared";
      }
      if (k == 100) at_two = e.scaleSd();
    }
    ASSERT_TRUE(e.usable());
    EXPECT_LT(e.scaleSd(), 0.5 * at_two) << "200 m against 20: the doubt shrinks with the travel";
    EXPECT_LT(e.scaleSd(), 0.002);
    const double z = (e.scale() - 1.0 / 1.01) / e.scaleSd();
    squares += z * z / 20.0, worst = std::max(worst, std::abs(z));
  }
  // Consecutive chords share an end, so the figure is the larger one: the errors within it.
  EXPECT_LT(worst, 3.0);
  EXPECT_LT(std::sqrt(squares), 1.2);
  EXPECT_GT(std::sqrt(squares), 0.05) << "not so loose that it says nothing";
}

}  // namespace
}  // namespace coloc::pipeline
