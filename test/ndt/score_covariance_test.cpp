// multi_ndt_score: NDT's covariance from the score's spread over offset poses, on worlds whose
// constraint is known by construction.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "coloc/core/error.hpp"
#include "coloc/ndt/aligner.hpp"
#include "coloc/ndt/ndt_pose_source.hpp"

namespace coloc::ndt {
namespace {

constexpr double kDeg = M_PI / 180.0;

// Ground from x0 to x1 across |y| <= 6 m, and walls on both sides (a corridor along x).
void addCorridor(PointCloud& cloud, double x0, double x1, std::mt19937& rng) {
  std::normal_distribution<float> rough(0.0f, 0.01f);
  for (double x = x0; x <= x1; x += 0.2) {
    for (double y = -6.0; y <= 6.0; y += 0.2) cloud.points.emplace_back(x, y, rough(rng));
    for (double z = 0.2; z <= 4.0; z += 0.2) {
      cloud.points.emplace_back(x, -6.0 + rough(rng), z);
      cloud.points.emplace_back(x, 6.0 + rough(rng), z);
    }
  }
}

// Cross walls from each side wall to 3 m from the centre line, at uneven spacing: surfaces facing
// along the corridor, which hold the position along it.
void addCrossWalls(PointCloud& cloud, double x0, double x1, std::mt19937& rng) {
  std::normal_distribution<float> rough(0.0f, 0.01f);
  for (double cx : {-33.0, -21.0, -12.5, -4.0, 3.5, 11.0, 17.0, 29.0}) {
    if (cx < x0 || cx > x1) continue;
    for (double side : {-1.0, 1.0})
      for (double y = 3.0; y <= 6.0; y += 0.1)
        for (double z = 0.1; z <= 3.0; z += 0.1) cloud.points.emplace_back(cx + rough(rng), side * y, z);
  }
}

PointCloud rotated(const PointCloud& cloud, double yaw) {
  PointCloud out;
  const Eigen::Matrix3f R = Eigen::AngleAxisf(static_cast<float>(yaw), Eigen::Vector3f::UnitZ()).toRotationMatrix();
  for (const auto& p : cloud.points) out.points.push_back(R * p);
  return out;
}

struct Outcome {
  AlignResult result;
  Eigen::Vector2d along_across;  ///< variance along the heading and across it, m^2
};

// The map spans 80 m of corridor, the scan (the vehicle's view) its middle 30 m; both turned by `yaw`.
Outcome alignIn(bool blocks, double yaw, const NdtConfig& config) {
  std::mt19937 rng(7);
  PointCloud map, scan;
  addCorridor(map, -40.0, 40.0, rng);
  addCorridor(scan, -15.0, 15.0, rng);
  if (blocks) {
    addCrossWalls(map, -40.0, 40.0, rng);
    addCrossWalls(scan, -15.0, 15.0, rng);
  }
  const NdtTarget target(rotated(map, yaw), config);
  Eigen::Matrix4d guess = Eigen::Matrix4d::Identity();
  guess.topLeftCorner<3, 3>() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Outcome out{align(target, scan, guess, config), {}};
  const Eigen::Vector2d along(std::cos(yaw), std::sin(yaw)), across(-std::sin(yaw), std::cos(yaw));
  const Eigen::Matrix2d xy = out.result.covariance.topLeftCorner<2, 2>();
  out.along_across = {along.dot(xy * along), across.dot(xy * across)};
  return out;
}

NdtConfig scoreConfig() {
  NdtConfig c;
  c.covariance = CovarianceMode::kMultiNdtScore;
  c.covariance_floor << 0.001, 0.001, 0.0225, 0.000625, 0.000625, 1e-6;
  c.score_yaw_offset_deg = 0.5;
  return c;
}

TEST(MultiNdtScoreCovariance, AFeaturelessCorridorIsUncertainAlongItAndCertainAcross) {
  const NdtConfig config = scoreConfig();
  const Outcome o = alignIn(false, 0.0, config);
  ASSERT_TRUE(o.result.accepted()) << o.result.detail;
  // Nothing holds the scan along the corridor: the offsets up to 1 m score alike, so the spread is
  // near that of the offsets themselves (0.36 m^2 with equal weights).
  EXPECT_GT(o.along_across[0], 0.2);
  // Across it the walls hold the scan: the floor (0.001) or barely above it.
  EXPECT_LT(o.along_across[1], 0.002);
  EXPECT_GE(o.along_across[1], 0.001 * (1 - 1e-9));
  // The walls also hold the heading: yaw within a fraction of the 0.5 deg probes.
  EXPECT_LT(o.result.covariance(5, 5), std::pow(0.2 * kDeg, 2));
}

TEST(MultiNdtScoreCovariance, StructureAlongTheCorridorBringsItToTheFloor) {
  const NdtConfig config = scoreConfig();
  const Outcome o = alignIn(true, 0.0, config);
  ASSERT_TRUE(o.result.accepted()) << o.result.detail;
  EXPECT_LT(o.along_across[0], 0.01);
  EXPECT_LT(o.along_across[1], 0.002);
}

TEST(MultiNdtScoreCovariance, TheUncertainDirectionTurnsWithTheHeading) {
  const NdtConfig config = scoreConfig();
  const Outcome o = alignIn(false, 30.0 * kDeg, config);
  ASSERT_TRUE(o.result.accepted()) << o.result.detail;
  EXPECT_GT(o.along_across[0], 0.2);
  EXPECT_LT(o.along_across[1], 0.002);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(o.result.covariance.topLeftCorner<2, 2>());
  const Eigen::Vector2d major = eig.eigenvectors().col(1);
  EXPECT_NEAR(std::abs(std::atan(major.y() / major.x())), 30.0 * kDeg, 1.0 * kDeg);
}

TEST(MultiNdtScoreCovariance, OpenGroundLeavesTheHeadingUncertainAndYawProbesSeeIt) {
  NdtConfig config = scoreConfig();
  std::mt19937 rng(3);
  std::normal_distribution<float> rough(0.0f, 0.01f);
  PointCloud ground;
  for (double x = -30.0; x <= 30.0; x += 0.2)
    for (double y = -30.0; y <= 30.0; y += 0.2) ground.points.emplace_back(x, y, rough(rng));
  PointCloud scan;
  for (const auto& p : ground.points)
    if (p.head<2>().norm() < 15.0f) scan.points.push_back(p);
  const NdtTarget target(ground, config);
  const AlignResult with_yaw = align(target, scan, Eigen::Matrix4d::Identity(), config);
  EXPECT_GT(with_yaw.covariance(5, 5), std::pow(0.5 * kDeg, 2));
  EXPECT_GT(with_yaw.covariance(0, 0), 0.2);
  EXPECT_GT(with_yaw.covariance(1, 1), 0.04);
  config.score_yaw_offset_deg = 0.0;  // Autoware's: x/y only, yaw at the fixed figure
  const AlignResult without = align(target, scan, Eigen::Matrix4d::Identity(), config);
  EXPECT_DOUBLE_EQ(without.covariance(5, 5), config.covariance_floor[5]);
}

TEST(MultiNdtScoreCovariance, IsSymmetricPositiveDefiniteAndNeverBelowTheFloor) {
  for (const bool blocks : {false, true}) {
    const NdtConfig config = scoreConfig();
    const Outcome o = alignIn(blocks, 10.0 * kDeg, config);
    const Matrix6d& c = o.result.covariance;
    EXPECT_TRUE(c.isApprox(c.transpose()));
    EXPECT_GT(Eigen::SelfAdjointEigenSolver<Matrix6d>(c).eigenvalues().minCoeff(), 0.0);
    EXPECT_GE(o.along_across.minCoeff(), 0.001 * (1 - 1e-9));
    for (int i = 2; i < 5; ++i) EXPECT_DOUBLE_EQ(c(i, i), config.covariance_floor[i]);
  }
}

TEST(MultiNdtScoreCovariance, BadSettingsAreRefusedNamingTheKey) {
  NdtPoseSourceConfig c;
  c.ndt.covariance = CovarianceMode::kMultiNdtScore;
  c.ndt.score_temperature = 0.0;
  try {
    validate(c);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("ndt.score_temperature"), std::string::npos) << e.what();
  }
  c.ndt.score_temperature = 0.05;
  c.ndt.score_yaw_offset_deg = std::nan("");
  EXPECT_THROW(validate(c), Error);
  c.ndt.score_yaw_offset_deg = -1.0;
  EXPECT_THROW(validate(c), Error);
}

}  // namespace
}  // namespace coloc::ndt

