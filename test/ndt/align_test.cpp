#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <tuple>
#include <Eigen/Geometry>

#include "coloc/core/error.hpp"
#include "coloc/ndt/aligner.hpp"
#include "coloc/ndt/pcd_file.hpp"
#include "coloc/ndt/preprocess.hpp"
#include "real_data.hpp"
#include "seeded_starts.hpp"

namespace coloc::ndt {
namespace {

using coloc::testing::poseDifference;
using coloc::testing::readMatrix4;
using coloc::testing::realData;
using coloc::testing::offsetPose;
using coloc::testing::seededStarts;

class RealPair : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    try {
      target_ = new PointCloud(loadPcd(realData("hdl32e_pair/target.pcd")));
      source_ = new PointCloud(voxelDownsample(loadPcd(realData("hdl32e_pair/source.pcd")), 0.1));
      gt1_ = readMatrix4(realData("hdl32e_pair/T_target_source.gt1.txt"));
    } catch (const std::exception& e) {
      load_error_ = new std::string(e.what());
    }
  }
  static void TearDownTestSuite() {
    delete target_;
    delete source_;
    delete load_error_;
    target_ = source_ = nullptr;
    load_error_ = nullptr;
  }
  // Each test fails with the loading error rather than running on clouds that are not there.
  void SetUp() override {
    if (load_error_) GTEST_FAIL() << *load_error_;
  }
  static PointCloud* target_;
  static PointCloud* source_;
  static Eigen::Matrix4d gt1_;
  static std::string* load_error_;
};
PointCloud* RealPair::target_ = nullptr;
PointCloud* RealPair::source_ = nullptr;
Eigen::Matrix4d RealPair::gt1_;
std::string* RealPair::load_error_ = nullptr;

TEST_F(RealPair, FastBackendReachesTheReferenceFromIdentity) {
  NdtConfig config;
  const NdtTarget target(*target_, config);
  const AlignResult r = align(target, *source_, Eigen::Matrix4d::Identity(), config);
  ASSERT_TRUE(r.accepted()) << r.detail;
  const auto [meters, degrees] = poseDifference(r.transform, gt1_);
  EXPECT_LT(meters, 0.03);
  EXPECT_LT(degrees, 0.3);
  EXPECT_GT(r.nvtl, config.nvtl_threshold);
  EXPECT_LT(r.iterations, config.max_iterations);
}

TEST_F(RealPair, FastBackendAgreesWithStockPclWithin2cmAnd0_2Degrees) {
  NdtConfig fast;
  NdtConfig stock = fast;
  stock.backend = NdtBackend::kPcl;
  const AlignResult a = align(NdtTarget(*target_, fast), *source_, Eigen::Matrix4d::Identity(), fast);
  const AlignResult b = align(NdtTarget(*target_, stock), *source_, Eigen::Matrix4d::Identity(), stock);
  ASSERT_TRUE(b.accepted()) << b.detail;
  const auto [meters, degrees] = poseDifference(a.transform, b.transform);
  EXPECT_LT(meters, 0.02);
  EXPECT_LT(degrees, 0.2);
  const auto [stock_m, stock_deg] = poseDifference(b.transform, gt1_);
  EXPECT_LT(stock_m, 0.03);
  // Both are scored by the same code at their results: near-identical poses, near-identical scores.
  EXPECT_NEAR(a.nvtl, b.nvtl, 0.01);
}

TEST_F(RealPair, AlignmentIsDeterministicAcrossRuns) {
  NdtConfig config;
  config.threads = 2;
  const NdtTarget target(*target_, config);
  const AlignResult a = align(target, *source_, Eigen::Matrix4d::Identity(), config);
  const AlignResult b = align(target, *source_, Eigen::Matrix4d::Identity(), config);
  EXPECT_EQ(a.transform, b.transform);
  EXPECT_EQ(a.nvtl, b.nvtl);
}

// The source scan as Autoware would feed it (about 1,000 points of 1 m voxels).
PointCloud autowareSizedScan() {
  PreprocessConfig pre;
  pre.voxel_size = 1.0;
  return preprocessScan(loadPcd(realData("hdl32e_pair/source.pcd")), pre);
}

TEST_F(RealPair, AutowareSizedInputConvergesFromHalfMetreAndTwoDegreesOff) {
  NdtConfig config;
  const NdtTarget target(*target_, config);
  const PointCloud scan = autowareSizedScan();
  ASSERT_GT(scan.size(), 800u);
  ASSERT_LE(scan.size(), 1500u);
  const Eigen::Matrix4d guess = offsetPose(gt1_, 2.0 * M_PI / 180.0, Eigen::Vector3d(0.4, -0.3, 0.0));
  const AlignResult r = align(target, scan, guess, config);
  ASSERT_TRUE(r.accepted()) << r.detail << " after " << r.iterations << " iterations, nvtl " << r.nvtl;
  const auto [meters, degrees] = poseDifference(r.transform, gt1_);
  EXPECT_LT(meters, 0.05);
  EXPECT_LT(degrees, 0.5);
}

