#include <gtest/gtest.h>

#include "motion_model.hpp"

namespace coloc::fusion {
namespace {

TEST(MotionModel, JacobianMatchesCentralDifferences) {
  Vector6d x;
  x << 3.0, -2.0, 0.7, 0.05, 8.0, 0.3;
  const double dt = 0.02, h = 1e-6;
  const Matrix6d A = motionJacobian(x, dt);
  for (int j = 0; j < 6; ++j) {
    Vector6d plus = x, minus = x;
    plus[j] += h;
    minus[j] -= h;
    const Vector6d column = (predictState(plus, dt) - predictState(minus, dt)) / (2 * h);
    for (int i = 0; i < 6; ++i) EXPECT_NEAR(A(i, j), column[i], 1e-8) << "A(" << i << "," << j << ")";
  }
}

TEST(MotionModel, PredictionMovesAlongBiasedHeadingAndWrapsYaw) {
  Vector6d x;
  x << 0.0, 0.0, M_PI - 0.01, 0.01, 10.0, 1.0;
  const Vector6d next = predictState(x, 0.1);
  EXPECT_NEAR(next[kX], -1.0, 1e-12);  // heading yaw + bias = pi
  EXPECT_NEAR(next[kY], 0.0, 1e-12);
  EXPECT_NEAR(next[kYaw], -M_PI + 0.09, 1e-12);
}

TEST(MotionModel, PredictionAndJacobianTogetherAreTheTwoApartToTheBit) {
  Vector6d x;
  x << 3.0, -2.0, 0.7, 0.05, 8.0, 0.3;
  Matrix6d A;
  const Vector6d next = predictState(x, 0.02, A);
  EXPECT_EQ(next, predictState(x, 0.02));
  EXPECT_EQ(A, motionJacobian(x, 0.02));
}

TEST(MotionModel, PropagatedCovarianceIsTheDenseProductForTheMotionJacobian) {
  // A covariance with every entry non-zero, so that a skipped term would show.
  Eigen::Matrix<double, 6, 6> G;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) G(i, j) = std::sin(1.0 + 7 * i + 3 * j);
  const Matrix6d P = G * G.transpose() + Matrix6d::Identity();
  const Matrix6d Q = processNoise({0.005, 10.0, 5.0}, 0.02);
  for (const double yaw : {0.0, 0.7, -2.5, M_PI}) {
    Vector6d x;
    x << 3.0, -2.0, yaw, 0.05, 8.0, 0.3;
    const Matrix6d A = motionJacobian(x, 0.02);
    const Matrix6d dense = A * P * A.transpose() + Q;
    const Matrix6d structured = propagateCovariance(A, P, Q);
    EXPECT_LT((structured - 0.5 * (dense + dense.transpose())).cwiseAbs().maxCoeff(), 1e-13 * P.cwiseAbs().maxCoeff()) << "yaw " << yaw;
    EXPECT_EQ(structured, structured.transpose());
  }
}

TEST(MotionModel, ProcessNoiseIsAutowaresDiagonal) {
  const Matrix6d Q = processNoise({0.005, 10.0, 5.0}, 0.02);
  Vector6d expected;
  expected << 0, 0, 1e-8, 0, 0.04, 0.01;
  EXPECT_TRUE(Q.diagonal().isApprox(expected, 1e-12));
  EXPECT_EQ((Q - Matrix6d(Q.diagonal().asDiagonal())).norm(), 0.0);
}

}  // namespace
}  // namespace coloc::fusion
