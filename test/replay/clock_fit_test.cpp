#include <gtest/gtest.h>

#include <random>

#include "coloc/replay/clock_fit.hpp"

namespace coloc::replay {
namespace {

TEST(ClockFit, RecoversRateAndOffsetOfASimulatorClockFromDelayedMessages) {
  // A simulator at 0.993 x real time, stamps near 900 s, logged on the epoch wall clock with 2-80 ms delays.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> delay(0.002, 0.080);
  const double rate = 0.993;
  std::vector<ClockSample> samples;
  const Stamp wall0 = 1'778'234'353'000'000'000LL, sim0 = 924'000'000'000LL;
  for (int i = 0; i < 3000; ++i) {
    const Stamp sim = sim0 + i * 33'000'000LL;
    const double wall_s = toSeconds(sim - sim0) / rate + delay(rng);
    samples.push_back({wall0 + fromSeconds(wall_s), sim});
  }
  const ClockFit fit = fitClock(samples);
  EXPECT_NEAR(fit.rate, rate, 1e-4);
  double smallest = 1e9, largest = -1e9;
  for (const ClockSample& s : samples) {
    const double d = toSeconds(fit.toStampClock(s.log_time) - s.stamp);
    smallest = std::min(smallest, d);
    largest = std::max(largest, d);
  }
  EXPECT_GE(smallest, -1e-6);  // nothing arrives before it was sensed
  EXPECT_LT(smallest, 0.005);  // and the fastest messages arrive almost at once
  EXPECT_LT(largest, 0.081);
}

TEST(ClockFit, SingleSampleGivesRateOneAndZeroDelay) {
  const ClockFit fit = fitClock({{5'000'000'000LL, 1'000'000'000LL}});
  EXPECT_EQ(fit.rate, 1.0);
  EXPECT_EQ(fit.toStampClock(5'000'000'000LL), 1'000'000'000LL);
}

}  // namespace
}  // namespace coloc::replay
