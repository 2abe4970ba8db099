#include "coloc/sim/mesh.hpp"

#include <algorithm>
#include <cmath>

namespace coloc::sim {

void TriangleMesh::append(const TriangleMesh& other) {
  const int offset = static_cast<int>(vertices.size());
  vertices.insert(vertices.end(), other.vertices.begin(), other.vertices.end());
  for (const Eigen::Vector3i& t : other.triangles) triangles.push_back(t + Eigen::Vector3i::Constant(offset));
}

TriangleMesh groundRectangle(const Eigen::Vector2f& min, const Eigen::Vector2f& max, float z) {
  TriangleMesh m;
  m.vertices = {{min.x(), min.y(), z}, {max.x(), min.y(), z}, {max.x(), max.y(), z}, {min.x(), max.y(), z}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

TriangleMesh heightField(const Eigen::Vector2f& min, const Eigen::Vector2f& max, float step, const std::function<float(float, float)>& z) {
  TriangleMesh m;
  const int nx = std::max(1, static_cast<int>(std::ceil((max.x() - min.x()) / step))), ny = std::max(1, static_cast<int>(std::ceil((max.y() - min.y()) / step)));
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      const float x = std::min(max.x(), min.x() + i * step), y = std::min(max.y(), min.y() + j * step);
      m.vertices.emplace_back(x, y, z(x, y));
    }
  const auto at = [&](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      m.triangles.emplace_back(at(i, j), at(i + 1, j), at(i + 1, j + 1));
      m.triangles.emplace_back(at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
  return m;
}

TriangleMesh box(const Eigen::Vector3f& base, const Eigen::Vector3f& size, float yaw) {
  const float hx = 0.5f * size.x(), hy = 0.5f * size.y(), h = size.z();
  TriangleMesh m;
  for (int k = 0; k < 2; ++k) {
    const float z = k * h;
    m.vertices.insert(m.vertices.end(), {{-hx, -hy, z}, {hx, -hy, z}, {hx, hy, z}, {-hx, hy, z}});
  }
  // bottom, top, then the four sides
  m.triangles = {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
                 {1, 2, 6}, {1, 6, 5}, {2, 3, 7}, {2, 7, 6}, {3, 0, 4}, {3, 4, 7}};
  return transformed(m, base, yaw);
}

TriangleMesh cylinder(const Eigen::Vector3f& base, float radius, float height, int sides) {
  TriangleMesh m;
  for (int k = 0; k < 2; ++k)
    for (int i = 0; i < sides; ++i) {
      const float a = 2.0f * static_cast<float>(M_PI) * i / sides;
      m.vertices.emplace_back(radius * std::cos(a), radius * std::sin(a), k * height);
    }
  m.vertices.emplace_back(0.0f, 0.0f, height);  // top centre
  const int top = 2 * sides;
  for (int i = 0; i < sides; ++i) {
    const int j = (i + 1) % sides;
    m.triangles.emplace_back(i, j, sides + j);
    m.triangles.emplace_back(i, sides + j, sides + i);
    m.triangles.emplace_back(sides + i, sides + j, top);
  }
  return transformed(m, base, 0.0f);
}

TriangleMesh transformed(const TriangleMesh& mesh, const Eigen::Vector3f& translation, float yaw) {
  TriangleMesh out = mesh;
  const float c = std::cos(yaw), s = std::sin(yaw);
  for (Eigen::Vector3f& v : out.vertices) v = Eigen::Vector3f(c * v.x() - s * v.y(), s * v.x() + c * v.y(), v.z()) + translation;
  return out;
}

}  // namespace coloc::sim
