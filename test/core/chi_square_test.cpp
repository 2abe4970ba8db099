#include <gtest/gtest.h>

#include "coloc/core/chi_square.hpp"

namespace coloc {
namespace {

TEST(ChiSquare, QuantileAtAutowareAlphaGivesItsGateValues) {
  // Autoware's pose_gate_dist 49.5 and twist_gate_dist 46.1 are these quantiles.
  EXPECT_NEAR(chiSquareQuantile(3, 1e-10), 49.5, 0.05);
  EXPECT_NEAR(chiSquareQuantile(2, 1e-10), 46.05, 0.01);
}

TEST(ChiSquare, QuantileMatchesTextbookValues) {
  EXPECT_NEAR(chiSquareQuantile(1, 0.05), 3.841459, 1e-5);
  EXPECT_NEAR(chiSquareQuantile(2, 0.05), 5.991465, 1e-5);
  EXPECT_NEAR(chiSquareQuantile(3, 0.01), 11.344867, 1e-5);
  EXPECT_NEAR(chiSquareQuantile(6, 0.001), 22.457744, 1e-5);
}

TEST(ChiSquare, SurvivalInvertsQuantile) {
  for (int dof = 1; dof <= 6; ++dof)
    for (double alpha : {0.5, 1e-3, 1e-10}) EXPECT_NEAR(chiSquareSurvival(dof, chiSquareQuantile(dof, alpha)) / alpha, 1.0, 1e-8);
}

TEST(ChiSquare, RejectsDimensionsAndProbabilitiesOutOfRange) {
  EXPECT_THROW(chiSquareQuantile(0, 0.1), std::invalid_argument);
  EXPECT_THROW(chiSquareQuantile(2, 0.0), std::invalid_argument);
  EXPECT_THROW(chiSquareQuantile(2, 1.0), std::invalid_argument);
}

}  // namespace
}  // namespace coloc
