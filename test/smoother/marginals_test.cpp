#include "marginals.hpp"

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <random>

namespace coloc::smoother {
namespace {

// Residuals of a chain: each state measured alone, neighbours tied together, and some states tied to
// a global block, all with random linear Jacobians (plus a Huber loss on a few, active at the point).
struct Linear : ceres::CostFunction {
  std::vector<Eigen::MatrixXd> jacobians;
  explicit Linear(std::vector<Eigen::MatrixXd> j) : jacobians(std::move(j)) {
    set_num_residuals(static_cast<int>(jacobians[0].rows()));
    for (const auto& m : jacobians) mutable_parameter_block_sizes()->push_back(static_cast<int>(m.cols()));
  }
  bool Evaluate(double const* const* p, double* r, double** J) const override {
    Eigen::Map<Eigen::VectorXd> res(r, num_residuals());
    res.setConstant(0.3);  // off the minimum, so that a Huber loss is past its knee
    for (std::size_t b = 0; b < jacobians.size(); ++b) {
      res += jacobians[b] * Eigen::Map<const Eigen::VectorXd>(p[b], jacobians[b].cols());
      if (J && J[b]) Eigen::Map<Eigen::Matrix<double, -1, -1, Eigen::RowMajor>>(J[b], num_residuals(), jacobians[b].cols()) = jacobians[b];
    }
    return true;
  }
};

TEST(ChainMarginals, EqualCeresOwnCovarianceOnAChainWithGlobalBlocks) {
  std::mt19937 rng(7);
  std::normal_distribution<double> g;
  auto random = [&](int r, int c) { return Eigen::MatrixXd::NullaryExpr(r, c, [&] { return g(rng); }).eval(); };
  const int n = 40;
  std::vector<std::vector<double>> states(n, std::vector<double>(6, 0.0));
  std::vector<double> global(4, 0.0), held(4, 0.0);
  ceres::Problem problem;
  for (int k = 0; k < n; ++k) {
    problem.AddResidualBlock(new Linear({random(3, 6)}), k % 5 == 0 ? new ceres::HuberLoss(0.5) : nullptr, states[k].data());
    if (k + 1 < n) problem.AddResidualBlock(new Linear({random(6, 6), random(6, 6)}), nullptr, states[k].data(), states[k + 1].data());
    if (k % 7 == 3) problem.AddResidualBlock(new Linear({random(2, 6), random(2, 4)}), nullptr, states[k].data(), global.data());
    if (k % 9 == 4) problem.AddResidualBlock(new Linear({random(2, 6), random(2, 4)}), nullptr, states[k].data(), held.data());
  }
  problem.SetManifold(held.data(), new ceres::SubsetManifold(4, {3}));  // a global with a held component

  std::vector<double*> chain;
  for (auto& s : states) chain.push_back(s.data());
  const ChainMarginals fast = chainMarginals(problem, chain, {global.data(), held.data()}, 1, 6);
  ASSERT_TRUE(fast.ok);
  ASSERT_TRUE(fast.globals);

  ceres::Covariance::Options o;
  o.algorithm_type = ceres::DENSE_SVD;
  ceres::Covariance reference(o);
  std::vector<std::pair<const double*, const double*>> wanted;
  for (double* s : chain) wanted.emplace_back(s, s);
  wanted.emplace_back(global.data(), global.data());
  wanted.emplace_back(held.data(), held.data());
  ASSERT_TRUE(reference.Compute(wanted, &problem));
  for (int k = 0; k < n; ++k) {
    Eigen::Matrix<double, 6, 6, Eigen::RowMajor> c;
    reference.GetCovarianceBlock(chain[k], chain[k], c.data());
    EXPECT_LT((fast.states[k] - c).norm(), 1e-9 * (1.0 + c.norm())) << "state " << k;
  }
  Eigen::Matrix<double, 4, 4, Eigen::RowMajor> cg, ch;
  reference.GetCovarianceBlock(global.data(), global.data(), cg.data());
  reference.GetCovarianceBlock(held.data(), held.data(), ch.data());
  EXPECT_LT((fast.globals->topLeftCorner(4, 4) - cg).norm(), 1e-9 * (1.0 + cg.norm()));
  // The held component is outside the tangent space: the other three are where they belong.
  EXPECT_LT((fast.globals->bottomRightCorner(3, 3) - ch.topLeftCorner(3, 3)).norm(), 1e-9 * (1.0 + ch.norm()));
  EXPECT_EQ(ch(3, 3), 0.0);
}

TEST(ChainMarginals, AGlobalBlockTheProblemDoesNotDetermineIsReportedUndetermined) {
  // Two global components that only ever appear as their sum: the Schur complement is singular.
  std::vector<std::vector<double>> states(10, std::vector<double>(6, 0.0));
  std::vector<double> global(2, 0.0);
  ceres::Problem problem;
  Eigen::MatrixXd sum(1, 2);
  sum << 1.0, 1.0;
  for (int k = 0; k < 10; ++k) {
    problem.AddResidualBlock(new Linear({Eigen::MatrixXd::Identity(6, 6)}), nullptr, states[k].data());
    problem.AddResidualBlock(new Linear({Eigen::MatrixXd::Identity(1, 6), sum}), nullptr, states[k].data(), global.data());
  }
  std::vector<double*> chain;
  for (auto& s : states) chain.push_back(s.data());
  const ChainMarginals m = chainMarginals(problem, chain, {global.data()}, 1, 6);
  EXPECT_FALSE(m.ok);
  EXPECT_FALSE(m.globals);
}

}  // namespace
}  // namespace coloc::smoother
