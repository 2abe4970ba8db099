#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <vector>

#include "coloc/fusion/localizer.hpp"
#include "coloc/rsu_client/rsu_fix.hpp"

namespace coloc::rsu_client {
namespace {

constexpr Stamp kNow = 1'700'000'000'000'000'000LL;

// A setup with one connected vehicle: unaddressed fixes taken (the addressing has tests of its own).
FixChecker checker() {
  FixCheckConfig config;
  config.accept_unaddressed = true;
  return FixChecker(RsuRegistry::parse("rsus:\n  - {id: rsu_a, position: [100, 0], lidar_model: VLP-16}\n", "test"), config);
}

FixChecker checkerOfStation(std::optional<std::uint32_t> station) {
  FixCheckConfig config;
  config.station_id = station;
  return FixChecker(RsuRegistry::parse("rsus:\n  - {id: rsu_a, position: [100, 0], lidar_model: VLP-16}\n", "test"), config);
}

RsuFix fixFor(std::optional<std::uint32_t> station, Stamp stamp, double x) {
  RsuFix fix{stamp, "rsu_a", x, 0.0, std::nullopt, std::nullopt, std::nullopt};
  fix.station_id = station;
  return fix;
}

TEST(FixChecker, OnlyFixesAddressedToThisVehiclesStationIdPass) {
  FixChecker c = checkerOfStation(1001);
  EXPECT_TRUE(c.check(fixFor(1001u, kNow - 1000, 101), kNow).accepted());
  const FixVerdict other = c.check(fixFor(1002u, kNow - 2000, 104), kNow);
  EXPECT_EQ(other.rejection, FixRejection::kAddressedToAnother) << other.detail;
  EXPECT_NE(other.detail.find("1002"), std::string::npos) << other.detail;
  EXPECT_NE(other.detail.find("1001"), std::string::npos) << other.detail;
  const FixVerdict unaddressed = c.check(fixFor(std::nullopt, kNow - 3000, 101), kNow);
  EXPECT_EQ(unaddressed.rejection, FixRejection::kUnaddressed) << unaddressed.detail;
  EXPECT_NE(unaddressed.detail.find("accept_unaddressed"), std::string::npos) << unaddressed.detail;
  const FixCounters& k = c.counters().at("rsu_a");
  EXPECT_EQ(k.received, 3u);
  EXPECT_EQ(k.passed_checks, 1u);
  EXPECT_EQ(k.addressed_to_another, 1u);
  EXPECT_EQ(k.unaddressed, 1u);
}

TEST(FixChecker, AVehicleWithoutAStationIdTakesNoAddressedFix) {
  FixChecker c = checkerOfStation(std::nullopt);
  const FixVerdict v = c.check(fixFor(7u, kNow - 1000, 101), kNow);
  EXPECT_EQ(v.rejection, FixRejection::kAddressedToAnother);
  EXPECT_NE(v.detail.find("rsu.station_id"), std::string::npos) << v.detail;
}

TEST(FixChecker, TwoVehiclesFixesFromOneFrameAreNotDuplicatesOfEachOther) {
  FixChecker c = checkerOfStation(1001);
  FixCheckConfig both;
  EXPECT_TRUE(c.check(fixFor(1001u, kNow - 1000, 101), kNow).accepted());
  EXPECT_EQ(c.check(fixFor(1002u, kNow - 1000, 104), kNow).rejection, FixRejection::kAddressedToAnother);
  EXPECT_EQ(c.check(fixFor(1001u, kNow - 1000, 101), kNow).rejection, FixRejection::kDuplicate);
}

TEST(FixChecker, AnAddressNotAStationIdIsRefusedAsBadAddress) {
  FixChecker c = checkerOfStation(1001);
  for (const char* child : {"", "base_link", "-5", "4294967296", "10 01", "0x3e9"}) {
    RsuFix fix = fixFor(parseStationId(child), kNow - 1000, 101);
    SentFields sent;
    sent.frame_id = "map";
    sent.covariance.diagonal() << 0.01486, 0.01486, kInfinity, kInfinity, kInfinity, kInfinity;
    sent.child_frame_id = child;
    fix.sent = sent;
    const FixVerdict v = c.check(fix, kNow);
    EXPECT_EQ(v.rejection, FixRejection::kBadAddress) << "'" << child << "': " << v.detail;
  }
  EXPECT_EQ(parseStationId("1001"), 1001u);
  EXPECT_EQ(parseStationId("4294967295"), 4294967295u);
  EXPECT_EQ(c.counters().at("rsu_a").bad_address, 6u);
}

TEST(FixChecker, ValidFixBecomesATwoDimensionalMeasurementWithInfiniteElsewhere) {
  FixChecker c = checker();
  const FixVerdict v = c.check({kNow - 20'000'000, "rsu_a", 110.0, 2.0, std::nullopt, std::nullopt, std::nullopt}, kNow);
  ASSERT_TRUE(v.accepted()) << v.detail;
  EXPECT_EQ(v.measurement.stamp, kNow - 20'000'000);  // capture time, not arrival
  EXPECT_EQ(v.measurement.covariance(0, 0), 0.01486);
  EXPECT_EQ(v.measurement.covariance(1, 1), 0.01486);
  for (int i = 2; i < 6; ++i) EXPECT_EQ(v.measurement.covariance(i, i), kInfinity);
  EXPECT_EQ(c.counters().at("rsu_a").passed_checks, 1u);
}

TEST(FixChecker, EveryInvalidFixIsRejectedWithItsReasonAndCounted) {
  FixChecker c = checker();
  const double nan = std::nan("");
  struct Case {
    RsuFix fix;
    FixRejection reason;
  };
  const Case cases[] = {
      {{kNow, "rsu_z", 100, 0, std::nullopt, std::nullopt, std::nullopt}, FixRejection::kUnknownRsu},
      {{kNow, "rsu_a", nan, 0, std::nullopt, std::nullopt, std::nullopt}, FixRejection::kNonFinite},
      {{kNow, "rsu_a", 100, kInfinity, std::nullopt, std::nullopt, std::nullopt}, FixRejection::kNonFinite},
      {{kNow, "rsu_a", 100, 0, nan, std::nullopt, std::nullopt}, FixRejection::kNonFinite},
      {{kNow, "rsu_a", 140, 0, std::nullopt, std::nullopt, std::nullopt}, FixRejection::kOutOfCoverage},
      {{kNow - 2 * kNanosPerSecond, "rsu_a", 100, 0, std::nullopt, std::nullopt, std::nullopt}, FixRejection::kStale},
      {{kNow + kNanosPerSecond, "rsu_a", 100, 0, std::nullopt, std::nullopt, std::nullopt}, FixRejection::kFromFuture},
  };
  for (const Case& k : cases) {
    const FixVerdict v = c.check(k.fix, kNow);
    EXPECT_EQ(v.rejection, k.reason) << v.detail;
    EXPECT_NE(v.detail.find(toString(k.reason)), std::string::npos) << v.detail;
    EXPECT_NE(v.detail.find(k.fix.rsu_id), std::string::npos) << v.detail;
  }
  EXPECT_TRUE(c.check({kNow - 1000, "rsu_a", 101, 0, std::nullopt, std::nullopt, std::nullopt}, kNow).accepted());
  EXPECT_EQ(c.check({kNow - 1000, "rsu_a", 101, 0, std::nullopt, std::nullopt, std::nullopt}, kNow + 5).rejection, FixRejection::kDuplicate);
  const FixCounters& a = c.counters().at("rsu_a");
  EXPECT_EQ(a.non_finite, 3u);
  EXPECT_EQ(a.out_of_coverage, 1u);
  EXPECT_EQ(a.stale, 1u);
  EXPECT_EQ(a.from_future, 1u);
  EXPECT_EQ(a.duplicate, 1u);
  EXPECT_EQ(a.passed_checks, 1u);
  EXPECT_EQ(c.counters().at("rsu_z").unknown_rsu, 1u);
}

// A fix as a message carries it: map frame, the registry's VLP-16 variance on x and y, +inf elsewhere.
RsuFix sentFix(Stamp stamp, double x) {
  RsuFix fix{stamp, "rsu_a", x, 0.0, std::nullopt, std::nullopt, std::nullopt};
  SentFields sent;
  sent.frame_id = "map";
  sent.nanosec = static_cast<std::uint32_t>(stamp % kNanosPerSecond);
  sent.covariance.diagonal() << 0.01486, 0.01486, kInfinity, kInfinity, kInfinity, kInfinity;
  fix.sent = sent;
  return fix;
}

// A checker of the registry `yaml` that takes fixes addressed to no one (one vehicle on the road).
FixChecker acceptingUnaddressed(const std::string& yaml) {
  FixCheckConfig one_vehicle;
  one_vehicle.accept_unaddressed = true;
  return FixChecker(RsuRegistry::parse(yaml, "test"), one_vehicle);
}

// A sent fix whose x/y covariance is (xx, xy; xy, yy).
RsuFix sentFixWith(Stamp stamp, double xx, double yy, double xy) {
  RsuFix fix = sentFix(stamp, 101);
  fix.sent->covariance(0, 0) = xx;
  fix.sent->covariance(1, 1) = yy;
  fix.sent->covariance(0, 1) = fix.sent->covariance(1, 0) = xy;
  return fix;
}

TEST(FixChecker, AMessagesFrameCovarianceAndStampFieldAreHeldAgainstTheRegistry) {
  FixChecker c = checker();
  ASSERT_TRUE(c.check(sentFix(kNow - 1000, 101), kNow).accepted());
  struct Case {
    const char* what;
    std::function<void(SentFields&)> spoil;
    FixRejection reason;
    const char* says;
  };
  const double nan = std::nan("");
  const std::vector<Case> cases = {
      {"frame odom", [](SentFields& s) { s.frame_id = "odom"; }, FixRejection::kWrongFrame, "frame 'odom'"},
      {"empty frame", [](SentFields& s) { s.frame_id.clear(); }, FixRejection::kWrongFrame, "frame ''"},
      {"frame not UTF-8", [](SentFields& s) { s.frame_id = "ma\xC3\x28"; }, FixRejection::kWrongFrame, "not UTF-8"},
      {"frame of 1 MiB", [](SentFields& s) { s.frame_id.assign(1 << 20, 'm'); }, FixRejection::kWrongFrame, "1048576 bytes"},
      {"nanosec 1e9", [](SentFields& s) { s.nanosec = 1000000000u; }, FixRejection::kBadStamp, "nanosec 1000000000"},
      {"NaN variance", [&](SentFields& s) { s.covariance(0, 0) = nan; }, FixRejection::kBadCovariance, "covariance[x,x] is NaN"},
      {"NaN off-diagonal", [&](SentFields& s) { s.covariance(2, 4) = nan; }, FixRejection::kBadCovariance, "covariance[z,pitch] is NaN"},
      {"-inf", [](SentFields& s) { s.covariance(5, 5) = -kInfinity; }, FixRejection::kBadCovariance, "is -inf"},
      {"negative", [](SentFields& s) { s.covariance(1, 1) = -0.01486; }, FixRejection::kBadCovariance, "covariance[y,y] is negative"},
      {"asymmetric", [](SentFields& s) { s.covariance(0, 1) = 0.001; }, FixRejection::kBadCovariance, "not symmetric"},
      {"x not measured", [](SentFields& s) { s.covariance(0, 0) = kInfinity; }, FixRejection::kBadCovariance, "+inf (not measured)"},
      {"y zero", [](SentFields& s) { s.covariance(1, 1) = 0.0; }, FixRejection::kBadCovariance, "covariance[y,y] is 0"},
      {"surer than the registry", [](SentFields& s) { s.covariance(0, 0) = s.covariance(1, 1) = 0.00681; }, FixRejection::kBadCovariance,
       "is below the registry's 0.01486"},
      {"x/y correlation beyond 1", [](SentFields& s) { s.covariance(0, 1) = s.covariance(1, 0) = 0.02; }, FixRejection::kBadCovariance,
       "exceeds what the x and y variances allow"},
  };
  for (std::size_t k = 0; k < cases.size(); ++k) {
    RsuFix fix = sentFix(kNow - 2000 - static_cast<Stamp>(k), 101);
    cases[k].spoil(*fix.sent);
    const FixVerdict v = c.check(fix, kNow);
    EXPECT_EQ(v.rejection, cases[k].reason) << cases[k].what << ": " << v.detail;
    EXPECT_NE(v.detail.find(cases[k].says), std::string::npos) << cases[k].what << ": " << v.detail;
    EXPECT_LT(v.detail.size(), 400u) << cases[k].what << ": a refusal quotes no megabyte";
  }
  const FixCounters& a = c.counters().at("rsu_a");
  EXPECT_EQ(a.wrong_frame, 4u);
  EXPECT_EQ(a.bad_stamp, 1u);
  EXPECT_EQ(a.bad_covariance, 9u);
  EXPECT_EQ(a.passed_checks, 1u);
  EXPECT_EQ(a.received, 1u + cases.size());
}

// Each fix's covariance from its own fit (roadside/fix_covariance.hpp): a fix sent as less sure than the
// registry's figure for its LiDAR is taken with what it says, correlation included.
TEST(FixChecker, AFixSentAsLessSureThanItsLidarsFigureIsTakenWithItsOwnCovariance) {
  FixChecker c = acceptingUnaddressed("rsus:\n  - {id: rsu_a, position: [100, 0], lidar_model: VLP-16}\n");
  const FixVerdict v = c.check(sentFixWith(kNow - 1000, 0.04, 0.02, 0.01), kNow);
  ASSERT_TRUE(v.accepted()) << v.detail;
  EXPECT_EQ(v.measurement.covariance(0, 0), 0.04);
  EXPECT_EQ(v.measurement.covariance(1, 1), 0.02);
  EXPECT_EQ(v.measurement.covariance(0, 1), 0.01);
  EXPECT_TRUE(std::isinf(v.measurement.covariance(2, 2)));
}

TEST(FixChecker, ARegistryFrameOtherThanMapAndACalibratedVarianceAreHonoured) {
  FixChecker c = acceptingUnaddressed("map_frame: earth\nrsus:\n  - {id: rsu_a, position: [100, 0], lidar_model: VLP-16, calibrated_variance: 0.0004}\n");
  RsuFix fix = sentFix(kNow - 1000, 101);
  EXPECT_EQ(c.check(fix, kNow).rejection, FixRejection::kWrongFrame);
  fix.sent->frame_id = "earth";
  fix.stamp -= 1;
  // The vehicle's own measurement of this RSU replaces the LiDAR's figure the RSU sends.
  const FixVerdict v = c.check(fix, kNow);
  ASSERT_TRUE(v.accepted()) << v.detail;
  EXPECT_EQ(v.measurement.covariance(0, 0), 0.0004);
}

// A calibration replaces the LiDAR's figure, the floor an RSU raises each principal variance of its fit
// to, not what a fix says beyond it: a far car's fit sent as less sure than the figure keeps its own
// covariance, each principal variance at least the calibrated one.
TEST(FixChecker, ACalibratedRsusFixKeepsWhatItSaysBeyondItsLidarsFigure) {
  FixChecker published = acceptingUnaddressed("rsus:\n  - {id: rsu_a, position: [100, 0], lidar_model: VLP-16, calibrated_variance: 0.0004}\n");
  RsuFix at_figure = sentFix(kNow - 1000, 101);  // sent with the figure, 0.01486
  FixVerdict v = published.check(at_figure, kNow);
  ASSERT_TRUE(v.accepted()) << v.detail;
  EXPECT_NEAR(v.measurement.covariance(0, 0), 0.0004, 1e-15);
  EXPECT_NEAR(v.measurement.covariance(1, 1), 0.0004, 1e-15);
  EXPECT_NEAR(v.measurement.covariance(0, 1), 0.0, 1e-15);
  // Principal variances 0.0441 and 0.0159, both beyond the figure: kept as sent.
  v = published.check(sentFixWith(kNow - 900, 0.04, 0.02, 0.01), kNow);
  ASSERT_TRUE(v.accepted()) << v.detail;
  EXPECT_NEAR(v.measurement.covariance(0, 0), 0.04, 1e-12);
  EXPECT_NEAR(v.measurement.covariance(1, 1), 0.02, 1e-12);
  EXPECT_NEAR(v.measurement.covariance(0, 1), 0.01, 1e-12);
  // Only one direction beyond the figure (an RSU raised the other to it): that one kept, the other
  // the calibration's.
  v = published.check(sentFixWith(kNow - 850, 0.03, 0.01486, 0.0), kNow);
  ASSERT_TRUE(v.accepted()) << v.detail;
  EXPECT_NEAR(v.measurement.covariance(0, 0), 0.03, 1e-12);
  EXPECT_NEAR(v.measurement.covariance(1, 1), 0.0004, 1e-12);
  // In metres (figure 0.01486^2 = 0.000221) with a calibration of 10 cm: a fit of 20 / 1.7 cm keeps
  // its 20 cm, and the 1.7 cm, below the calibration, takes the calibration's 10.
  FixChecker metres = acceptingUnaddressed(
      "covariance_placement: standard_deviation\nrsus:\n  - {id: rsu_a, position: [100, 0], lidar_model: VLP-16, calibrated_variance: 0.01}\n");
  v = metres.check(sentFixWith(kNow - 800, 0.04, 0.0003, 0.0), kNow);
  ASSERT_TRUE(v.accepted()) << v.detail;
  EXPECT_NEAR(v.measurement.covariance(0, 0), 0.04, 1e-12);
  EXPECT_NEAR(v.measurement.covariance(1, 1), 0.01, 1e-12);
  EXPECT_TRUE(std::isinf(v.measurement.covariance(2, 2)));
}

// A calibration by range: the variance along the line of sight from the RSU and across it, each
// interpolated in range between its rows and held beyond the last, whichever way the line runs; a
// fit's own doubt beyond the figure stays where it exceeds what the calibration says along it.
TEST(FixChecker, ACalibrationByRangeGivesEachFixItsRangesErrorAlongAndAcrossItsLineOfSight) {
  FixChecker c = acceptingUnaddressed(
      "rsus:\n  - {id: rsu_a, position: [100, 0], lidar_model: VLP-16, coverage_radius: 50, calibrated_variance: 0.0004,\n"
      "     calibrated_error_by_range: [[5, 0.01, 0.03], [25, 0.01, 0.01], [45, 0.02, 0.08]]}\n");
  RsuFix east = sentFix(kNow - 1000, 135);  // 35 m east: across is y, halfway between 25 and 45 m
  FixVerdict v = c.check(east, kNow);
  ASSERT_TRUE(v.accepted()) << v.detail;
  EXPECT_NEAR(v.measurement.covariance(0, 0), (0.01 * 0.01 + 0.02 * 0.02) / 2.0, 1e-12);
  EXPECT_NEAR(v.measurement.covariance(1, 1), (0.01 * 0.01 + 0.08 * 0.08) / 2.0, 1e-12);
  EXPECT_NEAR(v.measurement.covariance(0, 1), 0.0, 1e-12);
  RsuFix north = sentFix(kNow - 900, 100);
  north.y = 48.0;  // 48 m north, beyond the last row: across is x
  v = c.check(north, kNow);
  ASSERT_TRUE(v.accepted()) << v.detail;
  EXPECT_NEAR(v.measurement.covariance(0, 0), 0.08 * 0.08, 1e-12);
  EXPECT_NEAR(v.measurement.covariance(1, 1), 0.02 * 0.02, 1e-12);
  RsuFix near = sentFix(kNow - 800, 102);  // 2 m, before the first row: that row's
  v = c.check(near, kNow);
  ASSERT_TRUE(v.accepted()) << v.detail;
  EXPECT_NEAR(v.measurement.covariance(0, 0), 0.01 * 0.01, 1e-12);
  EXPECT_NEAR(v.measurement.covariance(1, 1), 0.03 * 0.03, 1e-12);
  // Sent 45 m east with its fit's doubt along the line of sight (x: 0.03, beyond the VLP-16's figure
  // 0.01486) and the figure across: x keeps its 0.03, y takes the calibration's 0.0064.
  RsuFix doubted = sentFixWith(kNow - 700, 0.03, 0.01486, 0.0);
  doubted.x = 145.0;
  v = c.check(doubted, kNow);
  ASSERT_TRUE(v.accepted()) << v.detail;
  EXPECT_NEAR(v.measurement.covariance(0, 0), 0.03, 1e-12);
  EXPECT_NEAR(v.measurement.covariance(1, 1), 0.0064, 1e-12);
  EXPECT_NEAR(v.measurement.covariance(0, 1), 0.0, 1e-12);
}

TEST(FixChecker, DelayedAndLostFixesAreHandledAsTheFilterPromises) {
  // Fixes at 10 Hz from a vehicle standing at (105, 1): one arrives 0.4 s late, one is lost. The
  // filter applies the late one at its capture time: the result equals on-time delivery.
  fusion::EkfConfig config;
  config.auto_initialize = false;
  auto run = [&](bool delayed) {
    fusion::Localizer l(config);
    l.addPoseSource("rsu_a");
    PoseMeasurement start;
    start.stamp = kNow;
    start.pose.position = {104.5, 1.3, 0};
    start.covariance = Matrix6d::Zero();
    start.covariance.diagonal() << 0.5, 0.5, kInfinity, kInfinity, kInfinity, 0.1;
    l.initialize(start);
    FixChecker checker_local = checker();
    for (int k = 1; k <= 30; ++k) {
      const Stamp now = kNow + k * 20'000'000LL;
      l.advanceTo(now);
      if (k % 5 != 0 || k == 20) continue;  // 10 Hz; the fix of tick 20 is lost
      if (delayed && k == 10) continue;  // held back by the link
      const FixVerdict v = checker_local.check({now, "rsu_a", 105.0, 1.0, std::nullopt, std::nullopt, std::nullopt}, now);
      EXPECT_TRUE(l.feedPose("rsu_a", v.measurement).applied());
    }
    if (delayed) {  // the fix of tick 10 arrives now, at tick 30
      const FixVerdict v = checker_local.check({kNow + 10 * 20'000'000LL, "rsu_a", 105.0, 1.0, std::nullopt, std::nullopt, std::nullopt}, kNow + 30 * 20'000'000LL);
      EXPECT_TRUE(v.accepted());
      EXPECT_TRUE(l.feedPose("rsu_a", v.measurement).applied());
    }
    l.advanceTo(kNow + 40 * 20'000'000LL);
    return l.estimate()->state;
  };
  const Vector6d on_time = run(false), late = run(true);
  EXPECT_NEAR(on_time[0], 105.0, 0.05);
  EXPECT_NEAR(on_time[1], 1.0, 0.05);
  EXPECT_TRUE(on_time.isApprox(late, 1e-9) || (on_time - late).norm() < 1e-9);
}

}  // namespace
}  // namespace coloc::rsu_client

