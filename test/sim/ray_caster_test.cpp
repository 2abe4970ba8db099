#include <gtest/gtest.h>

#include <cmath>

#include "coloc/core/error.hpp"
#include "coloc/sim/ray_caster.hpp"
#include "street_scene.hpp"

namespace coloc::sim {
namespace {

TEST(RayCaster, HitsTheNearestSurfaceAndSaysWhichMesh) {
  RayCaster world;
  const int ground = world.addMesh(groundRectangle({-50, -50}, {50, 50}));
  const int wall = world.addMesh(box({10, 0, 0}, {1, 20, 5}));
  world.commit();
  std::vector<RayHit> hits;
  world.cast({{0, 0, 1}, {0, 0, 1}, {0, 0, 1}}, {{1, 0, 0}, {0, 0, -1}, {0, 0, 1}}, 100.0f, hits);
  EXPECT_NEAR(hits[0].distance, 9.5f, 1e-4f);  // the wall's near face
  EXPECT_EQ(hits[0].mesh, wall);
  EXPECT_NEAR(hits[1].distance, 1.0f, 1e-5f);
  EXPECT_EQ(hits[1].mesh, ground);
  EXPECT_LT(hits[2].distance, 0.0f);  // the sky
}

TEST(RayCaster, MovedMeshIsHitWhereItIsNow) {
  RayCaster world;
  const int car = world.addMesh(box({5, 0, 0}, {4.5f, 1.8f, 1.5f}));
  world.commit();
  world.updateMesh(car, box({8, 0, 0}, {4.5f, 1.8f, 1.5f}));
  world.commit();
  std::vector<RayHit> hits;
  world.cast({{0, 0, 0.5f}}, {{1, 0, 0}}, 50.0f, hits);
  EXPECT_NEAR(hits[0].distance, 8.0f - 2.25f, 1e-4f);
}

// A street of houses, trees and cars seen by a 32-beam LiDAR from a moving vehicle: the packet cast on
// every core gives the one-ray-at-a-time cast's hits, ray for ray.
TEST(RayCaster, PacketsOnEveryCoreHitWhatOneRayAtATimeHits) {
  RayCaster world;
  std::vector<Eigen::Vector3f> origins, directions;
  testing::buildStreet(world, origins, directions);
  origins.resize(origins.size() - 5);  // a last packet that is not full
  directions.resize(origins.size());
  std::vector<RayHit> packets, reference;
  world.cast(origins, directions, 120.0f, packets);
  world.castOneByOne(origins, directions, 120.0f, reference);
  ASSERT_EQ(packets.size(), reference.size());
  std::size_t hit = 0, differing = 0;
  for (std::size_t i = 0; i < packets.size(); ++i) {
    hit += reference[i].mesh >= 0;
    differing += packets[i].mesh != reference[i].mesh || std::abs(packets[i].distance - reference[i].distance) > 1e-5f;
  }
  EXPECT_GT(hit, packets.size() / 2);
  EXPECT_EQ(differing, 0u) << "of " << packets.size() << " rays";
}

TEST(RayCaster, MisuseIsAnError) {
  RayCaster world;
  TriangleMesh broken;
  broken.vertices = {{0, 0, 0}};
  broken.triangles = {{0, 1, 2}};
  EXPECT_THROW(world.addMesh(broken), Error);
  EXPECT_THROW(world.addMesh(TriangleMesh{}), Error);
  world.addMesh(box({0, 0, 0}, {1, 1, 1}));
  std::vector<RayHit> hits;
  EXPECT_THROW(world.cast({{0, 0, 0}}, {{1, 0, 0}}, 1.0f, hits), Error);  // not committed
}

}  // namespace
}  // namespace coloc::sim
