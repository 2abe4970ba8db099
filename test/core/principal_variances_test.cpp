#include "coloc/core/principal_variances.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

namespace coloc {
namespace {

// The smallest variance of a 2x2 covariance in any direction.
double smallest(const Eigen::Matrix2d& m) { return Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(m).eigenvalues()[0]; }

TEST(PrincipalVariances, ACoveringIsAtLeastTheCovarianceAndTheFloorInEveryDirection) {
  // A fit sure along x and unsure along y; a floor turned 30 deg, large along its own x.
  const Eigen::Matrix2d covariance = Eigen::Vector2d(1e-6, 4e-4).asDiagonal();
  const Eigen::Matrix2d turn = Eigen::Rotation2Dd(M_PI / 6.0).toRotationMatrix();
  const Eigen::Matrix2d floor = turn * Eigen::Vector2d(1e-4, 1e-6).asDiagonal() * turn.transpose();
  const Eigen::Matrix2d c = coveringAtLeast(covariance, floor);
  EXPECT_GE(smallest(c - covariance), -1e-18);
  EXPECT_GE(smallest(c - floor), -1e-18);
  // No more than it must: along the floor's wide axis it is what the covariance and the floor need.
  EXPECT_LE((c - covariance).norm(), (floor - covariance).cwiseAbs().sum());
  // Already above the floor: unchanged; a round floor: principalVariancesAtLeast.
  EXPECT_LT((coveringAtLeast(covariance + floor, floor) - (covariance + floor)).norm(), 1e-18);
  EXPECT_LT((coveringAtLeast(covariance, 1e-4 * Eigen::Matrix2d::Identity()) - principalVariancesAtLeast(covariance, 1e-4)).norm(), 1e-15);
}

}  // namespace
}  // namespace coloc
