// The paper's roadside pipeline on the twin: a car with side mirrors drives past an RSU 2 m high; what
// do the true-size alignment and the 0.8 m height cut buy over the plain L-shape centre?
#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "coloc/core/error.hpp"
#include "coloc/sim/lidar_model.hpp"
#include "coloc/sim/roadside_perception.hpp"
#include "coloc/sim/vehicle_body.hpp"

namespace coloc::sim {
namespace {

struct Variant {
  bool cut, align;
};

// Mean planar error of the RSU fix over vehicle positions `along` (m, along the road from the RSU).
std::map<std::pair<bool, bool>, double> meanErrors(const LidarSpec& spec, const std::vector<double>& along) {
  RayCaster world;
  world.addMesh(groundRectangle({-120, -30}, {120, 30}));
  world.addMesh(box({0, 16, 0}, {200, 1, 8}));  // a facade across the road
  const VehicleBody car;
  const int car_mesh = world.addMesh(car.mesh(500, 500, 0));  // parked out of sight for the reference frame
  world.commit();
  RsuMount mount;
  mount.position = {0.0, -6.0, 2.0};
  const auto sensor = [&](double) { return Eigen::Isometry3d(Eigen::Translation3d(mount.position)); };
  LidarSpec quiet = spec;
  std::mt19937_64 rng(9);
  std::vector<Eigen::Vector3f> reference;
  for (const LidarPoint& p : scanSweep(quiet, world, sensor, rng)) reference.push_back(p.position);
  std::map<std::pair<bool, bool>, double> sum;
  int n = 0;
  for (double x : along) {
    const double yaw = 0.05;  // a slight angle to the road
    world.updateMesh(car_mesh, car.mesh(x, 0.0, yaw));
    world.commit();
    std::vector<Eigen::Vector3f> frame;
    for (const LidarPoint& p : scanSweep(quiet, world, sensor, rng)) frame.push_back(p.position);
    for (bool cut : {false, true})
      for (bool align : {false, true}) {
        RoadsidePerceptionConfig config;
        config.height_cut = cut;
        config.align_true_size = align;
        const RoadsidePerception perception(reference, mount, config);
        const VehicleDetection d = perception.detect(frame, 0, {x + 0.4, 0.3}, yaw + 0.03, car.length, car.width);
        EXPECT_TRUE(d.found) << spec.name << " at x " << x << " foreground " << d.foreground_points << " fit " << d.fit_points;
        sum[{cut, align}] += (d.position - Eigen::Vector2d(x, 0.0)).norm();
      }
    ++n;
  }
  for (auto& [k, v] : sum) v /= n;
  return sum;
}

TEST(RoadsidePerception, AlignedTrueSizeBoxWithTheHeightCutBeatsThePlainLShapeCentre) {
  for (const LidarSpec& spec : {vlp16(), vlp32c()}) {
    const auto e = meanErrors(spec, {-25, -18, -12, -6, 6, 12, 18, 25});
    const double plain = e.at({false, false}), plain_cut = e.at({true, false}), aligned = e.at({false, true}),
                 aligned_cut = e.at({true, true});
    std::printf("%s mean error, m: plain %.3f, plain+cut %.3f, aligned %.3f, aligned+cut %.3f\n", spec.name.c_str(), plain,
                plain_cut, aligned, aligned_cut);
    EXPECT_LT(aligned_cut, 0.5 * plain) << spec.name;
    EXPECT_LT(aligned_cut, aligned) << spec.name << ": the mirrors must cost the uncut fit";
    EXPECT_LT(aligned_cut, 0.10) << spec.name;
  }
}

TEST(RoadsidePerception, EmptyReferenceFrameIsAnError) { EXPECT_THROW(RoadsidePerception({}, RsuMount{}), Error); }

TEST(RoadsidePerception, NoVehicleInViewIsNotFound) {
  RayCaster world;
  world.addMesh(groundRectangle({-50, -50}, {50, 50}));
  world.commit();
  std::mt19937_64 rng(1);
  std::vector<Eigen::Vector3f> frame;
  for (const LidarPoint& p : scanSweep(vlp16(), world, [](double) { return Eigen::Isometry3d(Eigen::Translation3d(0, 0, 2)); }, rng))
    frame.push_back(p.position);
  const RoadsidePerception perception(frame, RsuMount{});
  EXPECT_FALSE(perception.detect(frame, 0, {10, 0}, 0.0, 4.5, 1.8).found);
}

}  // namespace
}  // namespace coloc::sim
