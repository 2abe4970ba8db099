#include <gtest/gtest.h>

#include <cstring>

#include "measurement_record.hpp"
#include "measurement_update.hpp"
#include "motion_model.hpp"
#include "measurements.hpp"

namespace coloc::fusion {
namespace {

using testing::fix2d;
using testing::planarPose;

FilterState stateWithCovariance(const Matrix6d& P) {
  FilterState s;
  s.x << 10.0, 20.0, 0.4, 0.0, 5.0, 0.1;
  s.P = P;
  return s;
}

UpdateRecord recordOf(const PoseMeasurement& m) { return std::get<UpdateRecord>(makePoseRecord(m)); }

TEST(InfiniteVariance, RsuFixWithUncorrelatedYawLeavesYawAndItsVarianceBitIdentical) {
  Matrix6d P = Matrix6d::Zero();
  P.diagonal() << 0.5, 0.4, 0.01, 1e-4, 0.2, 0.05;
  P(kX, kY) = P(kY, kX) = 0.1;  // x-y correlation is fine, yaw has none with them
  P(kVx, kWz) = P(kWz, kVx) = 0.01;
  FilterState s = stateWithCovariance(P);
  const FilterState before = s;
  const UpdateRecord r = recordOf(fix2d(0, 10.3, 19.8, 0.01486));
  ASSERT_EQ(r.m, 2);
  ASSERT_TRUE(applyUpdate(s, r));
  EXPECT_NE(s.x[kX], before.x[kX]);
  EXPECT_NE(s.x[kY], before.x[kY]);
  for (int i : {kYaw, kYawBias, kVx, kWz}) {
    EXPECT_EQ(s.x[i], before.x[i]) << "state " << i;
    for (int j : {kYaw, kYawBias, kVx, kWz}) EXPECT_EQ(s.P(i, j), before.P(i, j)) << "P(" << i << "," << j << ")";
  }
  for (int a = 0; a < 3; ++a) EXPECT_FALSE(s.aux[a].initialized) << "z / roll / pitch must not be touched";
}

TEST(InfiniteVariance, RsuFixMovesYawOnlyThroughItsCorrelationWithPosition) {
  Matrix6d P = Matrix6d::Zero();
  P.diagonal() << 0.5, 0.4, 0.01, 1e-4, 0.2, 0.05;
  P(kX, kYaw) = P(kYaw, kX) = 0.03;
  P(kY, kYaw) = P(kYaw, kY) = -0.02;
  FilterState s = stateWithCovariance(P);
  const FilterState before = s;
  const double sigma = 0.01486;
  const UpdateRecord r = recordOf(fix2d(0, 10.3, 19.8, sigma));
  ASSERT_TRUE(applyUpdate(s, r));
  // Closed form of the 2-D update: yaw moves by P_yaw,xy S^-1 e and its variance by P_yaw,xy S^-1 P_xy,yaw.
  Eigen::Matrix2d S = P.topLeftCorner<2, 2>() + sigma * Eigen::Matrix2d::Identity();
  const Eigen::Vector2d e(0.3, -0.2);
  const Eigen::RowVector2d p_yaw_xy = P.block<1, 2>(kYaw, 0);
  EXPECT_NEAR(s.x[kYaw] - before.x[kYaw], p_yaw_xy * S.inverse() * e, 1e-14);
  EXPECT_NEAR(before.P(kYaw, kYaw) - s.P(kYaw, kYaw), p_yaw_xy * S.inverse() * p_yaw_xy.transpose(), 1e-14);
}

TEST(InfiniteVariance, PoseWithInfiniteYawBuildsATwoComponentRecord) {
  const UpdateRecord r = recordOf(fix2d(0, 1.0, 2.0, 0.00681));
  EXPECT_EQ(r.m, 2);
  EXPECT_EQ(r.index[0], kX);
  EXPECT_EQ(r.index[1], kY);
  EXPECT_EQ(r.aux_mask, 0);
  EXPECT_EQ(r.R(0, 0), 0.00681);
}

TEST(InfiniteVariance, FullPoseFeedsAuxFiltersForZRollPitch) {
  PoseMeasurement m = planarPose(0, 1.0, 2.0, 0.3);
  m.pose.position.z() = 1.5;
  m.covariance(2, 2) = 0.0225;
  m.covariance(3, 3) = m.covariance(4, 4) = 0.000625;
  const UpdateRecord r = recordOf(m);
  EXPECT_EQ(r.m, 3);
  EXPECT_EQ(r.aux_mask, 7);
  EXPECT_NEAR(r.value[2], 0.3, 1e-12);
  EXPECT_EQ(r.aux_value[0], 1.5);
}

TEST(MeasurementUpdate, UpdateWithSmallerVarianceMovesStateStrictlyBetweenPriorAndMeasurement) {
  Matrix6d P = Matrix6d::Identity() * 0.1;
  FilterState s = stateWithCovariance(P);
  ASSERT_TRUE(applyUpdate(s, recordOf(planarPose(0, 11.0, 21.0, 0.5, 0.1, 0.1))));
  EXPECT_NEAR(s.x[kX], 10.5, 1e-12);  // equal variances: half-way
  EXPECT_NEAR(s.x[kY], 20.5, 1e-12);
  EXPECT_NEAR(s.x[kYaw], 0.45, 1e-12);
  EXPECT_NEAR(s.P(kX, kX), 0.05, 1e-12);
}

TEST(MeasurementUpdate, YawInnovationIsWrappedAcrossPi) {
  Matrix6d P = Matrix6d::Identity() * 0.1;
  FilterState s = stateWithCovariance(P);
  s.x[kYaw] = M_PI - 0.05;
  ASSERT_TRUE(applyUpdate(s, recordOf(planarPose(0, 10.0, 20.0, -M_PI + 0.05, 0.1, 0.1))));
  EXPECT_NEAR(wrapAngle(s.x[kYaw] - M_PI), 0.0, 1e-9);  // half-way along the short arc, not through zero
}

}  // namespace
}  // namespace coloc::fusion
