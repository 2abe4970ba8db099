// NDT's basin of convergence on the real HDL-32E pair: from 20 seeded starts at a given offset from
// the reference pose (a horizontal translation of that length in a random direction, a yaw of that
// angle with a random sign), how many alignments end within 5 cm and 0.5 deg of the reference, for the
// 16k-point input (0.1 m voxels) and the Autoware-sized one (~1k points, 1 m voxels), fast backend with
// its defaults, 2 threads. Prints a table; counts, not times.
//
//   build/bench/ndt_basin
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <algorithm>

#include "coloc/ndt/aligner.hpp"
#include "coloc/ndt/pcd_file.hpp"
#include "coloc/ndt/preprocess.hpp"
#include "real_data.hpp"
#include "seeded_starts.hpp"

using namespace coloc;
using namespace coloc::ndt;

namespace {

struct Outcome {
  int converged = 0;
  double worst_cm = 0.0, median_iterations = 0.0;
};

Outcome basin(const NdtTarget& target, const PointCloud& source, const Eigen::Matrix4d& reference, double metres, double degrees,
              const NdtConfig& config) {
  Outcome out;
  std::vector<int> iterations;
  for (const Eigen::Matrix4d& guess : testing::seededStarts(reference, metres, degrees)) {
    const AlignResult r = align(target, source, guess, config);
    const auto [m, deg] = testing::poseDifference(r.transform, reference);
    if (m <= 0.05 && deg <= 0.5) ++out.converged;
    out.worst_cm = std::max(out.worst_cm, 100.0 * m);
    iterations.push_back(r.iterations);
  }
  std::sort(iterations.begin(), iterations.end());
  out.median_iterations = iterations[iterations.size() / 2];
  return out;
}

}  // namespace

int main() {
  const PointCloud map = loadPcd(testing::realData("hdl32e_pair/target.pcd"));
  const PointCloud raw = loadPcd(testing::realData("hdl32e_pair/source.pcd"));
  const PointCloud dense = voxelDownsample(raw, 0.1);
  PreprocessConfig pre;
  pre.voxel_size = 1.0;
  const PointCloud sparse = preprocessScan(raw, pre);
  const Eigen::Matrix4d reference = testing::readMatrix4(testing::realData("hdl32e_pair/T_target_source.gt1.txt"));
  NdtConfig config;
  config.threads = 2;
  const NdtTarget target(map, config);
  std::printf("NDT basin, fast backend defaults: starts of 20 ending within 5 cm / 0.5 deg of the reference\n");
  std::printf("%-26s %-14s %10s %12s %16s\n", "input", "start offset", "converged", "worst (cm)", "median iterations");
  for (const auto& [name, cloud] : {std::pair<const char*, const PointCloud*>{"16k points (0.1 m voxels)", &dense},
                                    std::pair<const char*, const PointCloud*>{"1k points (1 m voxels)", &sparse}})
    for (const auto& [m, d] : {std::pair<double, double>{1.0, 5.0}, std::pair<double, double>{2.0, 10.0}}) {
      const Outcome o = basin(target, *cloud, reference, m, d, config);
      char offset[32];
      std::snprintf(offset, sizeof offset, "%.0f m / %.0f deg", m, d);
      std::printf("%-26s %-14s %7d/20 %12.1f %16.0f\n", name, offset, o.converged, o.worst_cm, o.median_iterations);
    }
  return 0;
}
