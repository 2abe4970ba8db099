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

TEST(PrincipalVariances, ACoverIsAtMostTheCeilingWhereTheCovarianceExceedsItAndUnchangedElsewhere) {
  // A fit unsure along y (0.3 m^2, probes half a metre apart that see nothing there) and sure along
  // x; a ceiling turned 30 deg, 4e-4 along its x and 1e-6 across.
  const Eigen::Matrix2d covariance = Eigen::Vector2d(1e-6, 0.3).asDiagonal();
  const Eigen::Matrix2d turn = Eigen::Rotation2Dd(M_PI / 6.0).toRotationMatrix();
  const Eigen::Matrix2d ceiling = turn * Eigen::Vector2d(4e-4, 1e-6).asDiagonal() * turn.transpose();
  const Eigen::Matrix2d c = coveredAtMost(covariance, ceiling);
  EXPECT_GE(smallest(ceiling - c), -1e-15) << "at most the ceiling in every direction";
  EXPECT_GE(smallest(covariance - c), -1e-14) << "and at most the covariance (to rounding: 0.3 m^2 whitened by 1e-6)";
  EXPECT_GE(smallest(c), -1e-18) << "still a covariance";
  // Where the two cross, the largest such: along the ceiling's narrow axis it is the ceiling's 1e-6.
  const Eigen::Vector2d narrow = turn.col(1);
  EXPECT_NEAR(narrow.dot(c * narrow), 1e-6, 1e-7);
  // Already below: unchanged; a round ceiling on a round covariance: the smaller.
  const Eigen::Matrix2d small = Eigen::Vector2d(1e-7, 2e-7).asDiagonal();
  EXPECT_LT((coveredAtMost(small, 1e-4 * Eigen::Matrix2d::Identity()) - small).norm(), 1e-20);
  EXPECT_LT((coveredAtMost(0.5 * Eigen::Matrix2d::Identity(), 0.1 * Eigen::Matrix2d::Identity()) - 0.1 * Eigen::Matrix2d::Identity()).norm(), 1e-15);
  // Axis-aligned: each variance the smaller of the two.
  const Eigen::Matrix2d aligned = coveredAtMost(covariance, Eigen::Vector2d(1e-4, 1e-2).asDiagonal().toDenseMatrix());
  EXPECT_NEAR(aligned(0, 0), 1e-6, 1e-18);
  EXPECT_NEAR(aligned(1, 1), 1e-2, 1e-15);
}

}  // namespace
}  // namespace coloc
