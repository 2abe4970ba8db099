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

TEST(MotionModel, ProcessNoiseIsAutowaresDiagonal) {
  const Matrix6d Q = processNoise({0.005, 10.0, 5.0}, 0.02);
  Vector6d expected;
  expected << 0, 0, 1e-8, 0, 0.04, 0.01;
  EXPECT_TRUE(Q.diagonal().isApprox(expected, 1e-12));
  EXPECT_EQ((Q - Matrix6d(Q.diagonal().asDiagonal())).norm(), 0.0);
}

}  // namespace
}  // namespace coloc::fusion
