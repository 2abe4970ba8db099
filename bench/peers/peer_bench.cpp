// coloc's fast NDT beside ndt_omp (DIRECT7, DIRECT1) and small_gicp (VGICP) on the real HDL-32E pair:
// one process, the same inputs, 2 threads then 1. The dense case starts from identity, the
// Autoware-sized one 0.5 m / 2 deg off. Each timed region is the alignment of an already prepared scan
// against an already built target: target builds are excluded everywhere. small_gicp is timed twice:
// its alignment alone (source covariances estimated once, outside), and its per-scan covariance
// estimation (k-d tree and 10-neighbour covariances, at the thread count of the row) plus the
// alignment, which is what a scan costs it in a localizer. The contenders run in interleaved rounds
// (each round every contender once, in turn, 15 dense and 51 sparse alignments, their median kept), so
// that a machine's drift between rounds touches every contender alike; printed: the median of the
// rounds' medians and their range, and the distance of each result from the reference GT1. See
// CMakeLists.txt for how to build it.
//
//   build-peers/peer_bench [ROUNDS]     (default 7)
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pclomp/ndt_omp.h>
#include <small_gicp/registration/registration_helper.hpp>
#include <small_gicp/util/downsampling_omp.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
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

struct Contender {
  std::string name;
  int threads;
  std::function<Eigen::Matrix4d()> dense, sparse;
  std::vector<double> dense_ms, sparse_ms;  // each round's median
  Eigen::Matrix4d dense_result, sparse_result;
};