TEST_F(RealPair, FromTwentySeededStartsFarOffAlmostAllConvergeOnBothInputSizes) {
  // Issue 13's basin: 20 starts at a horizontal offset in a random direction and a yaw of random sign;
  // converged = within 5 cm and 0.5 deg of the reference. At least 19 at 1 m / 5 deg and 15 at
  // 2 m / 10 deg, for the 16k-point scan and the Autoware-sized one. (Clamped Newton with a halving line
  // search, the method before, converged 19 / 9 and 15 / 6 times.)
  NdtConfig config;
  const NdtTarget target(*target_, config);
  const PointCloud sparse = autowareSizedScan();
  for (const PointCloud* scan : {static_cast<const PointCloud*>(source_), &sparse})
    for (const auto& [metres, degrees, needed] : {std::tuple<double, double, int>{1.0, 5.0, 19}, std::tuple<double, double, int>{2.0, 10.0, 15}}) {
      int converged = 0;
      for (const Eigen::Matrix4d& guess : seededStarts(gt1_, metres, degrees)) {
        const auto [m, d] = poseDifference(align(target, *scan, guess, config).transform, gt1_);
        if (m <= 0.05 && d <= 0.5) ++converged;
      }
      EXPECT_GE(converged, needed) << scan->size() << " points, " << metres << " m / " << degrees << " deg off";
    }
}

TEST_F(RealPair, ScanFromAnotherPlaceIsRejectedByTheQualityGate) {
  // The indoor room scan against the outdoor street map: whatever pose NDT ends at, it must not pass.
  NdtConfig config;
  const NdtTarget target(*target_, config);
  const PointCloud room = voxelDownsample(loadPcd(realData("pcl_room/source.pcd")), 0.2);
  const AlignResult r = align(target, room, Eigen::Matrix4d::Identity(), config);
  EXPECT_FALSE(r.accepted());
  EXPECT_FALSE(r.detail.empty());
  // And the street scan put 40 m away from where it belongs fits no better.
  Eigen::Matrix4d far = gt1_;
  far(0, 3) += 40.0;
  const AlignResult displaced = align(target, *source_, far, config);
  EXPECT_FALSE(displaced.accepted()) << "nvtl " << displaced.nvtl;
}

TEST_F(RealPair, LaplaceCovarianceIsFlooredAtTheCovarianceFloor) {
  NdtConfig config;
  config.covariance = CovarianceMode::kLaplace;
  const AlignResult r = align(NdtTarget(*target_, config), *source_, Eigen::Matrix4d::Identity(), config);
  ASSERT_TRUE(r.accepted());
  for (int i = 0; i < 6; ++i) EXPECT_GE(r.covariance(i, i), config.covariance_floor[i] * (1 - 1e-12));
  EXPECT_TRUE(r.covariance.isApprox(r.covariance.transpose()));
  Eigen::SelfAdjointEigenSolver<Matrix6d> eig(r.covariance);
  EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0);
}

TEST(NdtTarget, EmptyMapIsAnError) { EXPECT_THROW(NdtTarget(PointCloud{}, NdtConfig{}), Error); }

TEST(NdtTarget, MapTooSparseForAnyVoxelIsAnErrorSayingSo) {
  PointCloud sparse;
  for (int i = 0; i < 50; ++i) sparse.points.emplace_back(10.0f * i, 0.0f, 0.0f);
  try {
    NdtTarget target(sparse, NdtConfig{});
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("too sparse"), std::string::npos) << e.what();
  }
}

TEST(Align, EmptySourceIsRejectedNotCrashed) {
  PointCloud map;
  for (int i = 0; i < 2000; ++i) map.points.emplace_back(0.01f * (i % 100), 0.01f * (i / 100), 0.001f * (i % 7));
  const NdtTarget target(map, NdtConfig{});
  const AlignResult r = align(target, PointCloud{}, Eigen::Matrix4d::Identity(), NdtConfig{});
  EXPECT_EQ(r.rejection, AlignRejection::kEmptySource);
  Eigen::Matrix4d bad = Eigen::Matrix4d::Identity();
  bad(0, 3) = std::nan("");
  EXPECT_THROW(align(target, map, bad, NdtConfig{}), Error);
}

}  // namespace
}  // namespace coloc::ndt

namespace coloc::ndt {
namespace {

TEST(Align, NaNFilledCloudsGiveErrorsOrRejectionsNotCrashes) {
  const float nan = std::nanf("");
  PointCloud nan_map;
  for (int i = 0; i < 100; ++i) nan_map.points.emplace_back(nan, 1.0f, 2.0f);
  EXPECT_THROW(NdtTarget(nan_map, NdtConfig{}), Error);
  PointCloud map;
  for (int i = 0; i < 2000; ++i) map.points.emplace_back(0.01f * (i % 100), 0.01f * (i / 100), 0.001f * (i % 7));
  const NdtTarget target(map, NdtConfig{});
  PointCloud nan_scan;
  for (int i = 0; i < 50; ++i) nan_scan.points.emplace_back(nan, nan, nan);
  EXPECT_EQ(align(target, nan_scan, Eigen::Matrix4d::Identity(), NdtConfig{}).rejection, AlignRejection::kEmptySource);
  // A few NaN among good points are left out, the rest aligns.
  PointCloud mixed = map;
  mixed.points[3] = Eigen::Vector3f(nan, 0, 0);
  mixed.points[7] = Eigen::Vector3f(0, std::numeric_limits<float>::infinity(), 0);
  const AlignResult r = align(target, mixed, Eigen::Matrix4d::Identity(), NdtConfig{});
  EXPECT_NE(r.rejection, AlignRejection::kEmptySource);
  EXPECT_TRUE(r.transform.allFinite());
}

}  // namespace
}  // namespace coloc::ndt
