// The car the roadside LiDAR sees: the CAM's dimensions, rounded corners, wheels in their arches.
#include <gtest/gtest.h>

#include <cmath>

#include <Eigen/Geometry>

#include "coloc/sim/ray_caster.hpp"
#include "coloc/sim/vehicle_body.hpp"

namespace coloc::sim {
namespace {

Eigen::AlignedBox3f bounds(const TriangleMesh& m) {
  Eigen::AlignedBox3f b;
  for (const auto& v : m.vertices) b.extend(v);
  return b;
}

// Distance along a horizontal ray at height z from `from` towards `to` to the first surface of `body`.
float hit(const VehicleBody& body, const Eigen::Vector2f& from, const Eigen::Vector2f& to, float z) {
  RayCaster world;
  world.addMesh(body.mesh(0, 0, 0));
  world.commit();
  std::vector<RayHit> hits;
  world.cast({Eigen::Vector3f(from.x(), from.y(), z)}, {Eigen::Vector3f(to.x() - from.x(), to.y() - from.y(), 0).normalized()}, 100.0f, hits);
  return hits[0].distance;
}

TEST(VehicleBody, DetailedBodyHasTheCamsLengthAndWidthAndStandsOnItsWheels) {
  VehicleBody car;
  car.mirrors = false;
  const Eigen::AlignedBox3f b = bounds(car.mesh(0, 0, 0));
  EXPECT_NEAR(b.sizes().x(), car.length, 1e-4);
  EXPECT_NEAR(b.sizes().y(), car.width, 1e-4);
  EXPECT_NEAR(b.max().z(), car.height, 1e-4);
  EXPECT_NEAR(b.min().z(), 0.0, 1e-4);  // the tyres touch the road
  // With mirrors the body is wider than the CAM says, by the mirrors' reach on each side.
  EXPECT_NEAR(bounds(VehicleBody{}.mesh(0, 0, 0)).sizes().y(), car.width + 2 * car.mirror_reach, 0.03);
}

TEST(VehicleBody, MovingTheBodyKeepsItsTriangleCount) {
  const VehicleBody car;
  EXPECT_EQ(car.mesh(0, 0, 0).triangles.size(), car.mesh(120, -4, 2.1).triangles.size());
  EXPECT_EQ(VehicleBody::boxes().mesh(0, 0, 0).triangles.size(), VehicleBody::boxes().mesh(5, 5, 1).triangles.size());
}

TEST(VehicleBody, CornersAreRoundedWhereTheBoxesAreSquare) {
  // A ray at 0.5 m height aimed at the front-right corner along the diagonal.
  const VehicleBody car, boxes = VehicleBody::boxes();
  const auto corner_gap = [](const VehicleBody& b) {
    const Eigen::Vector2f corner(0.5f * static_cast<float>(b.length), -0.5f * static_cast<float>(b.width));
    const Eigen::Vector2f from = corner + Eigen::Vector2f(10, -10);
    return hit(b, from, corner, 0.5f) - (from - corner).norm();  // how far inside the corner the surface is
  };
  EXPECT_NEAR(corner_gap(boxes), 0.0, 1e-3);
  // A 0.45 m radius: the surface is r (sqrt 2 - 1) inside the corner along the diagonal.
  EXPECT_NEAR(corner_gap(car), car.corner_radius_front * (std::sqrt(2.0) - 1.0), 0.02);
}

TEST(VehicleBody, TheTyreIsSetInFromTheBodySideAndSeenThroughItsArch) {
  const VehicleBody car;
  const float front_axle = 0.5f * static_cast<float>(car.length - 2 * car.front_overhang);
  const float side = 0.5f * static_cast<float>(car.width);
  // At the axle, 0.4 m up: the arch is open and the tyre is wheel_inset behind the body side.
  const float to_tyre = hit(car, {front_axle, -10.0f}, {front_axle, 0.0f}, 0.4f);
  EXPECT_NEAR(to_tyre, 10.0f - side + static_cast<float>(car.wheel_inset), 1e-3);
  // Between the wheels, the sill is the body side itself.
  EXPECT_NEAR(hit(car, {0.0f, -10.0f}, {0.0f, 0.0f}, 0.4f), 10.0f - side, 1e-3);
}

}  // namespace
}  // namespace coloc::sim
