// The residuals whose derivatives are written out must give what automatic differentiation of the
// same residual gives, to the bit: the smoother's results do not depend on which one it uses.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "residuals.hpp"

namespace coloc::smoother::residuals {
namespace {

// Residuals and Jacobians of `a` and `b` on the same parameters, compared value for value.
void expectTheSameBits(const ceres::CostFunction& a, const ceres::CostFunction& b, const std::vector<std::vector<double>>& parameters) {
  ASSERT_EQ(a.num_residuals(), b.num_residuals());
  ASSERT_EQ(a.parameter_block_sizes(), b.parameter_block_sizes());
  const int m = a.num_residuals();
  std::vector<const double*> blocks;
  for (const auto& p : parameters) blocks.push_back(p.data());
  std::vector<double> ra(m), rb(m);
  std::vector<std::vector<double>> ja, jb;
  std::vector<double*> pa, pb;
  for (const int size : a.parameter_block_sizes()) {
    ja.emplace_back(static_cast<std::size_t>(m * size), -1.0);
    jb.emplace_back(static_cast<std::size_t>(m * size), -2.0);
  }
  for (std::size_t k = 0; k < ja.size(); ++k) pa.push_back(ja[k].data()), pb.push_back(jb[k].data());
  ASSERT_TRUE(a.Evaluate(blocks.data(), ra.data(), pa.data()));
  ASSERT_TRUE(b.Evaluate(blocks.data(), rb.data(), pb.data()));
  EXPECT_EQ(ra, rb);
  for (std::size_t k = 0; k < ja.size(); ++k) EXPECT_EQ(ja[k], jb[k]) << "parameter block " << k;
  // Without Jacobians, the same residuals.
  std::vector<double> rc(m);
  ASSERT_TRUE(a.Evaluate(blocks.data(), rc.data(), nullptr));
  EXPECT_EQ(rc, rb);
}

TEST(SmootherResiduals, TheTwistsWrittenOutDerivativesAreTheDualNumbersToTheBit) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  auto state = [&] {
    std::vector<double> s(kState);
    for (double& x : s) x = u(rng);
    return s;
  };
  // Speed alone, yaw rate alone, both with a correlated covariance; with and without the odometry's calibration.
  const std::vector<std::vector<int>> components = {{4}, {5}, {4, 5}};
  for (int trial = 0; trial < 20; ++trial)
    for (const std::vector<int>& c : components) {
      TwistResidual r;
      r.w = std::uniform_real_distribution<double>(0.0, 1.0)(rng);
      r.m = static_cast<int>(c.size());
      for (int j = 0; j < r.m; ++j) r.component[j] = c[static_cast<std::size_t>(j)], r.value[j] = u(rng);
      r.whitening << 1.0 / 0.05, 0.0, u(rng), 1.0 / 0.02;
      const std::vector<double> a = state(), b = state();
      const std::vector<double> odometry = {1.0 + 0.01 * u(rng), 0.001 * u(rng)};
      SCOPED_TRACE("trial " + std::to_string(trial) + ", " + std::to_string(r.m) + " component(s)");
      expectTheSameBits(TwistCost(r, false), ceres::AutoDiffCostFunction<TwistResidual, ceres::DYNAMIC, kState, kState>(new TwistResidual(r), r.m),
                        {a, b});
      expectTheSameBits(TwistCost(r, true),
                        ceres::AutoDiffCostFunction<CalibratedTwistResidual, ceres::DYNAMIC, kState, kState, 2>(new CalibratedTwistResidual{r}, r.m),
                        {a, b, odometry});
    }
}

TEST(SmootherResiduals, ThePoseBiasProcessWrittenOutIsTheDualNumbersToTheBit) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<double> a(kState), b(kState);
    for (double& x : a) x = u(rng);
    for (double& x : b) x = u(rng);
    const BiasProcess p{0.99 + 0.01 * u(rng), 1.0 / (0.03 + u(rng) * u(rng))};
    expectTheSameBits(BiasProcessCost(p), ceres::AutoDiffCostFunction<BiasProcess, 2, kState, kState>(new BiasProcess(p)), {a, b});
  }
}

}  // namespace
}  // namespace coloc::smoother::residuals
