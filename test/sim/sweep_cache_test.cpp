#include <gtest/gtest.h>

#include "coloc/core/error.hpp"
#include "coloc/sim/lidar_model.hpp"
#include "coloc/sim/sweep_cache.hpp"

namespace coloc::sim {
namespace {

// Two drives past the same wall, each with its own noise seed: with a shared cache the second casts
// nothing and gets exactly the points it gets without the cache; a drive on another path is cast
// afresh.
TEST(SweepCache, ASecondDriveGetsTheSamePointsWithoutCastingAndAnotherPathIsCastAfresh) {
  RayCaster world;
  world.addMesh(groundRectangle({-100, -100}, {100, 100}));
  world.addMesh(box({30, 0, 0}, {1, 200, 10}));
  world.commit();
  const LidarSpec spec = vlp16();
  auto path = [](double speed) {
    return [speed](double t) { return Eigen::Isometry3d(Eigen::Translation3d(speed * t, 0.0, 1.8)); };
  };
  SweepCache cache;
  for (std::uint64_t seed : {1u, 2u}) {
    RandomEngine uncached(seed), cached(seed);
    const auto plain = scanSweep(spec, world, path(10.0), uncached);
    const auto hits = cache.get(0, sweepFingerprint(spec, path(10.0)), [&] { return castSweep(spec, world, path(10.0)); });
    const auto shared = sweepPoints(spec, *hits, cached);
    ASSERT_EQ(plain.size(), shared.size());
    for (std::size_t i = 0; i < plain.size(); ++i) {
      EXPECT_EQ(plain[i].position, shared[i].position);
      EXPECT_EQ(plain[i].time, shared[i].time);
      EXPECT_EQ(plain[i].laser, shared[i].laser);
    }
  }
  EXPECT_EQ(cache.stats().cast, 1u);
  EXPECT_EQ(cache.stats().served, 1u);
  // Another speed: another fingerprint, cast, and the first drive's sweep stays.
  int casts = 0;
  cache.get(0, sweepFingerprint(spec, path(15.0)), [&] { ++casts; return castSweep(spec, world, path(15.0)); });
  EXPECT_EQ(casts, 1);
  cache.get(0, sweepFingerprint(spec, path(10.0)), [&] { ++casts; return castSweep(spec, world, path(10.0)); });
  EXPECT_EQ(casts, 1);
  // What moves in the world is part of the fingerprint when the caller gives it.
  const double here[2] = {5.0, 1.0}, there[2] = {5.0, 1.5};
  EXPECT_NE(sweepFingerprint(spec, path(10.0), here, 2), sweepFingerprint(spec, path(10.0), there, 2));
  EXPECT_GT(cache.bytes(), 0u);
}

TEST(SweepCache, HitsOfAnotherLidarAreRefusedWithAnErrorNamingIt) {
  RayCaster world;
  world.addMesh(box({10, 0, 0}, {2, 10, 5}));
  world.commit();
  const auto hits = castSweep(vlp16(), world, [](double) { return Eigen::Isometry3d::Identity(); });
  RandomEngine rng(1);
  try {
    sweepPoints(vlp32c(), hits, rng);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("VLP-32C"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace coloc::sim