// The median time of `runs` calls, the last call's result kept.
static double medianMs(int runs, const std::function<Eigen::Matrix4d()>& run, Eigen::Matrix4d& result) {
  std::vector<double> t;
  for (int i = 0; i < runs; ++i) {
    const auto t0 = Clock::now();
    result = run();
    t.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

static double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

int main(int argc, char** argv) {
  const int rounds = argc > 1 ? std::max(1, std::atoi(argv[1])) : 7;
  const ndt::PointCloud target = ndt::loadPcd(testing::realData("hdl32e_pair/target.pcd"));
  const ndt::PointCloud raw = ndt::loadPcd(testing::realData("hdl32e_pair/source.pcd"));
  const ndt::PointCloud dense = ndt::voxelDownsample(raw, 0.1);
  ndt::PreprocessConfig pre;
  pre.voxel_size = 1.0;
  const ndt::PointCloud sparse = ndt::preprocessScan(raw, pre);
  const Eigen::Matrix4d gt = testing::readMatrix4(testing::realData("hdl32e_pair/T_target_source.gt1.txt"));
  const Eigen::Matrix4d offset = testing::offsetPose(gt, 2.0 * M_PI / 180.0, Eigen::Vector3d(0.4, -0.3, 0.0));
  const auto target_pcl = toPcl(target), dense_pcl = toPcl(dense), sparse_pcl = toPcl(sparse);
  std::vector<Eigen::Vector3d> tp, dp, sp;
  for (auto& p : target.points) tp.push_back(p.cast<double>());
  for (auto& p : dense.points) dp.push_back(p.cast<double>());
  for (auto& p : sparse.points) sp.push_back(p.cast<double>());
  std::printf("inputs: target %zu points, dense source %zu, Autoware-sized source %zu; %d interleaved rounds\n", target.size(), dense.size(),
              sparse.size(), rounds);

  std::vector<Contender> all;
  for (int threads : {2, 1}) {
    for (auto hood : {ndt::Neighborhood::kRadius, ndt::Neighborhood::kFace7, ndt::Neighborhood::kSingle}) {
      auto c = std::make_shared<ndt::NdtConfig>();
      c->threads = threads;
      c->neighborhood = hood;
      auto t = std::make_shared<ndt::NdtTarget>(target, *c);
      all.push_back({hood == ndt::Neighborhood::kRadius ? "coloc fast (radius)" : hood == ndt::Neighborhood::kFace7 ? "coloc fast face7" : "coloc fast single",
                     threads, [&dense, c, t] { return ndt::align(*t, dense, Eigen::Matrix4d::Identity(), *c).transform; },
                     [&sparse, &offset, c, t] { return ndt::align(*t, sparse, offset, *c).transform; }, {}, {}, {}, {}});
    }
    for (auto method : {pclomp::DIRECT7, pclomp::DIRECT1}) {
      auto ndt = std::make_shared<pclomp::NormalDistributionsTransform<pcl::PointXYZ, pcl::PointXYZ>>();
      ndt->setResolution(2.0);
      ndt->setStepSize(0.1);
      ndt->setTransformationEpsilon(0.01);
      ndt->setMaximumIterations(30);
      ndt->setNumThreads(threads);
      ndt->setNeighborhoodSearchMethod(method);
      ndt->setInputTarget(target_pcl);
      auto run = [ndt](const pcl::PointCloud<pcl::PointXYZ>::Ptr& s, const Eigen::Matrix4d& g) {
        pcl::PointCloud<pcl::PointXYZ> out;
        ndt->setInputSource(s);
        ndt->align(out, g.cast<float>());
        return Eigen::Matrix4d(ndt->getFinalTransformation().cast<double>());
      };
      all.push_back({method == pclomp::DIRECT7 ? "ndt_omp DIRECT7" : "ndt_omp DIRECT1", threads, [run, &dense_pcl] { return run(dense_pcl, Eigen::Matrix4d::Identity()); },
                     [run, &sparse_pcl, &offset] { return run(sparse_pcl, offset); }, {}, {}, {}, {}});
    }
    {
      auto [tcloud, ttree] = small_gicp::preprocess_points(tp, 0.1, 10, threads);
      std::shared_ptr<small_gicp::GaussianVoxelMap> voxelmap = small_gicp::create_gaussian_voxelmap(*tcloud, 1.0);
      auto setting = std::make_shared<small_gicp::RegistrationSetting>();
      setting->type = small_gicp::RegistrationSetting::VGICP;
      setting->voxel_resolution = 1.0;
      setting->num_threads = threads;
      // The sources are already downsampled: the 0.1 mm grid keeps every point, so this is the k-d tree
      // and the covariances only.
      auto prepare = [threads](const std::vector<Eigen::Vector3d>& s) { return small_gicp::preprocess_points(s, 0.0001, 10, threads).first; };
      auto align = [voxelmap, setting](const small_gicp::PointCloud& s, const Eigen::Matrix4d& g) {
        return Eigen::Matrix4d(small_gicp::align(*voxelmap, s, Eigen::Isometry3d(g), *setting).T_target_source.matrix());
      };
      std::shared_ptr<small_gicp::PointCloud> dense_ready = prepare(dp), sparse_ready = prepare(sp);
      all.push_back({"small_gicp VGICP, align only", threads, [align, dense_ready] { return align(*dense_ready, Eigen::Matrix4d::Identity()); },
                     [align, sparse_ready, &offset] { return align(*sparse_ready, offset); }, {}, {}, {}, {}});
      all.push_back({"small_gicp VGICP, cov + align", threads, [align, prepare, &dp] { return align(*prepare(dp), Eigen::Matrix4d::Identity()); },
                     [align, prepare, &sp, &offset] { return align(*prepare(sp), offset); }, {}, {}, {}, {}});
    }
  }

  for (int r = 0; r < rounds; ++r) {
    // Each round starts with another contender, so that none always runs first (cold) or last.
    for (std::size_t k = 0; k < all.size(); ++k) {
      Contender& c = all[(k + static_cast<std::size_t>(r)) % all.size()];
      c.dense_ms.push_back(medianMs(15, c.dense, c.dense_result));
      c.sparse_ms.push_back(medianMs(51, c.sparse, c.sparse_result));
    }
    std::fprintf(stderr, "round %d of %d done\n", r + 1, rounds);
  }

  std::printf("| contender | threads | 16k points: ms, median [range] | cm | deg | 1k points, 0.5 m / 2 deg off: ms, median [range] | cm | deg |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (const Contender& c : all) {
    const auto [dm, dd] = testing::poseDifference(c.dense_result, gt);
    const auto [sm, sd] = testing::poseDifference(c.sparse_result, gt);
    const auto [dlo, dhi] = std::minmax_element(c.dense_ms.begin(), c.dense_ms.end());
    const auto [slo, shi] = std::minmax_element(c.sparse_ms.begin(), c.sparse_ms.end());
    std::printf("| %s | %d | %.2f [%.2f-%.2f] | %.2f | %.3f | %.2f [%.2f-%.2f] | %.2f | %.3f |\n", c.name.c_str(), c.threads, median(c.dense_ms), *dlo, *dhi,
                100.0 * dm, dd, median(c.sparse_ms), *slo, *shi, 100.0 * sm, sd);
  }
  return 0;
}
