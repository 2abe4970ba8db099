// coloc's fast NDT beside ndt_omp (DIRECT7, DIRECT1) and small_gicp (VGICP) on the real HDL-32E pair:
// one process, the same inputs, 2 threads then 1. The dense case starts from identity, the
// Autoware-sized one 0.5 m / 2 deg off; target builds are excluded (small_gicp's voxel map is built once,
// its per-scan covariance estimation is timed). Prints medians (15 and 51 runs) and the distance of
// each result from the reference GT1. See CMakeLists.txt for how to build it.
//
//   build-peers/peer_bench
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pclomp/ndt_omp.h>
#include <small_gicp/registration/registration_helper.hpp>
#include <small_gicp/util/downsampling_omp.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "coloc/ndt/aligner.hpp"
#include "coloc/ndt/pcd_file.hpp"
#include "coloc/ndt/preprocess.hpp"
#include "real_data.hpp"
#include "seeded_starts.hpp"

using namespace coloc;
using Clock = std::chrono::steady_clock;

static pcl::PointCloud<pcl::PointXYZ>::Ptr toPcl(const ndt::PointCloud& c) {
  auto out = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  for (const auto& p : c.points) out->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  return out;
}

struct Row { double ms; double cm; double deg; };

static Row measure(int runs, const Eigen::Matrix4d& gt, const std::function<Eigen::Matrix4d()>& run) {
  std::vector<double> t;
  Eigen::Matrix4d r;
  for (int i = 0; i < runs; ++i) {
    const auto t0 = Clock::now();
    r = run();
    t.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
  }
  std::sort(t.begin(), t.end());
  const auto [m, deg] = testing::poseDifference(r, gt);
  return {t[t.size() / 2], 100.0 * m, deg};
}

int main() {
  const ndt::PointCloud target = ndt::loadPcd(testing::realData("hdl32e_pair/target.pcd"));
  const ndt::PointCloud raw = ndt::loadPcd(testing::realData("hdl32e_pair/source.pcd"));
  const ndt::PointCloud dense = ndt::voxelDownsample(raw, 0.1);
  ndt::PreprocessConfig pre;
  pre.voxel_size = 1.0;
  const ndt::PointCloud sparse = ndt::preprocessScan(raw, pre);
  const Eigen::Matrix4d gt = testing::readMatrix4(testing::realData("hdl32e_pair/T_target_source.gt1.txt"));
  const Eigen::Matrix4d offset = testing::offsetPose(gt, 2.0 * M_PI / 180.0, Eigen::Vector3d(0.4, -0.3, 0.0));
  const auto target_pcl = toPcl(target), dense_pcl = toPcl(dense), sparse_pcl = toPcl(sparse);
  std::printf("inputs: target %zu points, dense source %zu, Autoware-sized source %zu\n", target.size(), dense.size(), sparse.size());
  std::printf("%-28s %7s | %9s %7s %7s | %9s %7s %7s\n", "contender", "threads", "dense ms", "cm", "deg", "1k ms", "cm", "deg");
  for (int threads : {2, 1}) {
    auto line = [&](const char* name, const Row& a, const Row& b) {
      std::printf("%-28s %7d | %9.2f %7.2f %7.3f | %9.2f %7.2f %7.3f\n", name, threads, a.ms, a.cm, a.deg, b.ms, b.cm, b.deg);
    };
    {  // coloc fast, radius (the default)
      for (auto hood : {ndt::Neighborhood::kRadius, ndt::Neighborhood::kFace7, ndt::Neighborhood::kSingle}) {
        ndt::NdtConfig c;
        c.threads = threads;
        c.neighborhood = hood;
        const ndt::NdtTarget t(target, c);
        const Row a = measure(15, gt, [&] { return ndt::align(t, dense, Eigen::Matrix4d::Identity(), c).transform; });
        const Row b = measure(51, gt, [&] { return ndt::align(t, sparse, offset, c).transform; });
        line(hood == ndt::Neighborhood::kRadius ? "coloc fast (radius)" : hood == ndt::Neighborhood::kFace7 ? "coloc fast face7" : "coloc fast single", a, b);
      }
    }
    for (auto method : {pclomp::DIRECT7, pclomp::DIRECT1}) {
      pclomp::NormalDistributionsTransform<pcl::PointXYZ, pcl::PointXYZ> ndt;
      ndt.setResolution(2.0);
      ndt.setStepSize(0.1);
      ndt.setTransformationEpsilon(0.01);
      ndt.setMaximumIterations(30);
      ndt.setNumThreads(threads);
      ndt.setNeighborhoodSearchMethod(method);
      ndt.setInputTarget(target_pcl);
      pcl::PointCloud<pcl::PointXYZ> out;
      auto run = [&](const pcl::PointCloud<pcl::PointXYZ>::Ptr& s, const Eigen::Matrix4d& g) {
        ndt.setInputSource(s);
        ndt.align(out, g.cast<float>());
        return Eigen::Matrix4d(ndt.getFinalTransformation().cast<double>());
      };
      const Row a = measure(15, gt, [&] { return run(dense_pcl, Eigen::Matrix4d::Identity()); });
      const Row b = measure(51, gt, [&] { return run(sparse_pcl, offset); });
      line(method == pclomp::DIRECT7 ? "ndt_omp DIRECT7" : "ndt_omp DIRECT1", a, b);
    }
    {  // small_gicp VGICP: target voxel map built once (excluded), source covariances per scan (included)
      std::vector<Eigen::Vector3d> tp, dp, sp;
      for (auto& p : target.points) tp.push_back(p.cast<double>());
      for (auto& p : dense.points) dp.push_back(p.cast<double>());
      for (auto& p : sparse.points) sp.push_back(p.cast<double>());
      auto [tcloud, ttree] = small_gicp::preprocess_points(tp, 0.1, 10, threads);
      auto voxelmap = small_gicp::create_gaussian_voxelmap(*tcloud, 1.0);
      small_gicp::RegistrationSetting setting;
      setting.type = small_gicp::RegistrationSetting::VGICP;
      setting.voxel_resolution = 1.0;
      setting.num_threads = threads;
      auto run = [&](const std::vector<Eigen::Vector3d>& s, const Eigen::Matrix4d& g) {
        auto [scloud, stree] = small_gicp::preprocess_points(s, 0.0001, 10, threads);  // already downsampled: covariances only
        Eigen::Isometry3d init(g);
        return Eigen::Matrix4d(small_gicp::align(*voxelmap, *scloud, init, setting).T_target_source.matrix());
      };
      const Row a = measure(15, gt, [&] { return run(dp, Eigen::Matrix4d::Identity()); });
      const Row b = measure(51, gt, [&] { return run(sp, offset); });
      line("small_gicp VGICP", a, b);
    }
  }
  return 0;
}
