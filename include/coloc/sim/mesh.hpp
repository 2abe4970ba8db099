#pragma once
// Triangle meshes, the one shape the digital twin's world is made of. Builders for the primitives a
// street needs: ground, boxes (buildings, walls, parked cars, vehicle bodies), upright cylinders (poles,
// tree trunks).
#include <Eigen/Core>
#include <functional>
#include <vector>

namespace coloc::sim {

struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> triangles;  ///< indices into vertices, counter-clockwise seen from outside

  /// Appends another mesh (indices shifted).
  void append(const TriangleMesh& other);
};

/// A flat rectangle at height z spanning [min, max] in x and y.
TriangleMesh groundRectangle(const Eigen::Vector2f& min, const Eigen::Vector2f& max, float z = 0.0f);

/// Ground that is not flat (a crowned road, a grade, gutters): the height z(x, y) sampled every `step`
/// metres over [min, max], two triangles per square.
TriangleMesh heightField(const Eigen::Vector2f& min, const Eigen::Vector2f& max, float step, const std::function<float(float, float)>& z);

/// A box with its base centred at `base` (x, y, z of the bottom face), size (length along the heading,
/// width, height), rotated by `yaw` about z.
TriangleMesh box(const Eigen::Vector3f& base, const Eigen::Vector3f& size, float yaw = 0.0f);

/// An upright cylinder standing on `base`, as a prism with `sides` faces.
TriangleMesh cylinder(const Eigen::Vector3f& base, float radius, float height, int sides = 12);

/// The same mesh moved: rotated by yaw about z, then translated.
TriangleMesh transformed(const TriangleMesh& mesh, const Eigen::Vector3f& translation, float yaw);

}  // namespace coloc::sim
