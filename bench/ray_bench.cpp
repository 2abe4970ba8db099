// Ray casting of the twin: rays per second of RayCaster::cast (packets of 8 on every core) against
// castOneByOne (one ray at a time on one thread, the reference), in the same run, on a street of
// houses, trees and cars seen by a 32-beam LiDAR sweep (57,600 rays).
#include <benchmark/benchmark.h>

#include <cstdio>

#include "coloc/sim/ray_caster.hpp"
#include "street_scene.hpp"

namespace {

using coloc::sim::RayCaster;
using coloc::sim::RayHit;

struct Street {
  RayCaster world;
  std::vector<Eigen::Vector3f> origins, directions;
  Street() { coloc::testing::buildStreet(world, origins, directions); }
};

Street& street() {
  static Street s;
  return s;
}

void BM_CastOneByOne(benchmark::State& state) {
  std::vector<RayHit> hits;
  for (auto _ : state) street().world.castOneByOne(street().origins, street().directions, 120.0f, hits);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * street().origins.size()));
}

void BM_CastPackets(benchmark::State& state) {
  std::vector<RayHit> hits;
  for (auto _ : state) street().world.cast(street().origins, street().directions, 120.0f, hits);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * street().origins.size()));
}

BENCHMARK(BM_CastOneByOne)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(BM_CastPackets)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);

}  // namespace

BENCHMARK_MAIN();
