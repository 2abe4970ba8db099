#include "coloc/smoother/smoother.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace coloc::smoother {
namespace {

constexpr Stamp kStart = 1'700'000'000'000'000'000LL;
constexpr double kSpeed = 10.0;  // m/s along x

Stamp at(double t) { return kStart + fromSeconds(t); }

Vector6d truth(double t) { return (Vector6d() << kSpeed * t, 0.0, 0.0, 0.0, kSpeed, 0.0).finished(); }

PoseMeasurement fix(double t, double x, double y, double variance) {
  PoseMeasurement m;
  m.stamp = at(t);
  m.pose.position = {x, y, 0.0};
  m.covariance = Matrix6d::Zero();
  m.covariance.diagonal() << variance, variance, kInfinity, kInfinity, kInfinity, kInfinity;
  return m;
}

TwistMeasurement twist(double t) {
  TwistMeasurement m;
  m.stamp = at(t);
  m.linear = {kSpeed, 0.0, 0.0};
  m.covariance = Matrix6d::Zero();
  m.covariance.diagonal() << 0.04, kInfinity, kInfinity, kInfinity, kInfinity, 0.01;
  return m;
}

// Two seconds of driving: twists at 50 Hz, a heading from a yaw-only pose at the start, guesses 30 cm
// off the truth, and fixes every 100 ms stamped half-way between two states.
Smoother drive(double fix_variance) {
  Smoother s;
  for (int k = 0; k <= 100; ++k) {
    s.addTwist("odom", twist(k * 0.02));
    Vector6d g = truth(k * 0.02);
    g[0] += 0.3;
    s.addGuess(at(k * 0.02), g);
  }
  PoseMeasurement heading;
  heading.stamp = at(0.0);
  heading.covariance = Matrix6d::Zero();
  heading.covariance.diagonal() << kInfinity, kInfinity, kInfinity, kInfinity, kInfinity, 1e-6;
  EXPECT_TRUE(s.addPose("heading", heading));
  for (int k = 0; k < 20; ++k) {
    const double t = 0.1 * k + 0.01;
    EXPECT_TRUE(s.addPose("rsu", fix(t, kSpeed * t, 0.0, fix_variance)));
  }
  return s;
}

TEST(Smoother, AFixIsComparedWithTheStateAtItsExactStamp) {
  // Fixes 10 ms after a state: at the nearest state they would pull the track 10 cm back.
  const SmootherResult r = drive(1e-6).solve(at(0.0), at(2.0));
  ASSERT_TRUE(r.summary.usable()) << r.summary.report;
  EXPECT_EQ(r.summary.states, 101);
  for (const SmoothedState& s : r.states) {
    const double t = toSeconds(s.stamp - kStart);
    EXPECT_NEAR(s.state[0], kSpeed * t, 0.005) << "at " << t << " s";
    EXPECT_NEAR(s.state[1], 0.0, 0.005) << "at " << t << " s";
  }
}

TEST(Smoother, AnInfiniteVarianceLeavesItsComponentOutExactly) {
  Smoother s = drive(1e-6);
  // A measurement of x only, with a y 5 m off: y must not move at all.
  PoseMeasurement only_x = fix(1.05, kSpeed * 1.05, 5.0, 1e-6);
  only_x.covariance(1, 1) = kInfinity;
  ASSERT_TRUE(s.addPose("x only", only_x));
  const SmootherResult r = s.solve(at(0.0), at(2.0));
  for (const SmoothedState& st : r.states) EXPECT_NEAR(st.state[1], 0.0, 0.005);
  // A measurement of nothing planar is refused, not added as a big number.
  PoseMeasurement nothing = only_x;
  nothing.covariance(0, 0) = kInfinity;
  EXPECT_FALSE(s.addPose("nothing", nothing));
}

TEST(Smoother, AGrossOutlierIsDownWeightedAndReported) {
  Smoother s = drive(1e-4);
  ASSERT_TRUE(s.addPose("rsu", fix(1.01, kSpeed * 1.01 + 3.0, 0.0, 1e-4)));  // a fix 3 m off
  const SmootherResult r = s.solve(at(0.0), at(2.0));
  ASSERT_TRUE(r.summary.usable()) << r.summary.report;
  const SmoothedState& near = r.states[50];  // t = 1.0 s
  EXPECT_NEAR(near.state[0], kSpeed * 1.0, 0.03);
  bool reported = false;
  for (const DownWeighted& d : r.summary.down_weighted)
    if (d.source == "rsu" && d.stamp == at(1.01)) reported = d.weight < 0.1;
  EXPECT_TRUE(reported);
}

TEST(Smoother, PositionsAreMostCertainWhereTheFixesAre) {
  Smoother s;
  for (int k = 0; k <= 100; ++k) {
    s.addTwist("odom", twist(k * 0.02));
    s.addGuess(at(k * 0.02), truth(k * 0.02));
  }
  ASSERT_TRUE(s.addPose("rsu", fix(0.2, kSpeed * 0.2, 0.0, 1e-4)));
  PoseMeasurement heading;  // the yaw, which no fix measures: without it the positions' covariance is not defined
  heading.stamp = at(0.0);
  heading.covariance = Matrix6d::Zero();
  heading.covariance.diagonal() << kInfinity, kInfinity, kInfinity, kInfinity, kInfinity, 1e-6;
  ASSERT_TRUE(s.addPose("heading", heading));
  const SmootherResult r = s.solve(at(0.0), at(2.0));
  ASSERT_TRUE(r.states[10].position_covariance && r.states[100].position_covariance);
  EXPECT_LT((*r.states[10].position_covariance)(0, 0), (*r.states[100].position_covariance)(0, 0));
  EXPECT_NEAR(std::sqrt((*r.states[10].position_covariance)(0, 0)), 0.01, 0.005);
}

TEST(Smoother, ChiSquareQuantilesMatchTheTables) {
  EXPECT_NEAR(chiSquareQuantile(1, 0.05), 3.841, 1e-3);
  EXPECT_NEAR(chiSquareQuantile(2, 0.05), 5.991, 1e-3);
  EXPECT_NEAR(chiSquareQuantile(3, 0.01), 11.345, 1e-3);
}

}  // namespace
}  // namespace coloc::smoother
