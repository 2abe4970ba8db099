// Memory and time of the dynamic NDT map as the map grows: a diagonal drive through square maps of
// 20 x 20, 40 x 40 and 80 x 80 tiles (20 m tiles, 400 m to 1.6 km across). Each size runs in a child
// process so that its peak resident memory (VmHWM) is its own. The target holds only the tiles within
// 150 m of the vehicle, so peak memory and target size must stay flat while the map grows 16-fold.
//
//   build/bench/map_bench
#include <benchmark/benchmark.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "coloc/ndt/pcd_file.hpp"
#include "coloc/ndt/tile_map.hpp"

namespace {

using namespace coloc::ndt;
namespace fs = std::filesystem;

// Ground at 1 m spacing and a few posts per tile: 20 m x 20 m, about 1,700 points.
PointCloud tileAt(int tx, int ty) {
  PointCloud tile;
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 20; ++j) {
      const float x = 20.0f * tx + i + 0.5f, y = 20.0f * ty + j + 0.5f;
      tile.points.emplace_back(x, y, 0.05f * std::sin(0.7f * x) * std::cos(0.3f * y));
      if ((i * 7 + j * 3 + tx + ty) % 31 == 0)
        for (int k = 0; k < 40; ++k) tile.points.emplace_back(x + 0.05f * (k % 3), y + 0.05f * (k % 5), 0.1f * k);
    }
  return tile;
}

std::string makeMap(int tiles_per_side) {
  const fs::path dir = fs::temp_directory_path() / ("coloc_map_bench_" + std::to_string(getpid()) + "_" + std::to_string(tiles_per_side));
  fs::create_directories(dir);
  for (int tx = 0; tx < tiles_per_side; ++tx)
    for (int ty = 0; ty < tiles_per_side; ++ty)
      savePcd((dir / ("tile_" + std::to_string(tx) + "_" + std::to_string(ty) + ".pcd")).string(), tileAt(tx, ty));
  return dir.string();
}

long peakRssKb() {
  std::ifstream status("/proc/self/status");
  std::string key;
  long value = 0;
  while (status >> key) {
    if (key == "VmHWM:") {
      status >> value;
      return value;
    }
    status.ignore(4096, '\n');
  }
  return 0;
}

struct DriveReport {
  double seconds;
  long peak_rss_kb;
  double max_target_points;
  double max_target_tiles;
  double builds;
  double map_points;
};

// Drives diagonally across the map, 1 m per step, telling the map where the vehicle is.
DriveReport drive(const std::string& folder, int tiles_per_side) {
  const auto start = std::chrono::steady_clock::now();
  NdtConfig ndt;
  MapUpdateConfig config;
  config.background = true;
  TileMap map = TileMap::open(folder);
  double map_points = 0;
  for (const auto& t : map.tiles()) map_points += static_cast<double>(t.points);
  DynamicMap dynamic(std::move(map), ndt, config);
  DriveReport r{};
  const double extent = 20.0 * tiles_per_side;
  for (double s = 0.0; s <= extent; s += 1.0) {
    dynamic.update({s, s});
    dynamic.waitIdle();  // a vehicle aligns scans between updates; let every rebuild finish
    const DynamicMapStats st = dynamic.stats();
    r.max_target_points = std::max(r.max_target_points, static_cast<double>(st.points_in_target));
    r.max_target_tiles = std::max(r.max_target_tiles, static_cast<double>(st.tiles_in_target));
  }
  dynamic.waitIdle();
  r.builds = static_cast<double>(dynamic.stats().builds);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.peak_rss_kb = peakRssKb();
  r.map_points = map_points;
  return r;
}

void BM_DynamicMapDrive(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const std::string folder = makeMap(n);
  DriveReport report{};
  for (auto _ : state) {
    int pipe_fd[2];
    if (pipe(pipe_fd) != 0) {
      state.SkipWithError("pipe failed");
      break;
    }
    const pid_t child = fork();
    if (child == 0) {
      close(pipe_fd[0]);
      const DriveReport r = drive(folder, n);
      if (write(pipe_fd[1], &r, sizeof r) != static_cast<ssize_t>(sizeof r)) _exit(1);
      _exit(0);
    }
    close(pipe_fd[1]);
    if (read(pipe_fd[0], &report, sizeof report) != static_cast<ssize_t>(sizeof report)) state.SkipWithError("child failed");
    close(pipe_fd[0]);
    waitpid(child, nullptr, 0);
    state.SetIterationTime(report.seconds);
  }
  fs::remove_all(folder);
  state.counters["map_tiles"] = n * n;
  state.counters["map_points"] = report.map_points;
  state.counters["target_points_max"] = report.max_target_points;
  state.counters["target_tiles_max"] = report.max_target_tiles;
  state.counters["builds"] = report.builds;
  state.counters["peak_rss_MB"] = report.peak_rss_kb / 1024.0;
}
BENCHMARK(BM_DynamicMapDrive)->Arg(20)->Arg(40)->Arg(80)->Iterations(1)->UseManualTime()->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
