#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include "coloc/ndt/preprocess.hpp"
#include "coloc/ndt/voxel_thinning.hpp"

namespace coloc::ndt {
namespace {

// Bit for bit: -0 and +0 differ, as a later pass would tell them apart.
void expectSameBits(const PointCloud& a, const PointCloud& b, const std::string& where) {
  ASSERT_EQ(a.size(), b.size()) << where;
  ASSERT_TRUE(a.times.empty() && b.times.empty()) << where;
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(std::memcmp(a.points[i].data(), b.points[i].data(), sizeof(float) * 3), 0) << where << ", point " << i;
}

// Adds `batch` to both: the thinning and a plain cloud downsampled whole at every pass, as the survey
// did; they must agree after every pass.
struct Both {
  VoxelThinning thinning;
  PointCloud whole;
  double voxel;
  explicit Both(double v) : thinning(v), voxel(v) {}
  void pass(const std::vector<Eigen::Vector3f>& batch, const std::string& where) {
    for (const Eigen::Vector3f& p : batch) {
      thinning.add(p);
      whole.points.push_back(p);
    }
    thinning.thin();
    whole = voxelDownsample(whole, voxel);
    expectSameBits(thinning.cloud(), whole, where);
  }
};

TEST(VoxelThinning, EveryPassGivesTheBitsOfDownsamplingTheWholeCloudAgain) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> wide(-60.0f, 60.0f), tall(-2.0f, 8.0f);
  Both both(0.5);
  for (int pass = 0; pass < 12; ++pass) {
    std::vector<Eigen::Vector3f> batch;
    // A moving patch (new voxels and old ones revisited) and points all over (far from the origin too).
    for (int i = 0; i < 4000; ++i) batch.emplace_back(10.0f * pass + 0.3f * wide(rng), 0.2f * wide(rng), tall(rng));
    for (int i = 0; i < 1000; ++i) batch.emplace_back(20.0f * wide(rng), 20.0f * wide(rng), tall(rng));
    both.pass(batch, "pass " + std::to_string(pass));
  }
  EXPECT_GT(both.whole.size(), 5000u);
}

// What lets a pass skip the old points: a centroid stays in its points' voxel and is never -0, even for
// points hugging a voxel's bounds (just below the next voxel, at the product of a coordinate and the
// inverse voxel size that rounds up to an integer, at -0 and the smallest denormals).
TEST(VoxelThinning, CentroidsOfPointsOnTheVoxelBoundsStayInTheirVoxelPassAfterPass) {
  for (const double voxel : {1.0, 0.3, 0.1}) {
    Both both(voxel);
    const float tiny = std::numeric_limits<float>::denorm_min();
    std::vector<Eigen::Vector3f> batch;
    for (int k = -20; k <= 20; ++k) {
      const float bound = static_cast<float>(k * voxel);
      for (int ulps = -3; ulps <= 3; ++ulps) {
        float x = bound;
        for (int u = 0; u < std::abs(ulps); ++u) x = std::nextafter(x, ulps < 0 ? -1e9f : 1e9f);
        batch.emplace_back(x, 0.5f, 0.5f);
        batch.emplace_back(0.5f, x, -x);
      }
    }
    for (const float z : {-0.0f, 0.0f, -tiny, tiny, -2 * tiny}) batch.emplace_back(z, z, z);
    for (int pass = 0; pass < 4; ++pass) both.pass(batch, "voxel " + std::to_string(voxel) + ", pass " + std::to_string(pass));
  }
}

TEST(VoxelThinning, PointsWithoutAVoxelAreLeftOutAndNoVoxelSizeKeepsEveryPoint) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  Both both(0.25);
  both.pass({{nan, 0.0f, 0.0f}, {1.0f, 1.0f, 1.0f}, {inf, 0.0f, 0.0f}, {1.1f, 1.1f, 1.1f}, {1e12f, 0.0f, 0.0f}}, "with points without a voxel");
  EXPECT_EQ(both.thinning.cloud().size(), 1u);
  both.pass({{1.2f, 1.2f, 1.2f}, {nan, nan, nan}}, "second pass");

  VoxelThinning none(0.0);
  none.add({1.0f, 1.0f, 1.0f});
  none.add({1.0f, 1.0f, 1.0f});
  none.thin();
  none.add({2.0f, 2.0f, 2.0f});
  none.thin();
  EXPECT_EQ(none.cloud().size(), 3u);
  const PointCloud released = none.release();
  EXPECT_EQ(released.size(), 3u);
  EXPECT_TRUE(none.cloud().empty());
}

}  // namespace
}  // namespace coloc::ndt
