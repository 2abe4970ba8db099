#include "coloc/pipeline/pipeline.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "coloc/rsu_client/dds_transport.hpp"
#include "measurements.hpp"
#include "one_rsu.hpp"

namespace coloc::pipeline {
namespace {

using coloc::testing::kStart;
using coloc::testing::kTick;
using coloc::testing::planarPose;
using coloc::testing::twist;

rsu_client::RsuRegistry oneRsu() { return coloc::testing::oneRsu({10.0, 0.0}, 30.0); }

// This vehicle is station 1001; its RSU addresses its fixes to it.
const Config kConfig = [] {
  Config c;
  c.rsu.checks.station_id = 1001;
  return c;
}();

rsu_client::RsuFix fixAt(Stamp stamp, double x, double y) { return {stamp, "rsu_a", x, y, std::nullopt, std::nullopt, 1001u}; }

// A vehicle at 5 m/s along x from the origin: twists at 50 Hz, a starting pose, and a fix at `fix_stamp`
// arriving `fix_delay` later. Returns the last estimate.
fusion::Estimate driveWithFix(Duration fix_delay, std::vector<fusion::Estimate>* ticks = nullptr) {
  Pipeline pipe(kConfig, PipelineOptions{std::nullopt, oneRsu(), false, {}, nullptr, nullptr});
  const fusion::SourceId odom = pipe.addTwistSource("odom");
  if (ticks) pipe.onEstimate([&](const fusion::Estimate& e) { ticks->push_back(e); });
  pipe.pushInitialPose(planarPose(kStart, 0.0, 0.0, 0.0), kStart);
  for (int k = 1; k <= 100; ++k) pipe.pushTwist(odom, twist(kStart + k * kTick, 5.0, 0.0), kStart + k * kTick + 2'000'000);
  const Stamp fix_stamp = kStart + 30 * kTick + 10'000'000;  // between two ticks, as an RSU's sweep is
  pipe.pushFix(fixAt(fix_stamp, 5.0 * toSeconds(fix_stamp - kStart) + 0.05, 0.02), fix_stamp + fix_delay);
  pipe.runUntil(kStart + 100 * kTick + 5'000'000);
  return *pipe.estimate();
}

TEST(Pipeline, GivesTheEstimateAtEveryTickOfTheCallersClock) {
  std::vector<fusion::Estimate> ticks;
  driveWithFix(0, &ticks);
  // The starting pose's estimate, then one per 20 ms tick over 2 s.
  ASSERT_EQ(ticks.size(), 101u);
  for (std::size_t i = 1; i < ticks.size(); ++i) EXPECT_EQ(ticks[i].stamp - ticks[i - 1].stamp, kTick);
  EXPECT_NEAR(ticks.back().pose.position.x(), 10.0, 0.1);
}

TEST(Pipeline, ALateFixGivesTheSameEstimateAsAnOnTimeOne) {
  // The filter, not the caller, compensates the delay: 150 ms late is exact within the history.
  const fusion::Estimate on_time = driveWithFix(0);
  const fusion::Estimate late = driveWithFix(150'000'000);
  EXPECT_NEAR((on_time.pose.position - late.pose.position).norm(), 0.0, 1e-9);
  EXPECT_NEAR(on_time.pose_covariance(0, 0), late.pose_covariance(0, 0), 1e-12);
}

TEST(Pipeline, ASettledEstimateIsTheFiltersViewOfAPosesStampOnceThatPoseIsIn) {
  // The fix 50 ms late: the tick's output at its stamp cannot know it, the settled estimate does.
  Pipeline pipe(kConfig, PipelineOptions{std::nullopt, oneRsu(), false, {}, nullptr, nullptr});
  const fusion::SourceId odom = pipe.addTwistSource("odom");
  std::vector<std::pair<std::string, fusion::Estimate>> settled;
  pipe.onPoseSettled([&](const std::string& source, const fusion::Estimate& e) { settled.emplace_back(source, e); });
  pipe.pushInitialPose(planarPose(kStart, 0.0, 0.0, 0.0), kStart);
  for (int k = 1; k <= 100; ++k) pipe.pushTwist(odom, twist(kStart + k * kTick, 5.0, 0.0), kStart + k * kTick + 2'000'000);
  const Stamp fix_stamp = kStart + 30 * kTick;
  pipe.pushFix(fixAt(fix_stamp, 3.0 + 0.05, 0.02), fix_stamp + 50'000'000);
  pipe.runUntil(kStart + 100 * kTick);
  ASSERT_EQ(settled.size(), 1u);
  EXPECT_EQ(settled[0].first, "/rsu/rsu_a/fix");  // the source, named by its topic
  EXPECT_EQ(settled[0].second.stamp, fix_stamp);
  // The fix (5 cm ahead, 2 cm left) pulled the estimate at its stamp towards it.
  EXPECT_GT(settled[0].second.pose.position.x(), 3.0 + 0.005);
  EXPECT_GT(settled[0].second.pose.position.y(), 0.002);
  EXPECT_LT(settled[0].second.pose.position.x(), 3.0 + 0.05 + 1e-9);
}

TEST(Pipeline, FixesPassTheRegistrysChecksBeforeReachingTheFilter) {
  Pipeline pipe(kConfig, PipelineOptions{std::nullopt, oneRsu(), false, {}, nullptr, nullptr});
  std::vector<std::string> rejections;
  pipe.onRejection([&](const std::string& line) { rejections.push_back(line); });
  pipe.pushInitialPose(planarPose(kStart, 10.0, 0.0, 0.0), kStart);
  pipe.pushFix(fixAt(kStart + kTick, 100.0, 0.0), kStart + kTick);          // 90 m from the RSU: outside its coverage
  pipe.pushFix({kStart + kTick, "rsu_x", 10.0, 0.0, std::nullopt, std::nullopt, std::nullopt}, kStart + kTick);  // an RSU nobody registered
  pipe.pushFix(fixAt(kStart + 2 * kTick, 10.01, 0.0), kStart + 2 * kTick);  // a good one
  pipe.runUntil(kStart + 10 * kTick);
  const PipelineReport r = pipe.report();
  EXPECT_EQ(r.fixes.at("rsu_a").received, 2u);
  EXPECT_EQ(r.fixes.at("rsu_a").out_of_coverage, 1u);
  EXPECT_EQ(r.fixes.at("rsu_a").passed_checks, 1u);
  EXPECT_EQ(r.fixes.at("rsu_x").unknown_rsu, 1u);
  ASSERT_EQ(rejections.size(), 2u);
  EXPECT_NE(rejections[0].find("out_of_coverage"), std::string::npos) << rejections[0];
  EXPECT_NE(rejections[1].find("unknown_rsu"), std::string::npos) << rejections[1];
  // Only the good fix reached the filter.
  for (const auto& s : r.sources)
    if (s.name == "/rsu/rsu_a/fix") {
      EXPECT_EQ(s.counters.received, 1u);
    }
}

TEST(Pipeline, InputsPushedFromManyThreadsAreAllTaken) {
  Pipeline pipe(kConfig, PipelineOptions{});
  const fusion::SourceId odom = pipe.addTwistSource("odom");
  pipe.pushInitialPose(planarPose(kStart, 0.0, 0.0, 0.0), kStart);
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t)
    threads.emplace_back([&, t] {
      for (int k = 0; k < 250; ++k) {
        const Stamp s = kStart + (t * 250 + k + 1) * 1'000'000LL;
        pipe.pushTwist(odom, twist(s, 1.0, 0.0), s);
      }
    });
  for (auto& t : threads) t.join();
  pipe.runUntil(kStart + 2'000'000'000LL);
  std::uint64_t received = 0;
  for (const auto& s : pipe.report().sources)
    if (s.name == "odom") received = s.counters.received;
  EXPECT_EQ(received, 1000u);
}

TEST(Pipeline, ItsOwnThreadRunsTheFilterOnTheSystemClock) {
  Pipeline pipe(kConfig, PipelineOptions{});
  std::atomic<int> estimates{0};
  pipe.onEstimate([&](const fusion::Estimate&) { ++estimates; });
  const Stamp now = rsu_client::systemNow();
  pipe.pushInitialPose(planarPose(now, 0.0, 0.0, 0.0), now);
  pipe.start();
  for (int i = 0; i < 200 && estimates.load() < 5; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  pipe.stop();
  EXPECT_GE(estimates.load(), 5);
  ASSERT_TRUE(pipe.estimate().has_value());
  EXPECT_GT(pipe.estimate()->stamp, now);
}

}  // namespace
}  // namespace coloc::pipeline
