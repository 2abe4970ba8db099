// The hashed voxel grid gives the voxels PCL's VoxelGridCovariance gives, statistic for statistic, on
// real clouds at several resolutions and on clouds built to hit PCL's edge cases.
#include <gtest/gtest.h>
#include <pcl/filters/voxel_grid_covariance.h>

#include <map>
#include <random>
#include <tuple>

#include "coloc/core/error.hpp"
#include "coloc/ndt/pcd_file.hpp"
#include "real_data.hpp"
#include "voxel_grid.hpp"

namespace coloc::ndt {
namespace {

// PCL's usable voxels by coordinates: (mean, inverse covariance).
std::map<std::tuple<int, int, int>, Voxel> pclVoxels(const std::vector<Eigen::Vector3f>& points, float leaf) {
  auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  for (const auto& p : points) {
    pcl::PointXYZ q;
    q.getVector3fMap() = p;
    cloud->push_back(q);
  }
  cloud->is_dense = true;
  pcl::VoxelGridCovariance<pcl::PointXYZ> grid;
  grid.setLeafSize(leaf, leaf, leaf);
  grid.setInputCloud(cloud);
  grid.filter(false);
  const Eigen::Vector3i min_b = grid.getMinBoxCoordinates();
  const Eigen::Vector3i mul = grid.getDivisionMultiplier();
  std::map<std::tuple<int, int, int>, Voxel> out;
  for (const auto& [index, l] : grid.getLeaves()) {
    if (l.nr_points < grid.getMinPointPerVoxel()) continue;
    const int i = static_cast<int>(index);
    out[{i % mul[1] + min_b[0], (i % mul[2]) / mul[1] + min_b[1], i / mul[2] + min_b[2]}] = {l.getMean(), l.getInverseCov()};
  }
  return out;
}

void expectSameVoxels(const std::vector<Eigen::Vector3f>& points, float leaf, const std::string& what) {
  const auto expected = pclVoxels(points, leaf);
  VoxelLookup lookup;
  buildVoxels(points, leaf, lookup);
  ASSERT_EQ(lookup.size(), expected.size()) << what;
  ASSERT_GT(expected.size(), 0u) << what;
  std::size_t bitwise = 0;
  for (const auto& [ijk, v] : expected) {
    const Voxel* mine = lookup.find({std::get<0>(ijk), std::get<1>(ijk), std::get<2>(ijk)});
    ASSERT_NE(mine, nullptr) << what << ": voxel missing";
    // Same sums in the same order through the same arithmetic: equal, within 1e-12 relative at most.
    EXPECT_LE((mine->mean - v.mean).norm(), 1e-12 * (1.0 + v.mean.norm())) << what;
    EXPECT_LE((mine->inverse_covariance - v.inverse_covariance).norm(), 1e-12 * (1.0 + v.inverse_covariance.norm())) << what;
    bitwise += mine->mean == v.mean && mine->inverse_covariance == v.inverse_covariance;
  }
  EXPECT_EQ(bitwise, expected.size()) << what << ": voxels not bit for bit equal";
}

TEST(VoxelGrid, RealScansAndTheAirborneTileGiveExactlyPclsVoxelsAtEveryResolution) {
  const PointCloud scan = loadPcd(testing::realData("hdl32e_pair/target.pcd"));
  for (const float leaf : {0.5f, 1.0f, 2.0f, 3.3f}) expectSameVoxels(scan.points, leaf, "HDL-32E scan at " + std::to_string(leaf) + " m");
  const PointCloud tile = loadPcd(testing::realData("als_tile/csite2_demeaned.pcd"));
  expectSameVoxels(tile.points, 2.0f, "ALS tile at 2 m");
}

TEST(VoxelGrid, FlatLinearSparseAndNegativeCoordinateVoxelsAreTreatedAsPclTreatsThem) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-10.0f, 10.0f);
  std::vector<Eigen::Vector3f> points;
  for (int i = 0; i < 4000; ++i) points.push_back({u(rng), u(rng), 0.0f});                  // a plane: thickened
  for (int i = 0; i < 500; ++i) points.push_back({u(rng), 3.0f, 7.0f});                     // a line
  for (int i = 0; i < 5; ++i) points.push_back({-20.5f, -20.5f, -20.5f + 0.1f * i});        // 5 points: too few
  for (int i = 0; i < 8; ++i) points.push_back({33.0f, 33.0f, 33.0f});                      // one point 8 times: singular
  for (int i = 0; i < 3000; ++i) points.push_back({u(rng) - 100.0f, u(rng) - 100.0f, u(rng)});  // a volume far off
  expectSameVoxels(points, 1.0f, "synthetic");
}

TEST(VoxelGrid, APointBeyondTheAddressableVoxelsIsAnErrorNamingIt) {
  VoxelLookup lookup;
  try {
    buildVoxels({{1e7f, 0.0f, 0.0f}}, 2.0f, lookup);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("re-centre the map"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace coloc::ndt
