// Every kind of bad input is refused with a reason that names it, counted, and leaves the filter's
// state bit for bit as it was.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>

#include "coloc/core/error.hpp"
#include "drive.hpp"

namespace coloc::fusion {
namespace {

using namespace coloc::testing;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kNow = 40;

struct BadPose {
  const char* name;
  std::function<void(PoseMeasurement&)> spoil;
  Reason reason;
  const char* says;  // a phrase the message must contain
};

void PrintTo(const BadPose& b, std::ostream* os) { *os << b.name; }

class BadPoseInput : public ::testing::TestWithParam<BadPose> {};

Localizer drivenLocalizer() {
  const Drive drive;
  Localizer localizer = startedLocalizer();
  for (int k = 1; k <= kNow; ++k) {
    driveTick(localizer, drive, k);
    if (k % 5 == 0) localizer.feedPose("ndt", ndtPoseAt(drive, k - 2));
  }
  return localizer;
}

std::uint64_t rejectionsOf(const SourceCounters& c, Reason reason) {
  switch (reason) {
    case Reason::kInvalid: return c.invalid;
    case Reason::kTooOld: return c.too_old;
    case Reason::kFromFuture: return c.from_future;
    case Reason::kNotInitialized: return c.not_initialized;
    case Reason::kGated: return c.gated;
    default: return 0;
  }
}

TEST_P(BadPoseInput, IsRejectedWithItsReasonAndLeavesTheStateBitIdentical) {
  const BadPose& bad = GetParam();
  Localizer localizer = drivenLocalizer();
  const Snapshot before = snapshot(localizer);
  PoseMeasurement m = ndtPoseAt(Drive{}, kNow - 2);
  bad.spoil(m);
  const SourceId ndt = *localizer.findSource("ndt");
  const std::uint64_t count_before = rejectionsOf(localizer.counters(ndt), bad.reason);
  const Verdict v = localizer.feedPose(ndt, m);
  EXPECT_TRUE(v.rejected());
  EXPECT_EQ(v.reason, bad.reason) << v.message();
  EXPECT_NE(v.message().find(bad.says), std::string::npos) << v.message();
  EXPECT_NE(v.message().find("'ndt'"), std::string::npos) << "the message must name the source: " << v.message();
  EXPECT_EQ(rejectionsOf(localizer.counters(ndt), bad.reason), count_before + 1);
  EXPECT_TRUE(snapshot(localizer) == before);
  // And the filter still works afterwards.
  EXPECT_TRUE(localizer.feedPose(ndt, ndtPoseAt(Drive{}, kNow - 1)).applied());
}

const BadPose kBadPoses[] = {
    {"NaNPosition", [](PoseMeasurement& m) { m.pose.position.x() = kNaN; }, Reason::kInvalid, "x is not finite"},
    {"InfinitePosition", [](PoseMeasurement& m) { m.pose.position.y() = kInfinity; }, Reason::kInvalid, "y is not finite"},
    {"NaNQuaternion", [](PoseMeasurement& m) { m.pose.orientation.w() = kNaN; }, Reason::kInvalid, "quaternion is not finite"},
    {"NonUnitQuaternion", [](PoseMeasurement& m) { m.pose.orientation.coeffs() *= 2.0; }, Reason::kInvalid, "norm"},
    {"NaNVariance", [](PoseMeasurement& m) { m.covariance(0, 0) = kNaN; }, Reason::kInvalid, "NaN"},
    {"NaNCovariance", [](PoseMeasurement& m) { m.covariance(1, 0) = kNaN; }, Reason::kInvalid, "NaN"},
    {"NegativeVariance", [](PoseMeasurement& m) { m.covariance(1, 1) = -0.01; }, Reason::kInvalid, "positive"},
    {"NegativeInfiniteVariance", [](PoseMeasurement& m) { m.covariance(5, 5) = -kInfinity; }, Reason::kInvalid, "positive"},
    {"ZeroVariance", [](PoseMeasurement& m) { m.covariance(0, 0) = 0.0; }, Reason::kInvalid, "positive"},
    {"InfiniteCovarianceBetweenMeasured", [](PoseMeasurement& m) { m.covariance(0, 1) = m.covariance(1, 0) = kInfinity; },
     Reason::kInvalid, "finite"},
    {"AsymmetricCovariance", [](PoseMeasurement& m) { m.covariance(0, 1) = 0.01; }, Reason::kInvalid, "symmetric"},
    {"NotPositiveDefinite", [](PoseMeasurement& m) { m.covariance(0, 1) = m.covariance(1, 0) = 0.05; },
     Reason::kInvalid, "positive definite"},
    {"MeasuresNothing", [](PoseMeasurement& m) { m.covariance.diagonal().setConstant(kInfinity); }, Reason::kInvalid,
     "measures no component"},
    {"StampFromTheFuture", [](PoseMeasurement& m) { m.stamp = kStart + (kNow + 10) * kTick; }, Reason::kFromFuture,
     "ahead of the clock"},
    {"StampTooOld", [](PoseMeasurement& m) { m.stamp = kStart - 5 * kNanosPerSecond; }, Reason::kTooOld, "behind"},
    {"OutlierFarFromTheEstimate", [](PoseMeasurement& m) { m.pose.position.x() += 50.0; }, Reason::kGated, "Mahalanobis"},
};

INSTANTIATE_TEST_SUITE_P(Poses, BadPoseInput, ::testing::ValuesIn(kBadPoses),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(BadInput, TwistWithNaNSpeedIsRejectedAndStateUnchanged) {
  Localizer localizer = drivenLocalizer();
  const Snapshot before = snapshot(localizer);
  const Verdict v = localizer.feedTwist("odom", twist(kStart + kNow * kTick, kNaN, 0.1));
  EXPECT_EQ(v.reason, Reason::kInvalid);
  EXPECT_NE(v.message().find("vx is not finite"), std::string::npos) << v.message();
  EXPECT_TRUE(snapshot(localizer) == before);
}

TEST(BadInput, TwistWithNegativeVarianceIsRejectedAndStateUnchanged) {
  Localizer localizer = drivenLocalizer();
  const Snapshot before = snapshot(localizer);
  const Verdict v = localizer.feedTwist("odom", twist(kStart + kNow * kTick, 8.0, 0.1, -1.0));
  EXPECT_EQ(v.reason, Reason::kInvalid);
  EXPECT_TRUE(snapshot(localizer) == before);
  EXPECT_EQ(localizer.counters(*localizer.findSource("odom")).invalid, 1u);
}

TEST(BadInput, UnknownSourceIsRejectedCountedAndStateUnchanged) {
  Localizer localizer = drivenLocalizer();
  const Snapshot before = snapshot(localizer);
  const Verdict v = localizer.feedPose("rsu_99", ndtPoseAt(Drive{}, kNow));
  EXPECT_EQ(v.reason, Reason::kUnknownSource);
  EXPECT_EQ(localizer.unknownSourceCount(), 1u);
  EXPECT_EQ(localizer.feedPose(SourceId{42}, ndtPoseAt(Drive{}, kNow)).reason, Reason::kUnknownSource);
  EXPECT_EQ(localizer.unknownSourceCount(), 2u);
  EXPECT_TRUE(snapshot(localizer) == before);
}

TEST(BadInput, ClockGoingBackwardsIsRejectedAndStateUnchanged) {
  Localizer localizer = drivenLocalizer();
  const Snapshot before = snapshot(localizer);
  const Verdict v = localizer.advanceTo(kStart + (kNow - 3) * kTick);
  EXPECT_EQ(v.reason, Reason::kClockBackwards);
  EXPECT_NE(v.message().find("before the previous"), std::string::npos) << v.message();
  EXPECT_TRUE(snapshot(localizer) == before);
}

TEST(BadInput, AClockJumpFarAheadIsRejectedAsAJumpNotAsGoingBackwards) {
  Localizer localizer = drivenLocalizer();
  const Snapshot before = snapshot(localizer);
  const Verdict v = localizer.advanceTo(kStart + 400'000 * kNanosPerSecond);  // ~4.6 days of 50 Hz ticks
  EXPECT_EQ(v.reason, Reason::kClockJump);
  EXPECT_NE(v.message().find("prediction ticks"), std::string::npos) << v.message();
  EXPECT_TRUE(snapshot(localizer) == before);
}

TEST(BadInput, MeasurementsBeforeInitialisationAreCountedNotApplied) {
  EkfConfig config;  // auto-initialisation on: a planar pose would start the filter, these cannot
  Localizer localizer(config);
  localizer.addPoseSource("rsu");
  localizer.addTwistSource("odom");
  EXPECT_EQ(localizer.feedTwist("odom", twist(kStart, 5.0, 0.0)).reason, Reason::kNotInitialized);
  EXPECT_EQ(localizer.feedPose("rsu", fix2d(kStart, 1.0, 2.0, 0.01)).reason, Reason::kNotInitialized);
  EXPECT_FALSE(localizer.initialized());
  EXPECT_FALSE(localizer.estimate().has_value());
  EXPECT_EQ(localizer.counters(*localizer.findSource("rsu")).not_initialized, 1u);
}

TEST(BadInput, FirstPlanarPoseInitialisesTheFilterWhenAutoInitialisationIsOn) {
  Localizer localizer;
  localizer.addPoseSource("ndt");
  EXPECT_TRUE(localizer.feedPose("ndt", planarPose(kStart, 3.0, 4.0, 0.5)).applied());
  ASSERT_TRUE(localizer.initialized());
  EXPECT_EQ(localizer.estimate()->state[0], 3.0);
}

TEST(BadInput, InitialPoseWithoutYawIsRejected) {
  Localizer localizer(quietConfig());
  const Verdict v = localizer.initialize(fix2d(kStart, 1.0, 2.0, 0.01));
  EXPECT_TRUE(v.rejected());
  EXPECT_FALSE(localizer.initialized());
}

TEST(BadConfig, OutOfRangeValueThrowsNamingTheKey) {
  EkfConfig config;
  config.predict_frequency = -50.0;
  try {
    Localizer localizer(config);
    FAIL() << "expected coloc::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("predict_frequency"), std::string::npos) << e.what();
  }
  config = {};
  config.pose_gate_alpha = 1.5;
  EXPECT_THROW(Localizer{config}, Error);
  config = {};
  config.proc_stddev_vx_c = kNaN;
  EXPECT_THROW(Localizer{config}, Error);
}

}  // namespace
}  // namespace coloc::fusion
