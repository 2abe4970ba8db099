// The heading's error between two twists (EkfConfig::yaw_rate_sampling_noise): the filter turns the
// heading at one twist's yaw rate until the next, and a rate that changed between them changed at a
// moment neither tells. Its spread, (change x interval)^2 / 12, goes into the yaw variance.
#include <gtest/gtest.h>

#include <vector>

#include "coloc/fusion/localizer.hpp"
#include "measurements.hpp"

namespace coloc::fusion {
namespace {

using namespace coloc::testing;

constexpr double kSpeed = 8.0;  // m/s

// A drive on twists alone, one per 20 ms tick reading `rates[k]` (rad/s), from a pose at the origin;
// the filter's yaw variance at the end. Twists arrive in order unless `late` is given: then the twist
// of that tick is fed again after the last one (a copy that comes late).
double yawVarianceAfter(const std::vector<double>& rates, bool sampling_noise, int late = -1) {
  EkfConfig config;
  config.yaw_rate_sampling_noise = sampling_noise;
  Localizer filter(config);
  const SourceId odom = filter.addTwistSource("odom");
  filter.initialize(planarPose(kStart, 0.0, 0.0, 0.0, 0.01, 1e-4), twist(kStart, kSpeed, rates[0], 0.0025, 2.5e-5));
  for (std::size_t k = 1; k < rates.size(); ++k) {
    const Stamp t = kStart + static_cast<Duration>(k) * kTick;
    filter.advanceTo(t);
    filter.feedTwist(odom, twist(t, kSpeed, rates[k], 0.0025, 2.5e-5));
  }
  if (late >= 0) {
    const Stamp t = kStart + static_cast<Duration>(late) * kTick;
    filter.feedTwist(odom, twist(t, kSpeed, rates[late], 0.0025, 2.5e-5));
  }
  const Stamp end = kStart + static_cast<Duration>(rates.size() + 5) * kTick;
  filter.advanceTo(end);
  return filter.estimate()->pose_covariance(5, 5);
}

// Straight, then into a bend at 0.4 rad/s from the 20th twist on.
std::vector<double> intoABend() {
  std::vector<double> rates(60, 0.0);
  for (std::size_t k = 20; k < rates.size(); ++k) rates[k] = 0.4;
  return rates;
}

TEST(YawRateSamplingNoise, ARateThatStepsBetweenTwoTwistsWidensTheHeadingByTheStepsSpread) {
  const double step = 0.4 * toSeconds(kTick);  // rad: the heading turned by the step over one interval
  const double added = yawVarianceAfter(intoABend(), true) - yawVarianceAfter(intoABend(), false);
  EXPECT_NEAR(added, step * step / 12.0, 1e-12) << "the step's spread, once";
}

TEST(YawRateSamplingNoise, ASteadyRateAddsNothing) {
  // On a straight road or round a bend at one rate, the filter is Autoware's to the bit.
  for (const double rate : {0.0, 0.25}) {
    const std::vector<double> steady(60, rate);
    EXPECT_EQ(yawVarianceAfter(steady, true), yawVarianceAfter(steady, false)) << rate << " rad/s";
  }
  EXPECT_FALSE(EkfConfig{}.yaw_rate_sampling_noise) << "off by default: Autoware's filter";
}

TEST(YawRateSamplingNoise, ATwistOlderThanTheNewestTakenAddsNothing) {
  // The 19th twist (before the step) again after the last: it lies within an interval already
  // counted, and the step's spread is added once.
  const double step = 0.4 * toSeconds(kTick);
  const double added = yawVarianceAfter(intoABend(), true, 19) - yawVarianceAfter(intoABend(), false, 19);
  EXPECT_NEAR(added, step * step / 12.0, 1e-12);
}

TEST(YawRateSamplingNoise, AfterAResetTheFirstTwistIsMeasuredFromNothing) {
  // A log played again from its start (a bend's exit at the 5th twist): its twists are not held
  // against the last rate of the first play, which would leave them all older than it.
  EkfConfig config;
  config.yaw_rate_sampling_noise = true;
  Localizer filter(config);
  const SourceId odom = filter.addTwistSource("odom");
  const auto run = [&] {
    filter.initialize(planarPose(kStart, 0.0, 0.0, 0.0, 0.01, 1e-4), twist(kStart, kSpeed, 0.0, 0.0025, 2.5e-5));
    for (int k = 1; k < 10; ++k) {
      filter.advanceTo(kStart + k * kTick);
      filter.feedTwist(odom, twist(kStart + k * kTick, kSpeed, k < 5 ? 0.3 : 0.0, 0.0025, 2.5e-5));
    }
    return filter.estimate()->pose_covariance(5, 5);
  };
  const double first = run();
  filter.reset();
  EXPECT_EQ(run(), first) << "the same drive, the same heading's variance";
}

}  // namespace
}  // namespace coloc::fusion