namespace coloc::rsu_client {
namespace {

TEST(FixChecker, ACalibratedRsusFixesAreCorrectedForItsSurveyAndClock) {
  // Surveyed at (30.15, -7.05), 0.5 deg and its clock 20 ms off: a vehicle truly at (20, -1) at t is
  // reported through the surveyed pose and stamped t + 20 ms; the calibration found on an earlier drive
  // undoes both.
  const RsuRegistry registry = RsuRegistry::parse(
      "rsus:\n  - {id: a, position: [30.15, -7.05], lidar_model: VLP-32C, "
      "calibration: {dx: 0.15, dy: -0.05, dyaw_deg: 0.5, clock_offset_ms: 20}}\n",
      "rsu.yaml");
  const Eigen::Vector2d truth(20.0, -1.0), rsu_true(30.0, -7.0), rsu_surveyed(30.15, -7.05);
  const Eigen::Vector2d reported = rsu_surveyed + Eigen::Rotation2Dd(0.5 * M_PI / 180.0) * (truth - rsu_true);
  const Stamp t = 1'700'000'000'000'000'000LL;
  FixCheckConfig checks;
  checks.station_id = 5;
  FixChecker checker(registry, checks);
  const FixVerdict v = checker.check({t + 20'000'000, "a", reported.x(), reported.y(), std::nullopt, std::nullopt, 5u}, t + 60'000'000);
  ASSERT_TRUE(v.accepted()) << v.detail;
  EXPECT_NEAR(v.measurement.pose.position.x(), truth.x(), 1e-9);
  EXPECT_NEAR(v.measurement.pose.position.y(), truth.y(), 1e-9);
  EXPECT_EQ(v.measurement.stamp, t);
  // And the registry writes it back as it read it.
  EXPECT_EQ(RsuRegistry::parse(registry.toYaml(), "again").toYaml(), registry.toYaml());
}

}  // namespace
}  // namespace coloc::rsu_client
