// The analytic gradient and Hessian of the NDT score against central differences of the score itself.
#include <gtest/gtest.h>

#include <random>

#include "ndt_score.hpp"

namespace coloc::ndt {
namespace {

TEST(NdtScore, GradientAndHessianMatchNumericDerivatives) {
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  VoxelLookup voxels;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      Eigen::Matrix3d A;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) A(r, c) = n(rng);
      const Eigen::Matrix3d cov = 0.05 * A * A.transpose() + 0.02 * Eigen::Matrix3d::Identity();
      voxels.insert(Eigen::Vector3i(i, j, 0), {Eigen::Vector3d(2.0 * i + 1.0 + 0.3 * n(rng), 2.0 * j + 1.0 + 0.3 * n(rng), 1.0), cov.inverse()});
    }
  voxels.finish();
  std::vector<Eigen::Vector3f> source;
  for (int k = 0; k < 300; ++k)
    source.emplace_back(static_cast<float>(8.0 * (0.5 + 0.5 * std::tanh(n(rng)))), static_cast<float>(8.0 * (0.5 + 0.5 * std::tanh(n(rng)))),
                        static_cast<float>(1.0 + 0.2 * n(rng)));
  const ScoreConstants k = scoreConstants(2.0, 0.55);
  Vector6d pose;
  pose << 0.1, -0.05, 0.02, 0.01, -0.02, 0.05;
  ScoreOptions options;
  options.threads = 1;
  for (Neighborhood hood : {Neighborhood::kRadius, Neighborhood::kFace7}) {
    options.neighborhood = hood;
    const ScoreEvaluation e = evaluateScore(voxels, 2.0, k, source, pose, options);
    ASSERT_GT(e.score, 1.0);
    const double h = 1e-6;
    for (int i = 0; i < 6; ++i) {
      Vector6d plus = pose, minus = pose;
      plus[i] += h;
      minus[i] -= h;
      const ScoreEvaluation ep = evaluateScore(voxels, 2.0, k, source, plus, options);
      const ScoreEvaluation em = evaluateScore(voxels, 2.0, k, source, minus, options);
      EXPECT_NEAR(e.gradient[i], (ep.score - em.score) / (2 * h), 1e-4 * (1.0 + std::abs(e.gradient[i]))) << "gradient " << i;
      const Vector6d column = (ep.gradient - em.gradient) / (2 * h);
      for (int j = 0; j < 6; ++j)
        EXPECT_NEAR(e.hessian(j, i), column[j], 1e-3 * (1.0 + std::abs(column[j]))) << "hessian " << j << "," << i;
    }
  }
}

TEST(NdtScore, TheNeighbourCacheGivesTheSameBitsAsTheFullSearchWhereverThePointsMove) {
  // A dense random field of voxels (most cells, means anywhere in their cells) and points spread over
  // it; the pose then walks away step by step, so that points cross cells into ones seen before and new
  // ones. Every evaluation must equal the uncached one exactly, NVTL included, on one thread and on two.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  VoxelLookup voxels;
  for (int i = -4; i < 8; ++i)
    for (int j = -4; j < 8; ++j)
      for (int l = -2; l < 3; ++l) {
        if (u(rng) < 0.3) continue;
        Eigen::Matrix3d A = Eigen::Matrix3d::Random();
        const Eigen::Matrix3d cov = 0.1 * A * A.transpose() + 0.05 * Eigen::Matrix3d::Identity();
        voxels.insert(Eigen::Vector3i(i, j, l), {2.0 * Eigen::Vector3d(i + u(rng), j + u(rng), l + u(rng)), cov.inverse()});
      }
  voxels.finish();
  std::vector<Eigen::Vector3f> source;
  for (int k = 0; k < 2000; ++k)
    source.emplace_back(static_cast<float>(-4.0 + 16.0 * u(rng)), static_cast<float>(-4.0 + 16.0 * u(rng)), static_cast<float>(-2.0 + 4.0 * u(rng)));
  const ScoreConstants k = scoreConstants(2.0, 0.55);
  ScoreOptions options;
  options.nvtl = true;
  const CellNeighbours cells(voxels, 2.0);
  NeighbourCache cache(source.size(), cells);
  Vector6d pose = Vector6d::Zero();
  for (int step = 0; step < 40; ++step) {
    options.threads = 1 + step % 2;
    pose += (Vector6d() << 0.07, -0.05, 0.03, 0.004, -0.003, 0.01).finished();
    const ScoreEvaluation plain = evaluateScore(voxels, 2.0, k, source, pose, options);
    const ScoreEvaluation cached = evaluateScore(voxels, 2.0, k, source, pose, options, &cache);
    ASSERT_GT(plain.nvtl_points, 500u);
    EXPECT_EQ(plain.score, cached.score) << "step " << step;
    EXPECT_EQ(plain.gradient, cached.gradient) << "step " << step;
    EXPECT_EQ(plain.hessian, cached.hessian) << "step " << step;
    EXPECT_EQ(plain.nvtl_sum, cached.nvtl_sum) << "step " << step;
    EXPECT_EQ(plain.nvtl_points, cached.nvtl_points) << "step " << step;
  }
}

TEST(NdtScore, PoseVectorAndMatrixRoundTrip) {
  Vector6d pose;
  pose << 1.0, -2.0, 0.5, 0.1, -0.2, 2.5;
  EXPECT_TRUE(matrixToPose(poseToMatrix(pose)).isApprox(pose, 1e-12));
}

TEST(NdtScore, ConstantsMatchPclsForResolutionTwo) {
  // d1 < 0 so that the score is positive; d2 > 0 so that it falls off with distance.
  const ScoreConstants k = scoreConstants(2.0, 0.55);
  EXPECT_LT(k.d1, 0.0);
  EXPECT_GT(k.d2, 0.0);
}

}  // namespace
}  // namespace coloc::ndt
