#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

#include "coloc/sim/lidar_model.hpp"

namespace coloc::sim {
namespace {

// A roadside LiDAR 2 m above the road, a car-sized box at `distance` straight ahead: how many returns
// come from the car's lower part (0.15 m to 0.8 m above the road), where the L-shape fit works?
int lowReturns(const LidarSpec& spec, double distance) {
  RayCaster world;
  world.addMesh(groundRectangle({-100, -100}, {100, 100}));
  const int car = world.addMesh(box({static_cast<float>(distance), 0.0f, 0.0f}, {4.5f, 1.8f, 1.5f}, 0.3f));
  world.commit();
  LidarSpec quiet = spec;
  quiet.range_noise = 0.0;
  RandomEngine rng(1);
  const auto points = scanSweep(quiet, world, [](double) { return Eigen::Isometry3d(Eigen::Translation3d(0, 0, 2.0)); }, rng);
  int n = 0;
  for (const LidarPoint& p : points) {
    const double z = p.position.z() + 2.0;
    if (p.mesh == car && z >= 0.15 && z <= 0.8) ++n;
  }
  return n;
}

TEST(LidarModel, Vlp16At2mSeesNoLowVehiclePartFrom40mOn) {
  // The reason its useful roadside range is 30 m: between its -3 and -1 deg beams lies a gap.
  EXPECT_GT(lowReturns(vlp16(), 20.0), 0);
  EXPECT_GT(lowReturns(vlp16(), 28.0), 0);
  for (double d : {40.0, 45.0, 50.0}) EXPECT_EQ(lowReturns(vlp16(), d), 0) << "at " << d << " m";
}

TEST(LidarModel, Vlp32cStillSeesTheLowPartAt50m) { EXPECT_GT(lowReturns(vlp32c(), 50.0), 0); }

TEST(LidarModel, BeamTablesAreVelodynesCalibration) {
  const LidarSpec a = vlp16(), b = vlp32c();
  ASSERT_EQ(a.vertical_deg.size(), 16u);
  ASSERT_EQ(b.vertical_deg.size(), 32u);
  ASSERT_EQ(b.azimuth_offset_deg.size(), 32u);
  EXPECT_EQ(b.vertical_deg[0], -25.0);
  EXPECT_EQ(b.vertical_deg[29], 15.0);
  EXPECT_EQ(a.vertical_deg[14], -1.0);
}

TEST(LidarModel, SweepHasTheRightSizeTimesAndNoise) {
  RayCaster world;
  world.addMesh(groundRectangle({-200, -200}, {200, 200}));
  world.commit();
  RandomEngine rng(7);
  const LidarSpec spec = vlp16();
  const auto points = scanSweep(spec, world, [](double) { return Eigen::Isometry3d(Eigen::Translation3d(0, 0, 1.8)); }, rng);
  // Of the 8 downward beams, the 7 from -15 to -3 deg reach the ground within 100 m at every one of the
  // 1,800 azimuths; the -1 deg beam would need 103 m.
  EXPECT_EQ(points.size(), 7u * 1800u);
  float latest = 0.0f;
  double sum_sq = 0.0;
  for (const LidarPoint& p : points) {
    latest = std::max(latest, p.time);
    sum_sq += std::pow(p.position.z() + 1.8, 2) / std::pow(p.position.normalized().z(), 2);  // range error, squared
  }
  EXPECT_LT(latest, 0.1f);
  EXPECT_GT(latest, 0.099f);
  EXPECT_NEAR(std::sqrt(sum_sq / points.size()), spec.range_noise, 0.002);
}

TEST(LidarModel, SameSeedSameScan) {
  RayCaster world;
  world.addMesh(box({10, 0, 0}, {2, 10, 5}));
  world.commit();
  RandomEngine a(3), b(3);
  const auto still = [](double) { return Eigen::Isometry3d::Identity(); };
  const auto pa = scanSweep(vlp16(), world, still, a), pb = scanSweep(vlp16(), world, still, b);
  ASSERT_EQ(pa.size(), pb.size());
  for (std::size_t i = 0; i < pa.size(); ++i) EXPECT_EQ(pa[i].position, pb[i].position);
}

TEST(LidarModel, MovingSensorScanCarriesMotionDistortion) {
  // Driving at 20 m/s towards a wall 30 m ahead: the last firings see it 2 m closer than the first.
  RayCaster world;
  world.addMesh(box({30, 0, 0}, {1, 200, 10}));
  world.commit();
  RandomEngine rng(1);
  LidarSpec spec = vlp16();
  spec.range_noise = 0.0;
  const auto points = scanSweep(spec, world, [](double t) { return Eigen::Isometry3d(Eigen::Translation3d(20.0 * t, 0, 1)); }, rng);
  double first = 0, last = 0;
  for (const LidarPoint& p : points) {
    if (std::abs(p.position.y()) > 0.5 || p.laser != 14) continue;  // the -1 deg beam straight ahead
    (p.time < 0.05f ? first : last) = p.position.x();
  }
  EXPECT_NEAR(first, 29.5, 0.05);
  EXPECT_NEAR(last, 27.5, 0.05);
}

// Inside a tall ring of radius R around the sensor, every ray returns at about R; how the noise and
// the lost returns grow with range.
struct RingScan {
  double noise_sd = 0.0, lost = 0.0;
};
RingScan ringScan(const LidarSpec& spec, float radius) {
  RayCaster world;
  world.addMesh(cylinder({0, 0, -40}, radius, 80, 720));
  world.commit();
  const auto still = [](double) { return Eigen::Isometry3d::Identity(); };
  LidarSpec exact = spec;
  exact.range_noise = exact.range_noise_per_m = exact.dropout = exact.dropout_at_max_range = 0.0;
  RandomEngine a(1), b(2);
  const auto truth = scanSweep(exact, world, still, a), noisy = scanSweep(spec, world, still, b);
  std::map<std::pair<int, float>, float> range;
  for (const LidarPoint& p : truth) range[{p.laser, p.time}] = p.position.norm();
  double sum_sq = 0.0;
  for (const LidarPoint& p : noisy) {
    const double e = p.position.norm() - range.at({p.laser, p.time});
    sum_sq += e * e;
  }
  return {std::sqrt(sum_sq / noisy.size()), 1.0 - static_cast<double>(noisy.size()) / truth.size()};
}

TEST(LidarModel, RangeNoiseAndLostReturnsGrowWithRangeAsConfigured) {
  LidarSpec spec = vlp16();  // 100 m datasheet range
  spec.range_noise = 0.02;
  spec.range_noise_per_m = 0.0002;
  spec.dropout = 0.01;
  spec.dropout_at_max_range = 0.5;
  for (float r : {10.0f, 80.0f}) {
    const RingScan s = ringScan(spec, r);
    EXPECT_NEAR(s.noise_sd, 0.02 + 0.0002 * r, 0.05 * (0.02 + 0.0002 * r)) << "at " << r << " m";  // 28,800 rays: 1 % sampling error
    const double expected = 0.01 + 0.5 * (r / 100.0) * (r / 100.0);
    EXPECT_NEAR(s.lost, expected, 0.01) << "at " << r << " m";
  }
  // The ideal spec loses nothing and its noise does not grow.
  const LidarSpec ideal = vlp16();
  EXPECT_EQ(ringScan(ideal, 80.0f).lost, 0.0);
  EXPECT_NEAR(ringScan(ideal, 80.0f).noise_sd, 0.02, 0.001);
}

// One laser level with the ground, firing 0 straight along x; a wall 40 m ahead and, nearer, a surface
// whose edge lies `edge` rad to the left of that firing's centre ray (the surface covers everything
// beyond it), at `near` m.
RayHit firingAtAnEdge(double divergence, double near, double edge) {
  RayCaster world;
  world.addMesh(box({40.0f, 0.0f, -5.0f}, {0.2f, 40.0f, 10.0f}));
  const float y0 = static_cast<float>(near * std::tan(edge));
  world.addMesh(box({static_cast<float>(near) + 0.1f, y0 + 2.0f, -5.0f}, {0.2f, 4.0f, 10.0f}));
  world.commit();
  LidarSpec spec;
  spec.name = "one laser";
  spec.vertical_deg = {0.0};
  spec.azimuth_offset_deg = {0.0};
  spec.beam_divergence = divergence;
  return castSweep(spec, world, [](double) { return Eigen::Isometry3d::Identity(); })[0];
}

// A real laser's footprint widens with range (Velodyne: 3 mrad across the scan). Where it straddles an
// edge, what it returns is not what its centre ray hits: a nearer surface covering a third of it is the
// stronger echo (the edge blooms outwards), and two surfaces closer than a pulse's length merge into
// one echo between them (a mixed pixel). Away from edges, and without divergence, the centre ray's.
TEST(LidarModel, AFootprintAcrossAnEdgeReturnsTheStrongerEchoOrAMixedRange) {
  const double divergence = 3e-3;
  // Without divergence the centre ray passes the edge 0.5 mrad away and hits the wall.
  EXPECT_NEAR(firingAtAnEdge(0.0, 20.0, 0.5e-3).distance, 39.9, 0.01);
  // With it, a third of the footprint lies on the surface at 20 m: (1/3) / 20^2 outshines (2/3) / 40^2.
  EXPECT_NEAR(firingAtAnEdge(divergence, 20.0, 0.5e-3).distance, 20.0, 0.01);
  // A surface farther from the edge than a third of the divergence is not seen.
  EXPECT_NEAR(firingAtAnEdge(divergence, 20.0, 1.2e-3).distance, 39.9, 0.01);
  // A third of the footprint at 39.6 m and two at 39.9 m: one echo at their mean.
  EXPECT_NEAR(firingAtAnEdge(divergence, 39.6, 0.5e-3).distance, (39.6 + 2 * 39.9) / 3.0, 0.01);
  // The centre on the near surface: a third beyond the edge does not outshine it.
  EXPECT_NEAR(firingAtAnEdge(divergence, 20.0, -0.5e-3).distance, 20.0, 0.01);
}

// Three lasers 1 deg apart, their footprint `divergence` up and down.
LidarSpec threeLasers(double divergence) {
  LidarSpec spec;
  spec.name = "three lasers";
  spec.vertical_deg = {-1.0, 0.0, 1.0};
  spec.azimuth_offset_deg = {0.0, 0.0, 0.0};
  spec.beam_divergence_vertical = divergence;
  return spec;
}

// Three lasers 1 deg apart, firing 0 straight along x; a wall 40 m ahead and, nearer, another object
// whose lower edge (a car's sill) lies `edge` rad above the middle laser's centre ray, at `near` m. The
// middle laser's return.
RayHit firingUnderAnEdge(double divergence, double near, double edge) {
  RayCaster world;
  world.addMesh(box({40.0f, 0.0f, -5.0f}, {0.2f, 40.0f, 10.0f}));
  const float z0 = static_cast<float>(near * std::tan(edge));
  world.addMesh(box({static_cast<float>(near) + 0.1f, 0.0f, z0}, {0.2f, 40.0f, 10.0f}));
  world.commit();
  const LidarSpec spec = threeLasers(divergence);
  return castSweep(spec, world, [](double) { return Eigen::Isometry3d::Identity(); })[1];
}

// The footprint up and down (Velodyne: 1.5 mrad): where a laser's centre passes just under an object
// that the laser above hits, a third of the footprint on it outshines the far wall, or merges with a
// surface less than a pulse behind. A surface that goes on (the same object) is no edge.
TEST(LidarModel, AFootprintUnderAnEdgeAboveReturnsTheStrongerEchoOrAMixedRange) {
  const double divergence = 1.5e-3;
  EXPECT_NEAR(firingUnderAnEdge(0.0, 20.0, 0.4e-3).distance, 39.9, 0.01) << "without divergence: the wall";
  EXPECT_NEAR(firingUnderAnEdge(divergence, 20.0, 0.4e-3).distance, 20.0, 0.01) << "a third on the object at 20 m";
  EXPECT_NEAR(firingUnderAnEdge(divergence, 20.0, 0.6e-3).distance, 39.9, 0.01) << "the edge beyond the footprint's upper third";
  EXPECT_NEAR(firingUnderAnEdge(divergence, 39.6, 0.4e-3).distance, (39.6 + 2 * 39.9) / 3.0, 0.01) << "a mixed pixel";
  // Only the wall: the three lasers hit the same object, and the middle one's return is its centre's.
  RayCaster wall;
  wall.addMesh(box({40.0f, 0.0f, -5.0f}, {0.2f, 40.0f, 10.0f}));
  wall.commit();
  const LidarSpec spec = threeLasers(divergence);
  EXPECT_NEAR(castSweep(spec, wall, [](double) { return Eigen::Isometry3d::Identity(); })[1].distance, 39.9, 1e-4);
}

// Each ray's noise is its own: the same sweep key gives a ray the same range whatever the other rays
// hit (so a ray into the sky changes nothing for the rest), and a sweep takes one draw of the engine.
TEST(LidarModel, ARaysNoiseAndDropoutAreItsOwnWhateverTheOtherRaysHit) {
  LidarSpec spec = vlp32c();
  spec.range_noise = 0.02;
  spec.range_noise_per_m = 0.0005;
  spec.dropout = 0.05;
  spec.dropout_at_max_range = 0.3;
  const std::size_t rays = static_cast<std::size_t>(firingsPerSweep(spec)) * spec.vertical_deg.size();
  std::mt19937 pattern(5);
  std::uniform_real_distribution<float> distance(0.5f, 110.0f);
  std::vector<RayHit> all(rays), some(rays);
  for (std::size_t i = 0; i < rays; ++i) {
    all[i] = {distance(pattern), static_cast<int>(i % 4)};
    if ((i / 7) % 3 != 0 && pattern() % 5 != 0) some[i] = all[i];  // misses in runs and alone
  }
  RandomEngine a(99), b(99), reference(99);
  const std::vector<LidarPoint> from_all = sweepPoints(spec, all, a), from_some = sweepPoints(spec, some, b);
  std::map<std::pair<int, float>, Eigen::Vector3f> by_ray;
  for (const LidarPoint& p : from_all) by_ray[{p.laser, p.time}] = p.position;
  ASSERT_GT(from_some.size(), rays / 3);
  std::size_t dropped = 0;
  for (const LidarPoint& p : from_some) {
    const auto found = by_ray.find({p.laser, p.time});
    ASSERT_NE(found, by_ray.end()) << "a ray kept with fewer neighbours hitting was dropped with more";
    EXPECT_EQ(found->second, p.position);
  }
  for (std::size_t i = 0; i < rays; ++i) dropped += some[i].distance >= 0.0f ? 1 : 0;
  dropped -= from_some.size();
  EXPECT_GT(dropped, 0u) << "the spec's dropouts were drawn";
  reference();  // the sweep's key
  const RandomEngine::result_type next = reference();
  EXPECT_EQ(a(), next) << "one draw of the engine per sweep";
  EXPECT_EQ(b(), next) << "one draw of the engine per sweep";
}

}  // namespace
}  // namespace coloc::sim
