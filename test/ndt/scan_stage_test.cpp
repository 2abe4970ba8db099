#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "scan_stage.hpp"

namespace coloc::ndt {
namespace {

// The vectorised staging must give the portable one's bits: the same points cropped, the same moved
// coordinates, the same voxels, for ordinary points and for the awkward ones (not finite, on the crop's
// bounds, on voxel bounds, beyond integer voxel reach, -0).
TEST(ScanStage, FourAtATimeGivesThePointByPointBitsForEveryKindOfPoint) {
  if (!stageRunVectorised()) GTEST_SKIP() << "this CPU takes the point-by-point path only";
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> coordinate(-80.0f, 80.0f);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 4000; ++i) points.emplace_back(coordinate(rng), coordinate(rng), 0.1f * coordinate(rng));
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  for (const float odd : {nan, inf, -inf, -0.0f, 0.0f, 3e9f, -3e9f, 1.9e9f, -1.9e9f, 1e30f, std::numeric_limits<float>::denorm_min()})
    for (int axis = 0; axis < 3; ++axis) {
      Eigen::Vector3f p(2.0f, 1.0f, 0.5f);
      p[axis] = odd;
      points.push_back(p);
    }
  for (int k = -10; k <= 10; ++k) {  // on and around voxel bounds (0.3 m voxels) and the crop's radii (1 m, 60 m)
    for (const float x : {0.3f * k, std::nextafter(0.3f * k, -1e9f), std::nextafter(0.3f * k, 1e9f), 1.0f, 60.0f, std::nextafter(60.0f, 1e9f)}) {
      points.emplace_back(x, 0.0f, 0.0f);
      points.emplace_back(0.0f, x, -x);
    }
  }

  // The limits of integer voxel reach with 1 m voxels: floor(v) within (-2e9, 2e9).
  for (const float x : {2e9f, std::nextafter(2e9f, 0.0f), -2e9f, std::nextafter(-2e9f, 0.0f), 4e9f, -4e9f})
    for (int axis = 0; axis < 3; ++axis) {
      Eigen::Vector3f p(2.0f, 1.0f, 0.5f);
      p[axis] = x;
      points.push_back(p);
    }

  StageBounds bounds;
  bounds.lo = 1.0;
  bounds.hi = 3600.0;
  bounds.inverse = 1.0 / 0.3;
  StageBounds metre = bounds;
  metre.lo = 0.0, metre.hi = std::numeric_limits<double>::infinity(), metre.inverse = 1.0;
  RunMotion still, moving;
  moving.moves = true;
  moving.c = std::cos(0.01), moving.s = std::sin(0.01), moving.dx = 0.8, moving.dy = 0.004;
  StageBounds uncropped = bounds;
  uncropped.lo = 0.0, uncropped.hi = std::numeric_limits<double>::infinity();
  for (const RunMotion& motion : {still, moving})
    for (const StageBounds& b : {bounds, uncropped, metre})
      for (const std::size_t n : {points.size(), std::size_t{3}, std::size_t{5}}) {  // runs with a tail of 0 to 3 points
        std::vector<StagedPoint> fast(n), reference(n);
        stageRun(points.data(), n, motion, b, fast.data());
        stageRunPortable(points.data(), n, motion, b, reference.data());
        int kept = 0;
        for (std::size_t i = 0; i < n; ++i) {
          ASSERT_EQ(fast[i].ok, reference[i].ok) << "point " << i << " (" << points[i].transpose() << ")";
          if (!reference[i].ok) continue;
          ++kept;
          ASSERT_EQ(std::memcmp(fast[i].p.data(), reference[i].p.data(), sizeof(float) * 3), 0) << "point " << i;
          ASSERT_TRUE(fast[i].key == reference[i].key) << "point " << i;
        }
        if (n == points.size()) {
          EXPECT_GT(kept, 1500);  // about half the random points lie within 60 m
        }
      }
}

}  // namespace
}  // namespace coloc::ndt
