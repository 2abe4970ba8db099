// NDT cost, stock PCL against coloc's fast backend, measured side by side in one run:
//  - the real HDL-32E pair, 0.1 m voxel source (~16k points), resolution 2.0, from identity;
//  - Autoware-sized input (~1,000-1,500 points) from a 0.5 m / 2 deg initial offset;
//  - building the target from the 487k-point airborne tile;
//  - preprocessing the raw scan as the pipeline does (range crop, 3 m voxels): pcl::VoxelGrid after a
//    crop, as Autoware's downsampling does, against coloc's one pass; the same with per-point times and
//    deskewing;
//  - the Autoware-sized alignment with each covariance (fixed, laplace, multi_ndt_score).
// Ends with a table of medians, ratios and the pose agreement of the two backends.
//
//   build/bench/ndt_bench
#include <benchmark/benchmark.h>

#include <algorithm>

#include "median_collector.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>

#include "coloc/ndt/aligner.hpp"
#include "coloc/ndt/pcd_file.hpp"
#include "coloc/ndt/preprocess.hpp"
#include "real_data.hpp"

#include <pcl/filters/voxel_grid.h>
#include <pcl/point_types.h>

namespace {

using namespace coloc;
using namespace coloc::ndt;

struct Data {
  PointCloud target, raw, source_dense, source_autoware, als;
  Eigen::Matrix4d gt1, offset_guess;
};

const Data& data() {
  static const Data d = [] {
    Data d;
    d.target = loadPcd(testing::realData("hdl32e_pair/target.pcd"));
    d.raw = loadPcd(testing::realData("hdl32e_pair/source.pcd"));
    const PointCloud& raw = d.raw;
    d.source_dense = voxelDownsample(raw, 0.1);
    PreprocessConfig pre;
    pre.voxel_size = 1.0;  // Autoware's 3 m leaves only ~240 points of this scan; 1 m gives ~1,000
    d.source_autoware = preprocessScan(raw, pre);
    d.als = loadPcd(testing::realData("als_tile/csite2_demeaned.pcd"));
    d.gt1 = testing::readMatrix4(testing::realData("hdl32e_pair/T_target_source.gt1.txt"));
    d.offset_guess = d.gt1;
    d.offset_guess.topLeftCorner<3, 3>() = Eigen::AngleAxisd(2.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()) * d.gt1.topLeftCorner<3, 3>();
    d.offset_guess.topRightCorner<3, 1>() += Eigen::Vector3d(0.4, -0.3, 0.0);
    return d;
  }();
  return d;
}

NdtConfig configFor(NdtBackend backend) {
  NdtConfig c;
  c.backend = backend;
  return c;
}

std::map<std::string, Eigen::Matrix4d> final_pose;  // last result per benchmark, for the agreement check

void BM_AlignDense(benchmark::State& state) {
  const NdtConfig config = configFor(static_cast<NdtBackend>(state.range(0)));
  const NdtTarget target(data().target, config);
  AlignResult r;
  for (auto _ : state) r = align(target, data().source_dense, Eigen::Matrix4d::Identity(), config);
  state.counters["iterations"] = r.iterations;
  state.counters["points"] = static_cast<double>(data().source_dense.size());
  final_pose[std::string("dense/") + std::to_string(state.range(0))] = r.transform;
}

void BM_AlignAutowareSized(benchmark::State& state) {
  const NdtConfig config = configFor(static_cast<NdtBackend>(state.range(0)));
  const NdtTarget target(data().target, config);
  AlignResult r;
  for (auto _ : state) r = align(target, data().source_autoware, data().offset_guess, config);
  state.counters["iterations"] = r.iterations;
  state.counters["points"] = static_cast<double>(data().source_autoware.size());
  final_pose[std::string("autoware/") + std::to_string(state.range(0))] = r.transform;
}

void BM_BuildTargetAls(benchmark::State& state) {
  const NdtConfig config = configFor(static_cast<NdtBackend>(state.range(0)));
  std::size_t voxels = 0;
  for (auto _ : state) voxels = NdtTarget(data().als, config).voxelCount();
  state.counters["voxels"] = static_cast<double>(voxels);
  state.counters["points"] = static_cast<double>(data().als.size());
}

// Points left by pcl::VoxelGrid at `leaf` (Autoware's downsampling).
std::size_t pclVoxelGridSize(const pcl::PointCloud<pcl::PointXYZ>::Ptr& cloud, double leaf) {
  pcl::VoxelGrid<pcl::PointXYZ> grid;
  grid.setLeafSize(static_cast<float>(leaf), static_cast<float>(leaf), static_cast<float>(leaf));
  grid.setInputCloud(cloud);
  pcl::PointCloud<pcl::PointXYZ> out;
  grid.filter(out);
  return out.size();
}

// Argument 0: pcl::VoxelGrid after a range crop; 1: coloc's preprocessScan (crop, deskew, voxels in one pass).
void BM_PreprocessScan(benchmark::State& state) {
  PreprocessConfig pre;
  pre.max_points = 0;  // the downsampling alone
  std::size_t kept = 0;
  if (state.range(0) == static_cast<int>(NdtBackend::kPcl)) {
    for (auto _ : state) {
      auto cropped = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
      cropped->reserve(data().raw.size());
      const double lo = pre.min_range * pre.min_range, hi = pre.max_range * pre.max_range;
      for (const Eigen::Vector3f& p : data().raw.points) {
        const double r = p.cast<double>().squaredNorm();
        if (r >= lo && r <= hi) cropped->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
      }
      kept = pclVoxelGridSize(cropped, pre.voxel_size);
    }
  } else {
    for (auto _ : state) kept = preprocessScan(data().raw, pre).size();
  }
  state.counters["points"] = static_cast<double>(data().raw.size());
  state.counters["kept"] = static_cast<double>(kept);
}

// The same with per-point times and the motion undone at 8 m/s, 0.1 rad/s, as the twin's and a driver's
// scans reach the pipeline: in firing order, the lasers of a firing sharing its time (a 10 Hz sweep of
// 1,800 firings, the firing from the point's azimuth). Argument 0: the crop and the deskew one point at a
// time, then pcl::VoxelGrid; 1: coloc's preprocessScan.
void BM_PreprocessScanDeskewed(benchmark::State& state) {
  static const PointCloud timed = [] {
    const PointCloud& raw = data().raw;
    std::vector<std::pair<int, std::size_t>> order;
    for (std::size_t i = 0; i < raw.size(); ++i) {
      const Eigen::Vector3f& p = raw.points[i];
      order.push_back({static_cast<int>(1800.0 * (std::atan2(p.y(), p.x()) + M_PI) / (2.0 * M_PI)) % 1800, i});
    }
    std::stable_sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    PointCloud c;
    for (const auto& [firing, i] : order) {
      c.points.push_back(raw.points[i]);
      c.times.push_back(static_cast<float>(0.1 * firing / 1800.0));
    }
    return c;
  }();
  PreprocessConfig pre;
  pre.max_points = 0;
  std::size_t kept = 0;
  if (state.range(0) == static_cast<int>(NdtBackend::kPcl)) {
    for (auto _ : state) {
      const PointCloud moved = deskew(cropRange(timed, pre.min_range, pre.max_range), 8.0, 0.1);
      auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
      cloud->reserve(moved.size());
      for (const Eigen::Vector3f& p : moved.points) cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
      kept = pclVoxelGridSize(cloud, pre.voxel_size);
    }
  } else {
    for (auto _ : state) kept = preprocessScan(timed, pre, 8.0, 0.1).size();
  }
  state.counters["points"] = static_cast<double>(timed.size());
  state.counters["kept"] = static_cast<double>(kept);
}

// The fast backend's alignment with each covariance (argument: CovarianceMode), Autoware-sized input:
// what the covariance adds to a scan's cost.
void BM_CovarianceAutowareSized(benchmark::State& state) {
  NdtConfig config;
  config.covariance = static_cast<CovarianceMode>(state.range(0));
  const NdtTarget target(data().target, config);
  AlignResult r;
  for (auto _ : state) r = align(target, data().source_autoware, data().offset_guess, config);
  state.counters["sd_x_cm"] = 100.0 * std::sqrt(r.covariance(0, 0));
  state.counters["sd_y_cm"] = 100.0 * std::sqrt(r.covariance(1, 1));
}

void backends(benchmark::internal::Benchmark* b) {
  b->Arg(static_cast<int>(NdtBackend::kPcl))->Arg(static_cast<int>(NdtBackend::kFast));
  b->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true)->UseRealTime();
}
BENCHMARK(BM_AlignDense)->Apply(backends)->Iterations(3);
BENCHMARK(BM_AlignAutowareSized)->Apply(backends)->Iterations(20);
BENCHMARK(BM_BuildTargetAls)->Apply(backends)->Iterations(2);
BENCHMARK(BM_PreprocessScan)->Apply(backends)->Iterations(50);
BENCHMARK(BM_PreprocessScanDeskewed)->Apply(backends)->Iterations(50);
BENCHMARK(BM_CovarianceAutowareSized)
    ->Arg(static_cast<int>(CovarianceMode::kFixed))
    ->Arg(static_cast<int>(CovarianceMode::kLaplace))
    ->Arg(static_cast<int>(CovarianceMode::kMultiNdtScore))
    ->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true)->UseRealTime()->Iterations(20);


}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  coloc::bench::MedianCollector reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  const std::string pcl = std::to_string(static_cast<int>(NdtBackend::kPcl));
  const std::string fast = std::to_string(static_cast<int>(NdtBackend::kFast));
  std::printf("\nMedian milliseconds, stock pcl::NormalDistributionsTransform vs coloc fast backend (resolution 2.0)\n");
  std::printf("%-44s %10s %10s %8s\n", "case", "pcl", "fast", "ratio");
  const std::pair<const char*, const char*> cases[] = {
      {"BM_AlignDense", "HDL-32E pair, 0.1 m voxel source, identity"},
      {"BM_AlignAutowareSized", "HDL-32E, 1 m voxel source, 0.5 m / 2 deg off"},
      {"BM_BuildTargetAls", "target build, ALS tile (487k points)"},
      {"BM_PreprocessScan", "preprocessing the raw scan (crop, 3 m voxels)"},
      {"BM_PreprocessScanDeskewed", "the same with per-point times, deskewed"}};
  for (const auto& [name, label] : cases) {
    auto& m = reporter.medians[name];
    if (!m.count(pcl) || !m.count(fast)) continue;
    std::printf("%-44s %10.2f %10.2f %7.1fx\n", label, m[pcl], m[fast], m[pcl] / m[fast]);
  }
  auto& cov = reporter.medians["BM_CovarianceAutowareSized"];
  const std::string fixed = std::to_string(static_cast<int>(CovarianceMode::kFixed));
  if (cov.count(fixed))
    for (const CovarianceMode mode : {CovarianceMode::kLaplace, CovarianceMode::kMultiNdtScore})
      if (const auto m = cov.find(std::to_string(static_cast<int>(mode))); m != cov.end())
        std::printf("alignment with covariance %-16s %.3f ms against %.3f ms fixed (%.2fx), 1 m voxel source\n", covarianceModeName(mode), m->second,
                    cov[fixed], m->second / cov[fixed]);
  for (const char* which : {"dense", "autoware"}) {
    const auto a = final_pose.find(std::string(which) + "/" + pcl), b = final_pose.find(std::string(which) + "/" + fast);
    if (a == final_pose.end() || b == final_pose.end()) continue;
    const auto [m, deg] = testing::poseDifference(a->second, b->second);
    const auto [m_gt, deg_gt] = testing::poseDifference(b->second, data().gt1);
    std::printf("%-9s fast vs pcl: %.2f cm, %.3f deg; fast vs GT1: %.2f cm, %.3f deg\n", which, 100 * m, deg, 100 * m_gt, deg_gt);
  }
  benchmark::Shutdown();
  return 0;
}
