#include <gtest/gtest.h>

#include <cmath>

#include "drive.hpp"

namespace coloc::fusion {
namespace {

using namespace coloc::testing;

// Right after initialisation the covariance is diagonal, so S = P + R is diagonal and an innovation of
// k standard deviations of S along x has squared Mahalanobis distance exactly k^2.
PoseMeasurement offsetAlongX(Localizer& localizer, double sigmas) {
  const Estimate e = *localizer.estimate();
  const PoseMeasurement base = planarPose(e.stamp, e.state[0], e.state[1], e.state[2]);
  const double s_xx = e.state_covariance(0, 0) + base.covariance(0, 0);
  PoseMeasurement m = base;
  m.pose.position.x() += sigmas * std::sqrt(s_xx);
  return m;
}

TEST(Gate, RejectsATenSigmaOutlierAndLeavesTheStateUnchanged) {
  Localizer localizer = startedLocalizer();
  const Snapshot before = snapshot(localizer);
  const Verdict v = localizer.feedPose("ndt", offsetAlongX(localizer, 10.0));
  EXPECT_EQ(v.reason, Reason::kGated) << v.message();
  EXPECT_NEAR(v.mahalanobis_squared, 100.0, 1e-9);
  EXPECT_TRUE(snapshot(localizer) == before);
  EXPECT_EQ(localizer.counters(*localizer.findSource("ndt")).gated, 1u);
}

TEST(Gate, AcceptsAOneSigmaMeasurement) {
  Localizer localizer = startedLocalizer();
  const Verdict v = localizer.feedPose("ndt", offsetAlongX(localizer, 1.0));
  EXPECT_TRUE(v.applied()) << v.message();
  EXPECT_NEAR(v.mahalanobis_squared, 1.0, 1e-9);
}

TEST(Gate, ComparesTheSquaredDistanceWithTheChiSquareQuantile) {
  // 7 sigma: d^2 = 49 just under the 3-dof quantile 49.5 at alpha 1e-10; 7.1 sigma (50.4) just over.
  // Autoware compares the unsquared distance (7) with 49.5 and would accept both.
  Localizer accept = startedLocalizer(), reject = startedLocalizer();
  EXPECT_TRUE(accept.feedPose("ndt", offsetAlongX(accept, 7.0)).applied());
  EXPECT_EQ(reject.feedPose("ndt", offsetAlongX(reject, 7.1)).reason, Reason::kGated);
}

TEST(Gate, IncludesTheMeasurementCovarianceInS) {
  // The same innovation passes when the measurement says it is uncertain: S = H P H^T + R.
  Localizer localizer = startedLocalizer();
  PoseMeasurement m = offsetAlongX(localizer, 10.0);
  m.covariance(0, 0) = 100.0;
  EXPECT_TRUE(localizer.feedPose("ndt", m).applied());
}

TEST(Gate, TwistGateRejectsAnImpossibleSpeed) {
  Localizer localizer = startedLocalizer();
  const Verdict v = localizer.feedTwist("odom", twist(kStart, 300.0, 0.0, 0.01, 0.01));
  EXPECT_EQ(v.reason, Reason::kGated) << v.message();
}

}  // namespace
}  // namespace coloc::fusion
