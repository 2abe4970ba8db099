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
  clock.reset(kWall + 1'000'000'000, kWall);
  EXPECT_EQ(clock.toStampClock(kWall), 0);
  clock.observe(kWall + 10'000'000, kWall);  // the same player now sends stamps on its own clock
  EXPECT_FALSE(clock.separate());
}

// A log played in a loop: each topic's reader is a thread of its own, so a fix sent at the end of a
// pass can arrive after /clock went back. Taken, it decided the new relation (a stamp 12.9 s ahead)
// and started the filter on the old timeline, and the whole pass was then refused as too old.
TEST(StampClock, AnInputSentBeforeTheClockWentBackIsStaleAndDecidesNothing) {
  StampClock clock(pipeline::ClockMode::kAuto, 0.05);
  const Stamp start = kWall, end = kWall + 12'900'000'000LL;
  for (Stamp t = start; t < end; t += 100'000'000) ASSERT_TRUE(clock.observe(t + 10'000'000, t));
  clock.reset(end, start);
  EXPECT_FALSE(clock.observe(start + 1'000'000, end - 100'000'000)) << "stamped at the end of the last pass";
  EXPECT_EQ(clock.toStampClock(start + 1'000'000), 0) << "still undecided";
  EXPECT_TRUE(clock.observe(start + 20'000'000, start));
  EXPECT_FALSE(clock.separate());
  EXPECT_EQ(clock.toStampClock(start + 20'000'000), start + 20'000'000);
  // An arrival read just before /clock went back, by a reader that observes just after: stale too.
  EXPECT_FALSE(clock.observe(end, start + 10'000'000));
  // Once the new relation has inputs of its own, nothing from before is on its way: all taken again
  // (the new pass's own stamps reach where the old one's were).
  for (int i = 1; i < 16; ++i) EXPECT_TRUE(clock.observe(start + i * 10'000'000 + 5'000'000, start + i * 10'000'000));
  EXPECT_TRUE(clock.observe(start + 6'500'000'000LL, start + 6'490'000'000LL));
  EXPECT_TRUE(clock.observe(start + 6'600'000'000LL, end - 100'000'000)) << "no longer told apart: the filter's to refuse";
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