#include "ndt_score.hpp"
#include "target_impl.hpp"

namespace coloc::ndt {
namespace {

TEST(NvtlAtTranslations, EqualsTheScoreEvaluatedAtEachShiftedPose) {
  std::mt19937 rng(11);
  PointCloud map, scan;
  addCorridor(map, -40.0, 40.0, rng);
  addCrossWalls(map, -40.0, 40.0, rng);
  addCorridor(scan, -15.0, 15.0, rng);
  addCrossWalls(scan, -15.0, 15.0, rng);
  const NdtConfig config;
  const NdtTarget target(map, config);
  const NdtTarget::Impl& t = target.impl();
  Vector6d pose;
  pose << 0.3, -0.2, 0.05, 0.01, -0.02, 0.4;
  const std::vector<Eigen::Vector3d> shifts = {{0, 0, 0}, {0.5, 0, 0}, {-1.0, 0.3, 0}, {0.2, -0.5, 0.1}, {-3.0, 2.5, 0}};
  const std::vector<double> nvtl = nvtlAtTranslations(t.voxels, config.resolution, t.constants, scan.points, pose, shifts, *t.neighbours, 2);
  ASSERT_EQ(nvtl.size(), shifts.size());
  // With the alignment's memory of each point's cell (filled by a score at the pose), the same bits.
  NeighbourCache cache(scan.size(), *t.neighbours);
  evaluateScore(t.voxels, config.resolution, t.constants, scan.points, pose, ScoreOptions{}, &cache);
  EXPECT_EQ(nvtlAtTranslations(t.voxels, config.resolution, t.constants, scan.points, pose, shifts, *t.neighbours, 2, &cache), nvtl);
  for (std::size_t j = 0; j < shifts.size(); ++j) {
    Vector6d shifted = pose;
    shifted.head<3>() += shifts[j];
    ScoreOptions options;
    options.nvtl = true;
    options.gradient = options.hessian = false;
    const ScoreEvaluation e = evaluateScore(t.voxels, config.resolution, t.constants, scan.points, shifted, options);
    ASSERT_GT(e.nvtl_points, 0u);
    EXPECT_NEAR(nvtl[j], e.nvtl_sum / static_cast<double>(e.nvtl_points), 1e-9) << "shift " << j;
  }
}

}  // namespace
}  // namespace coloc::ndt
