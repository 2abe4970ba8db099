// The map-matching bias as two more states (EkfConfig::map_match_bias_sd): NDT's poses carry an error
// that stays from scan to scan; anchors (roadside fixes) tell it apart.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "coloc/core/error.hpp"
#include "coloc/fusion/localizer.hpp"
#include "measurements.hpp"

namespace coloc::fusion {
namespace {

using namespace coloc::testing;

constexpr double kSpeed = 10.0;              // m/s along x
const Eigen::Vector2d kBias{0.10, -0.06};    // NDT's error here, the same every scan
constexpr double kNdtNoise = 0.01;           // m, NDT's scan-to-scan noise per axis
constexpr double kYawNoise = 0.002;          // rad
constexpr double kFixNoise = 0.015;          // m, the RSU's
constexpr double kSpeedNoise = 0.05;         // m/s, the odometry's
constexpr double kYawRateNoise = 0.005;      // rad/s

struct DriveResult {
  double mean_error = 0.0;    // m, the fused position against the truth over the last half
  Eigen::Vector2d bias_estimate = Eigen::Vector2d::Zero();
  double ndt_nis_per_dof = 0.0;
};

// 20 s at 10 m/s: odometry at 50 Hz, NDT at 10 Hz (truth + bias + noise), fixes at 10 Hz when `fixes`;
// NDT's poses stated at `ndt_variance` per axis. The bias is kBias throughout, or with `wandering` it
// starts there and moves as the filter's model says (a random walk in distance of the configuration's
// length and sd).
DriveResult drive(const EkfConfig& config, bool fixes, double ndt_variance, bool wandering = false, std::uint32_t seed = 7) {
  Localizer filter(config);
  const SourceId odom = filter.addTwistSource("odom");
  const SourceId ndt = filter.addPoseSource("ndt");
  const SourceId rsu = filter.addPoseSource("rsu", 0, true);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> unit;
  DriveResult run;
  int samples = 0;
  Eigen::Vector2d bias = kBias;
  const double phi = std::exp(-kSpeed * toSeconds(kTick) / config.map_match_bias_length);
  const int ticks = 1000;
  for (int k = 0; k <= ticks; ++k) {
    const Stamp t = kStart + k * kTick;
    const double x = kSpeed * k * toSeconds(kTick);
    if (k > 0) filter.advanceTo(t);
    if (k > 0 && wandering)
      bias = phi * bias + std::sqrt(1.0 - phi * phi) * config.map_match_bias_sd * Eigen::Vector2d(unit(rng), unit(rng));
    if (k % 5 == 0) {
      const PoseMeasurement pose = planarPose(t, x + bias.x() + kNdtNoise * unit(rng), bias.y() + kNdtNoise * unit(rng),
                                              kYawNoise * unit(rng), ndt_variance, kYawNoise * kYawNoise);
      if (k == 0) {
        EXPECT_TRUE(filter.initialize(pose, twist(t, kSpeed, 0.0, kSpeedNoise * kSpeedNoise, kYawRateNoise * kYawRateNoise)).applied());
      } else {
        filter.feedPose(ndt, pose);
      }
      if (fixes) filter.feedPose(rsu, fix2d(t, x + kFixNoise * unit(rng), kFixNoise * unit(rng), kFixNoise * kFixNoise));
    }
    filter.feedTwist(odom, twist(t, kSpeed + kSpeedNoise * unit(rng), kYawRateNoise * unit(rng), kSpeedNoise * kSpeedNoise,
                                 kYawRateNoise * kYawRateNoise));
    if (k >= ticks / 2) {
      const Estimate e = *filter.estimate();
      run.mean_error += std::hypot(e.pose.position.x() - kSpeed * k * toSeconds(kTick), e.pose.position.y());
      run.bias_estimate = e.map_match_bias;
      ++samples;
    }
  }
  run.mean_error /= samples;
  const SourceCounters& c = filter.counters(ndt);
  run.ndt_nis_per_dof = c.nis_sum / static_cast<double>(c.nis_dof);
  return run;
}

EkfConfig withBias() {
  EkfConfig c;
  c.map_match_bias_sd = 0.12;
  c.map_match_bias_length = 100.0;
  return c;
}

TEST(MapMatchBias, AnchorsTellNdtsBiasApartAndTheFusedPoseLosesIt) {
  const DriveResult modelled = drive(withBias(), true, kNdtNoise * kNdtNoise);
  EXPECT_LT(modelled.mean_error, 0.02);  // the fixes' noise averaged; NDT's 11.7 cm bias gone
  EXPECT_NEAR(modelled.bias_estimate.x(), kBias.x(), 0.02);
  EXPECT_NEAR(modelled.bias_estimate.y(), kBias.y(), 0.02);
  // The 6-state filter, NDT taken at its noise: it follows NDT, fixes or not.
  const DriveResult plain = drive(EkfConfig{}, true, kNdtNoise * kNdtNoise);
  EXPECT_GT(plain.mean_error, 0.06);
  EXPECT_EQ(plain.bias_estimate, Eigen::Vector2d::Zero());
}

TEST(MapMatchBias, WithoutAnchorsNdtsInnovationsAreHonestAtItsNoiseWhileItsWholeErrorMakesThemLookTooSmall) {
  // Alone, NDT's bias cannot be told apart: its innovations show the noise and the bias's wander, which
  // is what the filter takes them at. 200 poses of 3 degrees of freedom: the mean lies within 0.84-1.17
  // 95 % of the time when the model is right.
  for (std::uint32_t seed : {7u, 8u, 9u}) {
    const DriveResult modelled = drive(withBias(), false, kNdtNoise * kNdtNoise, true, seed);
    EXPECT_GT(modelled.ndt_nis_per_dof, 0.8) << "seed " << seed;
    EXPECT_LT(modelled.ndt_nis_per_dof, 1.2) << "seed " << seed;
    // Stated at its whole error (the bias's spread and the noise) as a per-pose floor does, NDT looks
    // far better than it says: its x and y near 0 (its yaw, stated at its noise, still near 1).
    const DriveResult floored = drive(EkfConfig{}, false, 0.12 * 0.12 + kNdtNoise * kNdtNoise, true, seed);
    EXPECT_LT(floored.ndt_nis_per_dof, 0.5) << "seed " << seed;
  }
}

TEST(MapMatchBias, ALateFixGivesTheSameBiasAndPoseAsOnTime) {
  Localizer on_time(withBias()), late(withBias());
  for (Localizer* f : {&on_time, &late}) {
    f->addTwistSource("odom");
    f->addPoseSource("ndt");
    f->addPoseSource("rsu", 0, true);
    ASSERT_TRUE(f->initialize(planarPose(kStart, 0.1, 0.0, 0.0, 1e-4, 1e-6), twist(kStart, kSpeed, 0.0, 0.0025, 1e-5)).applied());
  }
  for (int k = 1; k <= 60; ++k) {
    const Stamp t = kStart + k * kTick;
    const double x = kSpeed * k * toSeconds(kTick);
    for (Localizer* f : {&on_time, &late}) {
      f->advanceTo(t);
      f->feedTwist("odom", twist(t, kSpeed, 0.0, 0.0025, 1e-5));
      if (k % 5 == 0) f->feedPose("ndt", planarPose(t, x + 0.1, 0.0, 0.0, 1e-4, 1e-6));
    }
    if (k == 20) on_time.feedPose("rsu", fix2d(t, x, 0.0, 2e-4));
    if (k == 27) {
      EXPECT_TRUE(late.feedPose("rsu", fix2d(kStart + 20 * kTick, kSpeed * 20 * toSeconds(kTick), 0.0, 2e-4)).applied());
    }
  }
  const Estimate a = *on_time.estimate(), b = *late.estimate();
  EXPECT_NEAR((a.pose.position - b.pose.position).norm(), 0.0, 1e-9);
  EXPECT_NEAR((a.map_match_bias - b.map_match_bias).norm(), 0.0, 1e-9);
  EXPECT_NEAR((a.map_match_bias_covariance - b.map_match_bias_covariance).norm(), 0.0, 1e-12);
  EXPECT_GT(a.map_match_bias.x(), 0.03);  // the one fix moved the bias towards NDT's 10 cm
}

// Where NDT's poses followed the bias (held at nothing, NDT at its 1 cm noise, 10 cm off), the
// position carries it: let in with its spread at the first fix's tick, that fix moves the position
// most of the way to the truth, where without it the filter, sure of its position, barely moves; a
// late fix after a release gives what an on-time one gives; bad spreads are refused.
TEST(MapMatchBias, ABiasLetInAtAFixLetsTheFixMoveThePositionAndALateFixGivesTheSameAsOnTime) {
  const auto run = [](bool release, int fix_delay) {
    Localizer f(withBias());
    f.addTwistSource("odom");
    f.addPoseSource("ndt");
    f.addPoseSource("rsu", 0, true);
    f.setMapMatchBiasVariance(0.0);
    EXPECT_TRUE(f.initialize(planarPose(kStart, 0.1, 0.0, 0.0, 1e-4, 1e-6), twist(kStart, kSpeed, 0.0, 0.0025, 1e-5)).applied());
    for (int k = 1; k <= 60; ++k) {
      const Stamp t = kStart + k * kTick;
      const double x = kSpeed * k * toSeconds(kTick);
      f.advanceTo(t);
      f.feedTwist("odom", twist(t, kSpeed, 0.0, 0.0025, 1e-5));
      if (k % 5 == 0) f.feedPose("ndt", planarPose(t, x + 0.1, 0.0, 0.0, 1e-4, 1e-6));
      if (k == 40 + fix_delay) {
        const Stamp at = kStart + 40 * kTick;
        if (release) {
          f.setMapMatchBiasVariance(0.01);
          f.releaseMapMatchBias(at, 0.01);
        }
        EXPECT_TRUE(f.feedPose("rsu", fix2d(at, kSpeed * 40 * toSeconds(kTick), 0.0, 2e-4)).applied());
      }
    }
    return *f.estimate();
  };
  const Estimate released = run(true, 0), held = run(false, 0), late = run(true, 4);
  const double truth = kSpeed * 60 * toSeconds(kTick);
  EXPECT_LT(std::abs(released.pose.position.x() - truth), 0.03) << "the fix took most of NDT's 10 cm back";
  EXPECT_GT(std::abs(held.pose.position.x() - truth), 0.08) << "sure of its position, the filter barely moved";
  EXPECT_GT(released.map_match_bias.x(), 0.07);
  EXPECT_NEAR((released.pose.position - late.pose.position).norm(), 0.0, 1e-9);
  EXPECT_NEAR((released.map_match_bias - late.map_match_bias).norm(), 0.0, 1e-9);
  EXPECT_NEAR((released.map_match_bias_covariance - late.map_match_bias_covariance).norm(), 0.0, 1e-12);
  Localizer f(withBias());
  for (double bad : {-1.0, std::nan(""), kInfinity}) EXPECT_THROW(f.releaseMapMatchBias(kStart, bad), Error);
  EXPECT_NO_THROW(f.releaseMapMatchBias(kStart, 0.01)) << "before the start: nothing to let it into";
}

TEST(MapMatchBias, AVarianceThatIsNotOneIsRefusedNamingIt) {
  Localizer filter(withBias());
  for (double bad : {-1.0, std::nan(""), kInfinity, 2e6}) EXPECT_THROW(filter.setMapMatchBiasVariance(bad), Error);
  try {
    filter.setMapMatchBiasVariance(-0.5);
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("map-matching bias variance"), std::string::npos) << e.what();
  }
  EkfConfig bad = withBias();
  bad.map_match_bias_length = 0.0;
  EXPECT_THROW({ Localizer l(bad); }, Error);
  bad = withBias();
  bad.map_match_bias_sd = -0.1;
  EXPECT_THROW({ Localizer l(bad); }, Error);
}

}  // namespace
}  // namespace coloc::fusion
