// The pipeline starts by itself from the roadside, is brought back by it when lost, takes only the
// fixes addressed to its vehicle, counts truthfully, and starts again when time goes back.
#include <gtest/gtest.h>

#include <cmath>

#include "coloc/pipeline/pipeline.hpp"
#include "measurements.hpp"
#include "one_rsu.hpp"

namespace coloc::pipeline {
namespace {

using coloc::testing::kStart;
using coloc::testing::kTick;
using coloc::testing::planarPose;
using coloc::testing::twist;

constexpr std::uint32_t kEgo = 1001, kOther = 1002;
constexpr double kSpeed = 10.0, kHeading = 0.5;  // m/s, rad

rsu_client::RsuRegistry rsuAtOrigin() { return coloc::testing::oneRsu({0.0, 0.0}, 80.0); }

Config egoConfig() {
  Config c;
  c.rsu.checks.station_id = kEgo;
  return c;
}

// A car driving straight at kSpeed along kHeading through (0, 0) at kStart, `side` metres to its left.
Eigen::Vector2d truthAt(Stamp t, double side = 0.0) {
  const Eigen::Vector2d along(std::cos(kHeading), std::sin(kHeading)), left(-std::sin(kHeading), std::cos(kHeading));
  return -40.0 * along + kSpeed * toSeconds(t - kStart) * along + side * left;
}

struct Drive {
  Pipeline pipe;
  fusion::SourceId odom, ndt;
  std::vector<fusion::Estimate> estimates;
  std::vector<std::string> events;
  explicit Drive(const Config& c = egoConfig()) : pipe(c, PipelineOptions{std::nullopt, rsuAtOrigin(), false, {}, nullptr, nullptr}) {
    odom = pipe.addTwistSource("odom");
    ndt = pipe.addPoseSource("ndt");
    pipe.onEstimate([this](const fusion::Estimate& e) { estimates.push_back(e); });
    pipe.onEvent([this](const std::string& line) { events.push_back(line); });
  }
  /// Odometry at 50 Hz and, from `fixes_from`, the RSU's fixes at 10 Hz (4 cm off at most, 60 ms late)
  /// addressed to `station`; `ndt_offset`: a map matcher stuck that far to the left (none: no map matching).
  void drive(Stamp from, Stamp to, Stamp fixes_from, std::uint32_t station = kEgo, std::optional<double> ndt_offset = std::nullopt,
             double fix_side = 0.0) {
    for (Stamp t = from; t <= to; t += kTick) {
      pipe.pushTwist(odom, twist(t, kSpeed, 0.0), t + 2'000'000);
      const int k = static_cast<int>((t - kStart) / kTick);
      if (k % 5 == 0 && ndt_offset) {
        const Eigen::Vector2d p = truthAt(t, *ndt_offset);
        pipe.pushPose(ndt, planarPose(t, p.x(), p.y(), kHeading), t + 30'000'000);
      }
      if (k % 5 == 2 && t >= fixes_from) {
        const Eigen::Vector2d p = truthAt(t, fix_side) + 0.04 * Eigen::Vector2d(std::sin(k), std::cos(3 * k));
        pipe.pushFix({t, "rsu_a", p.x(), p.y(), std::nullopt, std::nullopt, station}, t + 60'000'000);
      }
      pipe.runUntil(t);
    }
  }
  /// The largest error of the estimates from `from` on.
  double worstErrorFrom(Stamp from) const {
    double worst = 0.0;
    for (const fusion::Estimate& e : estimates)
      if (e.stamp >= from) worst = std::max(worst, (e.pose.position.head<2>() - truthAt(e.stamp)).norm());
    return worst;
  }
};

TEST(LostAndFound, StartsFromRoadsideFixesWithoutAnInitialPose) {
  Drive run;
  const Stamp first_fix = kStart + 1'000'000'000 + 2 * kTick;
  run.drive(kStart, kStart + 6'000'000'000, first_fix);
  ASSERT_FALSE(run.estimates.empty());
  EXPECT_LE(run.estimates.front().stamp, first_fix + 2'000'000'000);  // within 2 s of the first fix
  EXPECT_LT(run.worstErrorFrom(first_fix + 2'000'000'000), 0.3);
  const PipelineReport r = run.pipe.report();
  EXPECT_EQ(r.starts, 1u);
  EXPECT_NE(r.started_how.find("direction of travel"), std::string::npos) << r.started_how;
  EXPECT_EQ(r.state, fusion::LocalizationState::kLocalized) << r.state_reason;
  // Before the start, fixes were counted as not initialised, never as applied.
  const fusion::SourceCounters& f = r.filter_of_fixes.at("rsu_a");
  EXPECT_GT(f.not_initialized, 0u);
  EXPECT_EQ(f.applied + f.not_initialized + f.gated + f.too_old + f.pending, r.fixes.at("rsu_a").passed_checks);
  const double heading = rollPitchYaw(run.estimates.back().pose.orientation)[2];
  EXPECT_NEAR(heading, kHeading, 0.05);
}

TEST(LostAndFound, WithoutAnyPositionItWaitsAndSaysForWhat) {
  Drive run;
  run.drive(kStart, kStart + 2'000'000'000, kStart + 100'000'000'000);  // no fix, no pose
  EXPECT_TRUE(run.estimates.empty());
  const PipelineReport r = run.pipe.report();
  EXPECT_EQ(r.state, fusion::LocalizationState::kInitialising);
}

class WrongInitialPose : public ::testing::TestWithParam<Eigen::Vector2d> {};

TEST_P(WrongInitialPose, FiveMetresOffIsBroughtBackByTheRoadside) {
  // The vehicle starts 5 m off, and its map matching stays locked on the wrong place (it confirms its
  // own guess); the RSU's fixes, from 1 s on, must bring it back.
  const Eigen::Vector2d off = GetParam();
  const Eigen::Vector2d along(std::cos(kHeading), std::sin(kHeading)), left(-std::sin(kHeading), std::cos(kHeading));
  const Eigen::Vector2d start = truthAt(kStart) + off.x() * along + off.y() * left;
  Drive run;
  run.pipe.pushInitialPose(planarPose(kStart, start.x(), start.y(), kHeading, 0.25, 0.01), kStart);
  const Stamp first_fix = kStart + 1'000'000'000 + 2 * kTick;
  // The stuck map matcher gives poses 5 m off until the fixes have come in for a while, as NDT's
  // guesses do from a wrong prediction; afterwards it matches where the filter now predicts (here: truth).
  run.drive(kStart, first_fix + 500'000'000, first_fix, kEgo, off.y() != 0.0 ? std::optional<double>(off.y()) : std::nullopt);
  run.drive(first_fix + 500'000'000 + kTick, kStart + 8'000'000'000, first_fix, kEgo, 0.0);
  EXPECT_LT(run.worstErrorFrom(first_fix + 3'000'000'000), 0.3);
  const PipelineReport r = run.pipe.report();
  EXPECT_GE(r.recoveries + r.starts, 1u);
  EXPECT_EQ(r.state, fusion::LocalizationState::kLocalized) << r.state_reason;
}

INSTANTIATE_TEST_SUITE_P(SidewaysAndAlong, WrongInitialPose, ::testing::Values(Eigen::Vector2d(0.0, 5.0), Eigen::Vector2d(5.0, 0.0)));

TEST(LostAndFound, AnotherVehiclesFixesAreNeverAppliedEvenRightAfterARestart) {
  // A second car 3.5 m to the side hears its fixes on the same RSU topic; the ego restarts from an
  // RViz-style initial pose (0.25 m^2) right between them.
  Drive run;
  run.pipe.pushInitialPose(planarPose(kStart, truthAt(kStart).x(), truthAt(kStart).y(), kHeading, 0.25, 0.01), kStart);
  run.drive(kStart, kStart + 2'000'000'000, kStart, kOther, 0.0, 3.5);
  const Stamp restart = kStart + 2'000'000'000 + kTick;
  const Eigen::Vector2d p = truthAt(restart);
  run.pipe.pushInitialPose(planarPose(restart, p.x(), p.y(), kHeading, 0.25, 0.01), restart);
  run.drive(restart, kStart + 5'000'000'000, kStart, kOther, 0.0, 3.5);
  const PipelineReport r = run.pipe.report();
  EXPECT_GT(r.fixes.at("rsu_a").addressed_to_another, 40u);
  EXPECT_EQ(r.fixes.at("rsu_a").passed_checks, 0u);
  EXPECT_EQ(r.filter_of_fixes.at("rsu_a").applied, 0u);
  EXPECT_LT(run.worstErrorFrom(kStart), 0.3);
}

TEST(LostAndFound, ATimeJumpBackStartsTheFilterAgainAndSaysSoOnce) {
  Drive run;
  const Stamp first_fix = kStart + 500'000'000 + 2 * kTick;
  run.drive(kStart, kStart + 4'000'000'000, first_fix);
  ASSERT_EQ(run.pipe.report().starts, 1u);
  run.estimates.clear();
  // The log again from its start: the clock goes back 4 s.
  run.drive(kStart, kStart + 4'000'000'000, first_fix);
  const PipelineReport r = run.pipe.report();
  EXPECT_EQ(r.clock_resets, 1u);
  EXPECT_EQ(r.starts, 2u);
  int said = 0;
  for (const std::string& line : run.events) said += line.find("clock went back") != std::string::npos;
  EXPECT_EQ(said, 1);
  ASSERT_FALSE(run.estimates.empty());
  EXPECT_LT(run.estimates.front().stamp, first_fix + 2'000'000'000);  // the second pass has estimates again
  EXPECT_LT(run.worstErrorFrom(first_fix + 2'000'000'000), 0.3);
}

TEST(LostAndFound, UnaddressedFixesAreRefusedUnlessTheConfigurationTakesThem) {
  Config one_vehicle = egoConfig();
  one_vehicle.rsu.checks.accept_unaddressed = true;
  for (const bool accept : {false, true}) {
    Drive run(accept ? one_vehicle : egoConfig());
    const Stamp t = kStart + kTick;
    run.pipe.pushInitialPose(planarPose(kStart, truthAt(kStart).x(), truthAt(kStart).y(), kHeading), kStart);
    run.pipe.pushFix({t, "rsu_a", truthAt(t).x(), truthAt(t).y(), std::nullopt, std::nullopt, std::nullopt}, t);
    run.pipe.runUntil(kStart + 10 * kTick);
    const PipelineReport r = run.pipe.report();
    EXPECT_EQ(r.fixes.at("rsu_a").unaddressed, accept ? 0u : 1u);
    EXPECT_EQ(r.filter_of_fixes.at("rsu_a").applied, accept ? 1u : 0u);
  }
}

}  // namespace
}  // namespace coloc::pipeline
