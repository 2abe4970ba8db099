// Ray casting of the twin: rays per second of RayCaster::cast (packets of 8 on every core) against
// castOneByOne (one ray at a time on one thread, the reference), in the same run, on a street of
// houses, trees and cars seen by a 32-beam LiDAR sweep (57,600 rays). And the sweep's noise: the points
// sim::sweepPoints makes of those hits (range noise and dropouts, each ray's own draws) against the same
// loop on the standard library's engine and distributions, two draws per ray in ray order (one thread); and
// the twin's engine against std::mt19937_64, which gives the same numbers, a million numbers at a time.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <random>

#include "coloc/sim/lidar_model.hpp"
#include "coloc/sim/ray_caster.hpp"
#include "standard_sweep.hpp"
#include "street_scene.hpp"

namespace {

using coloc::sim::RayCaster;
using coloc::sim::RayHit;

struct Street {
  RayCaster world;
  std::vector<Eigen::Vector3f> origins, directions;
  std::vector<RayHit> hits;
  Street() {
    coloc::testing::buildStreet(world, origins, directions);
    world.cast(origins, directions, 120.0f, hits);
  }
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

// A whole sweep of the VLP-32C from the street's sensor position through sim::castSweep, without a
// footprint (arguments 0, 0), with Velodyne's 3 mrad across the scan (3, 0), and with its 1.5 mrad up
// and down as well (3, 15; tenths of a mrad): what the footprint's edge samples cost, as ratios in the
// same run.
void BM_CastSweepFootprint(benchmark::State& state) {
  coloc::sim::LidarSpec spec = coloc::sim::vlp32c();
  spec.max_range = 120.0;
  spec.beam_divergence = 1e-3 * static_cast<double>(state.range(0));
  spec.beam_divergence_vertical = 1e-4 * static_cast<double>(state.range(1));
  const Eigen::Vector3d sensor = street().origins.front().cast<double>();
  const coloc::sim::SensorTrajectory pose = [sensor](double) { return Eigen::Isometry3d(Eigen::Translation3d(sensor)); };
  std::vector<RayHit> hits;
  for (auto _ : state) coloc::sim::castSweep(spec, street().world, pose, hits);
  std::size_t edges = 0;  // rays whose return the footprint changed
  const std::vector<RayHit> plain = [&] {
    coloc::sim::LidarSpec without = spec;
    without.beam_divergence = without.beam_divergence_vertical = 0.0;
    return coloc::sim::castSweep(without, street().world, pose);
  }();
  for (std::size_t i = 0; i < hits.size(); ++i) edges += hits[i].distance != plain[i].distance ? 1 : 0;
  state.counters["changed_share"] = static_cast<double>(edges) / static_cast<double>(hits.size());
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * hits.size()));
}

// A VLP-32C with range-dependent noise and dropouts (its sweep is the street's 57,600 rays).
coloc::sim::LidarSpec noisySpec() {
  coloc::sim::LidarSpec spec = coloc::sim::vlp32c();
  spec.range_noise_per_m = 0.0002;
  spec.dropout = 0.01;
  spec.dropout_at_max_range = 0.2;
  return spec;
}

// The reference: per ray a std::normal_distribution and a std::uniform_real_distribution draw on
// std::mt19937_64 (each ray's noisy range kept as a hit: the same work less the points' directions).
void BM_SweepNoiseStandardLibrary(benchmark::State& state) {
  const coloc::sim::LidarSpec spec = noisySpec();
  std::mt19937_64 rng(1);
  std::vector<RayHit> kept;
  for (auto _ : state) {
    coloc::testing::standardSweepRanges(spec, street().hits, rng, kept);
    benchmark::DoNotOptimize(kept.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * street().hits.size()));
}

void BM_SweepNoise(benchmark::State& state) {
  const coloc::sim::LidarSpec spec = noisySpec();
  coloc::sim::RandomEngine rng(1);
  std::vector<coloc::sim::LidarPoint> points;
  for (auto _ : state) {
    coloc::sim::sweepPoints(spec, street().hits, rng, points);
    benchmark::DoNotOptimize(points.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * street().hits.size()));
}

template <typename Engine>
void BM_RandomNumbers(benchmark::State& state) {
  Engine engine(1);
  std::uint64_t sum = 0;
  for (auto _ : state) {
    for (int i = 0; i < 1000000; ++i) sum += engine();
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) * 1000000);
}

BENCHMARK(BM_CastOneByOne)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(BM_CastPackets)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(BM_CastSweepFootprint)->Args({0, 0})->Args({3, 0})->Args({3, 15})->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(BM_SweepNoiseStandardLibrary)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK(BM_SweepNoise)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK_TEMPLATE(BM_RandomNumbers, std::mt19937_64)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);
BENCHMARK_TEMPLATE(BM_RandomNumbers, coloc::sim::RandomEngine)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);

}  // namespace

BENCHMARK_MAIN();
