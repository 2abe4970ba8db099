// The target's shared cell lists: each the voxels gathered for its cell, the same from every thread,
// kept where they are, and bounded (past the bound a list is gathered for the caller and not kept).
#include <gtest/gtest.h>

#include <random>
#include <thread>

#include "cell_neighbours.hpp"

namespace coloc::ndt {
namespace {

VoxelLookup randomVoxels(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  VoxelLookup voxels;
  for (int i = -6; i < 6; ++i)
    for (int j = -6; j < 6; ++j)
      for (int l = -2; l < 2; ++l)
        if (u(rng) < 0.6) voxels.insert(Eigen::Vector3i(i, j, l), {2.0 * Eigen::Vector3d(i + u(rng), j + u(rng), l + u(rng)), Eigen::Matrix3d::Identity()});
  voxels.finish();
  return voxels;
}

std::vector<std::uint32_t> gathered(const VoxelLookup& voxels, const Eigen::Vector3i& cell) {
  std::vector<std::uint32_t> out;
  gatherCell(voxels, 2.0, cell, out);
  return out;
}

std::vector<std::uint32_t> asVector(const CellNeighbours::List& list) { return {list.voxels, list.voxels + list.size}; }

TEST(CellNeighbours, EachCellsListIsItsGatheredVoxelsAndStaysWhereItIsWhileOthersAreAdded) {
  std::mt19937 rng(3);
  const VoxelLookup voxels = randomVoxels(rng);
  const CellNeighbours cells(voxels, 2.0);
  std::vector<std::uint32_t> scratch;
  const Eigen::Vector3i first(0, 0, 0);
  const CellNeighbours::List kept = cells.get(first, VoxelLookup::pack(first), scratch);
  const std::vector<std::uint32_t> expected = gathered(voxels, first);
  ASSERT_FALSE(expected.empty());
  EXPECT_EQ(asVector(kept), expected);
  for (int i = -8; i < 8; ++i)
    for (int j = -8; j < 8; ++j)
      for (int l = -3; l < 3; ++l) {
        const Eigen::Vector3i c(i, j, l);
        EXPECT_EQ(asVector(cells.get(c, VoxelLookup::pack(c), scratch)), gathered(voxels, c)) << c.transpose();
      }
  EXPECT_EQ(cells.get(first, VoxelLookup::pack(first), scratch).voxels, kept.voxels);  // the same list, not a copy
  EXPECT_EQ(asVector(kept), expected);
  EXPECT_EQ(cells.cells(), 16u * 16u * 6u);
}

TEST(CellNeighbours, TwoThreadsAskingForTheSameCellsGetTheSameLists) {
  std::mt19937 rng(5);
  const VoxelLookup voxels = randomVoxels(rng);
  const CellNeighbours cells(voxels, 2.0);
  int wrong[2] = {0, 0};
  auto ask = [&](int t) {
    std::vector<std::uint32_t> scratch;
    for (int round = 0; round < 3; ++round)
      for (int i = -7; i < 7; ++i)
        for (int j = -7; j < 7; ++j)
          for (int l = -2; l < 2; ++l) {
            const Eigen::Vector3i c(t == 0 ? i : -i - 1, j, l);  // in opposite orders
            const CellNeighbours::List list = cells.get(c, VoxelLookup::pack(c), scratch);
            if (asVector(list) != gathered(voxels, c)) ++wrong[t];
          }
  };
  std::thread other(ask, 1);
  ask(0);
  other.join();
  EXPECT_EQ(wrong[0], 0);
  EXPECT_EQ(wrong[1], 0);
  EXPECT_EQ(cells.cells(), 14u * 14u * 4u);
}

TEST(CellNeighbours, PastItsBoundAListIsGatheredForTheCallerAndNotKept) {
  std::mt19937 rng(7);
  const VoxelLookup voxels = randomVoxels(rng);
  const CellNeighbours cells(voxels, 2.0, 64);  // one list per shard
  std::vector<std::uint32_t> scratch;
  int not_kept = 0;
  for (int i = -6; i < 6; ++i)
    for (int j = -6; j < 6; ++j) {
      const Eigen::Vector3i c(i, j, 0);
      const CellNeighbours::List list = cells.get(c, VoxelLookup::pack(c), scratch);
      EXPECT_EQ(asVector(list), gathered(voxels, c)) << c.transpose();
      if (!list.kept) {
        EXPECT_EQ(list.voxels, scratch.data());  // in the caller's scratch
        ++not_kept;
      }
    }
  EXPECT_LE(cells.cells(), 64u);
  EXPECT_GT(not_kept, 0);
}

}  // namespace
}  // namespace coloc::ndt
