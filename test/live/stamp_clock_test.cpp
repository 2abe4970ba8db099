// The node's time on the header stamps' clock: one clock stays as it is; stamps far from the node's
// time are related by the smallest delay seen, as `coloc fuse` relates them offline.
#include "stamp_clock.hpp"

#include <gtest/gtest.h>

namespace coloc::live {
namespace {

constexpr Stamp kWall = 1'778'234'353'000'000'000LL;  // a recorder's wall clock
constexpr Stamp kSim = 924'000'000'000LL;             // a simulator's clock

TEST(StampClock, StampsOnTheNodesClockLeaveItsTimeAsItIs) {
  StampClock clock(pipeline::ClockMode::kAuto, 0.05);
  EXPECT_EQ(clock.toStampClock(kWall), 0);  // undecided: the filter's clock has not started
  clock.observe(kWall + 30'000'000, kWall);
  EXPECT_FALSE(clock.separate());
  EXPECT_EQ(clock.toStampClock(kWall + 1'000'000'000), kWall + 1'000'000'000);
}

TEST(StampClock, StampsOnAnotherClockAreRelatedByTheSmallestDelaySeen) {
  StampClock clock(pipeline::ClockMode::kAuto, 0.05);
  const Duration apart = kWall - kSim;
  clock.observe(kSim + apart + 80'000'000, kSim);                      // 80 ms late
  clock.observe(kSim + 100'000'000 + apart + 20'000'000, kSim + 100'000'000);  // 20 ms late: the smallest
  clock.observe(kSim + 200'000'000 + apart + 50'000'000, kSim + 200'000'000);
  ASSERT_TRUE(clock.separate());
  EXPECT_EQ(clock.offset(), apart + 20'000'000);
  EXPECT_EQ(clock.toStampClock(kWall + 1'000'000'000), kSim + 1'000'000'000 - 20'000'000);
}

TEST(StampClock, AClockThatWentBackIsRelatedAfresh) {
  StampClock clock(pipeline::ClockMode::kAuto, 0.05);
  clock.observe(kWall, kSim);
  ASSERT_TRUE(clock.separate());
  clock.reset();
  EXPECT_EQ(clock.toStampClock(kWall), 0);
  clock.observe(kWall + 10'000'000, kWall);  // the same player now sends stamps on its own clock
  EXPECT_FALSE(clock.separate());
}

TEST(StampClock, AConfiguredModeIsNotGuessed) {
  StampClock same(pipeline::ClockMode::kSame, 0.05);
  EXPECT_EQ(same.toStampClock(kWall), kWall);
  same.observe(kWall, kSim);
  EXPECT_FALSE(same.separate());
  StampClock separate(pipeline::ClockMode::kSeparate, 0.05);
  separate.observe(kWall + 5'000'000, kWall);
  EXPECT_TRUE(separate.separate());
  EXPECT_EQ(separate.toStampClock(kWall + 5'000'000), kWall);
}

TEST(StampClock, OneMessageStampedFarOffNeitherDecidesTheModeNorMovesTheTime) {
  StampClock clock(pipeline::ClockMode::kAuto, 0.05);
  clock.observe(kWall, kSim);  // the first input, stamped on a simulator's clock
  for (int i = 1; i <= 5; ++i) clock.observe(kWall + i * 100'000'000 + 10'000'000, kWall + i * 100'000'000);
  EXPECT_FALSE(clock.separate()) << "the inputs' stamps are on the node's clock";
  StampClock sim(pipeline::ClockMode::kAuto, 0.05);
  const Duration apart = kWall - kSim;
  for (int i = 0; i < 10; ++i) sim.observe(kSim + i * 100'000'000 + apart + 20'000'000, kSim + i * 100'000'000);
  const Stamp before = sim.toStampClock(kWall + 2'000'000'000LL);
  sim.observe(kSim + 1'000'000'000 + apart, kSim + 1'000'000'000 + 3600'000'000'000LL);  // stamped an hour ahead
  EXPECT_EQ(sim.toStampClock(kWall + 2'000'000'000LL), before);
  EXPECT_EQ(sim.offset(), apart + 20'000'000);
}

}  // namespace
}  // namespace coloc::live
