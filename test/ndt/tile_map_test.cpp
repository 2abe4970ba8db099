#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "coloc/core/error.hpp"
#include "coloc/ndt/aligner.hpp"
#include "coloc/ndt/pcd_file.hpp"
#include "coloc/ndt/tile_map.hpp"
#include "temp_dir.hpp"

namespace coloc::ndt {
namespace {

// A ground plane with posts every 4 m: enough structure for NDT, one 20 m tile per file.
PointCloud syntheticTile(int tx, int ty) {
  PointCloud tile;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j) {
      const float x = 20.0f * tx + 0.5f * i + 0.25f, y = 20.0f * ty + 0.5f * j + 0.25f;
      tile.points.emplace_back(x, y, 0.02f * std::sin(x) * std::cos(y));
      if (i % 8 == 0 && j % 8 == 0)
        for (int k = 1; k < 12; ++k) tile.points.emplace_back(x + 0.1f * (k % 2), y, 0.25f * k);
    }
  return tile;
}

std::string writeTiles(const testing::TempDir& dir, int n) {
  const std::string folder = dir / "tiles";
  std::filesystem::create_directories(folder);
  for (int tx = 0; tx < n; ++tx)
    for (int ty = 0; ty < n; ++ty) savePcd(folder + "/tile_" + std::to_string(tx) + "_" + std::to_string(ty) + ".pcd", syntheticTile(tx, ty));
  return folder;
}

// A replay checks the map it is given before anything else, whether or not it will read its tiles.
TEST(TileMap, CheckPathRefusesAMissingPathAndAFolderWithoutTilesAndReadsNoTile) {
  testing::TempDir dir;
  const auto message = [](const std::string& path) {
    try {
      TileMap::checkPath(path);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(message(dir / "nowhere"), dir / "nowhere" + ": no such map file or folder");
  std::filesystem::create_directories(dir / "empty");
  std::ofstream(dir / "empty" + "/notes.txt") << "not a tile\n";
  EXPECT_EQ(message(dir / "empty"), dir / "empty" + ": the map folder holds no .pcd tile");
  // A folder with a tile passes, even one that would not load: checking reads no tile.
  std::filesystem::create_directories(dir / "one");
  std::ofstream(dir / "one" + "/tile.pcd") << "not a PCD\n";
  EXPECT_EQ(message(dir / "one"), "");
  EXPECT_EQ(message(writeTiles(dir, 1)), "");
}

TEST(TileMap, FolderIsIndexedWithEachTilesBounds) {
  testing::TempDir dir;
  const TileMap map = TileMap::open(writeTiles(dir, 3));
  ASSERT_EQ(map.tiles().size(), 9u);
  for (const TileInfo& t : map.tiles()) {
    EXPECT_LE(t.max.x() - t.min.x(), 20.0);
    EXPECT_GT(t.points, 1600u);
  }
}

TEST(TileMap, OnlyTilesWithinTheRadiusAreKept) {
  testing::TempDir dir;
  const TileMap map = TileMap::open(writeTiles(dir, 5));  // 100 m x 100 m
  // From the centre of tile (0, 0) with 15 m: its own tile and the two neighbours within 5 m.
  const auto near = map.tilesWithin({10.0, 10.0}, 15.0);
  EXPECT_EQ(near.size(), 4u);  // (0,0), (1,0), (0,1), and (1,1) whose corner is 14.1 m away
  for (std::size_t t : near) {
    const TileInfo& info = map.tiles()[t];
    EXPECT_LT(info.min.x(), 40.0);
    EXPECT_LT(info.min.y(), 40.0);
  }
  EXPECT_EQ(map.tilesWithin({50.0, 50.0}, 200.0).size(), 25u);
  EXPECT_TRUE(map.tilesWithin({-500.0, 0.0}, 150.0).empty());
}

TEST(DynamicMap, TargetFollowsTheVehicleAndHoldsOnlyTheTilesInRange) {
  testing::TempDir dir;
  NdtConfig ndt;
  MapUpdateConfig config;
  config.radius = 25.0;
  DynamicMap map(TileMap::open(writeTiles(dir, 6)), ndt, config);
  map.update({10.0, 10.0});
  ASSERT_NE(map.target(), nullptr);
  const DynamicMapStats first = map.stats();
  EXPECT_EQ(first.builds, 1u);
  EXPECT_LE(first.tiles_in_target, 9u);
  const auto old_target = map.target();
  map.update({15.0, 10.0});  // 5 m: below update_distance, no rebuild
  map.waitIdle();
  EXPECT_EQ(map.stats().builds, 1u);
  map.update({90.0, 90.0});  // far: rebuilt in the background, then swapped in
  map.waitIdle();
  EXPECT_EQ(map.stats().builds, 2u);
  EXPECT_NE(map.target(), old_target);
  EXPECT_LE(map.stats().tiles_in_target, 9u);
  // The old target stayed usable while the new one was built: it is still a valid object now.
  EXPECT_GT(old_target->voxelCount(), 0u);
}

TEST(DynamicMap, MapsSharingATargetCacheBuildEachSetOfTilesOnceAndGetTheSameTarget) {
  testing::TempDir dir;
  const std::string folder = writeTiles(dir, 6);
  NdtConfig ndt;
  MapUpdateConfig config;
  config.radius = 25.0;
  config.background = false;
  auto cache = std::make_shared<TargetCache>(4);
  DynamicMap a(TileMap::open(folder), ndt, config, cache), b(TileMap::open(folder), ndt, config, cache);
  a.update({10.0, 10.0});
  b.update({11.0, 9.0});  // another centre, the same tiles
  EXPECT_EQ(a.target(), b.target());
  EXPECT_EQ(cache->stats().builds, 1u);
  EXPECT_EQ(cache->stats().requests, 2u);
  // Another resolution is another target, even on the same tiles.
  NdtConfig coarse = ndt;
  coarse.resolution = 4.0;
  DynamicMap c(TileMap::open(folder), coarse, config, cache);
  c.update({10.0, 10.0});
  EXPECT_NE(c.target(), a.target());
  EXPECT_EQ(cache->stats().builds, 2u);
  // The cached target holds what an uncached build of the same tiles holds.
  DynamicMap alone(TileMap::open(folder), ndt, config);
  alone.update({10.0, 10.0});
  EXPECT_EQ(alone.target()->voxelCount(), a.target()->voxelCount());
  EXPECT_EQ(alone.target()->pointCount(), a.target()->pointCount());
  EXPECT_EQ(alone.stats().points_in_target, a.stats().points_in_target);
  // Past its capacity the cache forgets the least recently used set of tiles; maps keep theirs.
  const auto kept = a.target();
  for (double x : {50.0, 90.0, 110.0, 30.0}) b.update({x, x});
  EXPECT_EQ(cache->stats().builds, 6u);
  a.update({80.0, 10.0});
  b.update({80.0, 10.0});
  EXPECT_EQ(a.target(), b.target());
  EXPECT_GT(kept->voxelCount(), 0u);
}

TEST(TargetCache, AFailedBuildReachesItsCallerAndIsNotKept) {
  TargetCache cache(2);
  NdtConfig ndt;
  EXPECT_THROW(cache.get("m", {1, 2}, ndt, []() -> std::shared_ptr<const NdtTarget> { throw Error("tile unreadable"); }), Error);
  PointCloud cloud;
  for (int i = 0; i < 200; ++i) cloud.points.emplace_back(0.01f * i, 0.013f * (i % 17), 0.007f * (i % 5));
  const auto built = cache.get("m", {1, 2}, ndt, [&] { return std::make_shared<const NdtTarget>(cloud, ndt); });
  ASSERT_NE(built, nullptr);
  EXPECT_EQ(cache.stats().builds, 2u);
  EXPECT_EQ(cache.get("m", {1, 2}, ndt, []() -> std::shared_ptr<const NdtTarget> { throw Error("not called"); }), built);
}

TEST(DynamicMap, ScanAlignsAgainstTheTilesAroundIt) {
  testing::TempDir dir;
  NdtConfig ndt;
  MapUpdateConfig config;
  config.background = false;
  DynamicMap map(TileMap::open(writeTiles(dir, 4)), ndt, config);
  map.update({40.0, 40.0});
  // A "scan" cut from the map around (40, 40), shifted by a known offset.
  PointCloud scan;
  for (const auto& p : TileMap::open(dir / "tiles").load(5).points) scan.points.push_back(p - Eigen::Vector3f(40.0f, 40.0f, 0.0f));
  Eigen::Matrix4d guess = Eigen::Matrix4d::Identity();
  guess.topRightCorner<3, 1>() = Eigen::Vector3d(40.3, 39.8, 0.0);
  const AlignResult r = align(*map.target(), scan, guess, ndt);
  // The synthetic world is a plane with thin posts: NDT's optimum sits within a few cm of the truth.
  EXPECT_NEAR(r.transform(0, 3), 40.0, 0.1);
  EXPECT_NEAR(r.transform(1, 3), 40.0, 0.1);
}

TEST(TileMap, BadMapsGiveErrorsNamingThePath) {
  testing::TempDir dir;
  EXPECT_THROW(TileMap::open(dir / "nothing_here"), Error);
  std::filesystem::create_directories(dir / "empty");
  try {
    TileMap::open(dir / "empty");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no .pcd tile"), std::string::npos);
  }
  std::filesystem::create_directories(dir / "corrupt");
  std::ofstream(dir / "corrupt/bad.pcd") << "garbage";
  try {
    TileMap::open(dir / "corrupt");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.pcd"), std::string::npos) << e.what();
  }
}

TEST(TileMap, SingleFileIsSlicedIntoTiles) {
  PointCloud cloud;
  for (int tx = 0; tx < 3; ++tx) {
    const PointCloud t = syntheticTile(tx, 0);
    cloud.points.insert(cloud.points.end(), t.points.begin(), t.points.end());
  }
  const TileMap map = TileMap::fromCloud(cloud, 20.0);
  EXPECT_EQ(map.tiles().size(), 3u);
  EXPECT_EQ(map.load(1).size(), map.tiles()[1].points);
}

}  // namespace
}  // namespace coloc::ndt
