#include <gtest/gtest.h>

#include "scan_pool.hpp"

namespace coloc::twin {
namespace {

void fillWith(ndt::PointCloud& cloud, int n, float value) {
  cloud.points.reserve(static_cast<std::size_t>(n));  // as the twin's scans: room for the sweep (a no-op in the pool's room)
  cloud.times.reserve(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    cloud.points.emplace_back(value, static_cast<float>(i), 0.0f);
    cloud.times.push_back(0.001f * i);
  }
}

TEST(ScanPool, AScanLetGoIsFilledAgainInTheSameMemoryWithOnlyTheNewPoints) {
  ScanPool pool(std::size_t{1} << 20);
  std::shared_ptr<const ndt::PointCloud> first = pool.make(1000, [](ndt::PointCloud& c) { fillWith(c, 1000, 1.0f); });
  const Eigen::Vector3f* memory = first->points.data();
  EXPECT_EQ(pool.bytes(), 0u);
  first.reset();
  EXPECT_EQ(pool.bytes(), 1000 * (sizeof(Eigen::Vector3f) + sizeof(float)));
  const std::shared_ptr<const ndt::PointCloud> second = pool.make(600, [](ndt::PointCloud& c) {
    EXPECT_TRUE(c.points.empty() && c.times.empty());
    fillWith(c, 600, 2.0f);
  });
  EXPECT_EQ(second->points.data(), memory);
  ASSERT_EQ(second->size(), 600u);
  ASSERT_EQ(second->times.size(), 600u);
  EXPECT_EQ(second->points[599], Eigen::Vector3f(2.0f, 599.0f, 0.0f));
  EXPECT_EQ(pool.bytes(), 0u);
}

TEST(ScanPool, AScanTakesTheSmallestRoomItFitsInAndFreshMemoryWhenNoneIsLargeEnough) {
  ScanPool pool(std::size_t{1} << 20);
  auto small = pool.make(100, [](ndt::PointCloud& c) { fillWith(c, 100, 1.0f); });
  auto large = pool.make(2000, [](ndt::PointCloud& c) { fillWith(c, 2000, 1.0f); });
  auto middle = pool.make(500, [](ndt::PointCloud& c) { fillWith(c, 500, 1.0f); });
  const Eigen::Vector3f* small_memory = small->points.data();
  const Eigen::Vector3f* large_memory = large->points.data();
  const Eigen::Vector3f* middle_memory = middle->points.data();
  small.reset();
  large.reset();
  middle.reset();
  const auto a = pool.make(400, [](ndt::PointCloud& c) { fillWith(c, 400, 2.0f); });
  EXPECT_EQ(a->points.data(), middle_memory);
  const auto b = pool.make(3000, [](ndt::PointCloud& c) { fillWith(c, 3000, 2.0f); });
  EXPECT_NE(b->points.data(), small_memory);
  EXPECT_NE(b->points.data(), large_memory);
  const auto c = pool.make(1500, [](ndt::PointCloud& cloud) { fillWith(cloud, 1500, 2.0f); });
  EXPECT_EQ(c->points.data(), large_memory);
  EXPECT_EQ(pool.bytes(), 100 * (sizeof(Eigen::Vector3f) + sizeof(float)));  // the small one, waiting
}

TEST(ScanPool, BeyondItsBoundAScanLetGoIsFreedAndANewOneGetsFreshMemory) {
  ScanPool pool(4096);
  pool.make(1000, [](ndt::PointCloud& c) { fillWith(c, 1000, 1.0f); }).reset();  // 16 KB: more than the pool keeps
  EXPECT_EQ(pool.bytes(), 0u);
  const auto next = pool.make(10, [](ndt::PointCloud& c) { fillWith(c, 10, 3.0f); });
  EXPECT_EQ(next->size(), 10u);
  EXPECT_EQ(next->points[0].x(), 3.0f);
}

TEST(ScanPool, AFreshScanHasRoomForAQuarterMoreSoThatALargerScanFitsItLater) {
  ScanPool pool(std::size_t{1} << 20);
  std::shared_ptr<const ndt::PointCloud> first = pool.make(1000, [](ndt::PointCloud& c) { fillWith(c, 1000, 1.0f); });
  const Eigen::Vector3f* memory = first->points.data();
  EXPECT_GE(first->points.capacity(), 1250u);
  EXPECT_GE(first->times.capacity(), 1250u);
  first.reset();
  std::shared_ptr<const ndt::PointCloud> larger = pool.make(1200, [](ndt::PointCloud& c) { fillWith(c, 1200, 2.0f); });
  EXPECT_EQ(larger->points.data(), memory);
  EXPECT_EQ(larger->points[1199], Eigen::Vector3f(2.0f, 1199.0f, 0.0f));
  larger.reset();
  const auto beyond = pool.make(1300, [](ndt::PointCloud& c) { fillWith(c, 1300, 3.0f); });  // more than its room
  EXPECT_NE(beyond->points.data(), memory);
}

TEST(ScanPool, ItsBoundCountsTheMostAScanEverFilledNotTheRoomItReserved) {
  constexpr std::size_t kFilled = 1000 * (sizeof(Eigen::Vector3f) + sizeof(float));
  ScanPool pool(kFilled);  // room for 1250 points reserved, 1000 filled: kept
  std::shared_ptr<const ndt::PointCloud> scan = pool.make(1000, [](ndt::PointCloud& c) { fillWith(c, 1000, 1.0f); });
  const Eigen::Vector3f* memory = scan->points.data();
  scan.reset();
  EXPECT_EQ(pool.bytes(), kFilled);
  // Filled with fewer points, the memory the first fill touched is still held: counted as before.
  scan = pool.make(200, [](ndt::PointCloud& c) { fillWith(c, 200, 2.0f); });
  EXPECT_EQ(scan->points.data(), memory);
  EXPECT_EQ(pool.bytes(), 0u);
  scan.reset();
  EXPECT_EQ(pool.bytes(), kFilled);
  // Filled with more, it holds more than the bound: freed when let go.
  scan = pool.make(1100, [](ndt::PointCloud& c) { fillWith(c, 1100, 3.0f); });
  EXPECT_EQ(scan->points.data(), memory);
  scan.reset();
  EXPECT_EQ(pool.bytes(), 0u);
}

}  // namespace
}  // namespace coloc::twin
