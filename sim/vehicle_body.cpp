#include "coloc/sim/vehicle_body.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace coloc::sim {

namespace {

using Polygon = std::vector<Eigen::Vector2f>;

// A rectangle with rounded corners in plan, counter-clockwise: centred at x = cx, half-sizes hl, hw,
// corner radii rf (front, +x) and rr (rear).
Polygon roundedRectangle(float cx, float hl, float hw, float rf, float rr) {
  constexpr int kArc = 6;
  Polygon p;
  const auto arc = [&](float ox, float oy, float r, float a0) {
    for (int i = 0; i <= kArc; ++i) {
      const float a = a0 + 0.5f * static_cast<float>(M_PI) * i / kArc;
      p.emplace_back(ox + r * std::cos(a), oy + r * std::sin(a));
    }
  };
  arc(cx + hl - rf, -hw + rf, rf, -0.5f * static_cast<float>(M_PI));  // front right
  arc(cx + hl - rf, hw - rf, rf, 0.0f);                               // front left
  arc(cx - hl + rr, hw - rr, rr, 0.5f * static_cast<float>(M_PI));    // rear left
  arc(cx - hl + rr, -hw + rr, rr, static_cast<float>(M_PI));          // rear right
  return p;
}

// The convex polygon cut to x0 <= x <= x1 (Sutherland-Hodgman against two vertical lines).
Polygon clipX(const Polygon& in, float x0, float x1) {
  const auto clip = [](const Polygon& poly, float x, bool keep_above) {
    Polygon out;
    for (std::size_t i = 0; i < poly.size(); ++i) {
      const Eigen::Vector2f a = poly[i], b = poly[(i + 1) % poly.size()];
      const bool ain = keep_above ? a.x() >= x : a.x() <= x, bin = keep_above ? b.x() >= x : b.x() <= x;
      if (ain) out.push_back(a);
      if (ain != bin) out.push_back(a + (b - a) * ((x - a.x()) / (b.x() - a.x())));
    }
    return out;
  };
  return clip(clip(in, x0, true), x1, false);
}

// A vertical prism over a convex polygon, from z0 to z1.
TriangleMesh prism(const Polygon& poly, float z0, float z1) {
  TriangleMesh m;
  const int n = static_cast<int>(poly.size());
  if (n < 3) return m;
  for (float z : {z0, z1})
    for (const auto& v : poly) m.vertices.emplace_back(v.x(), v.y(), z);
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    m.triangles.emplace_back(i, j, n + j);
    m.triangles.emplace_back(i, n + j, n + i);
  }
  for (int i = 1; i + 1 < n; ++i) {
    m.triangles.emplace_back(0, i + 1, i);
    m.triangles.emplace_back(n, n + i, n + i + 1);
  }
  return m;
}

// A wheel: a cylinder with its axis along y.
TriangleMesh wheel(const Eigen::Vector3f& centre, float radius, float width) {
  constexpr int kSides = 16;
  TriangleMesh m;
  for (float side : {-0.5f, 0.5f})
    for (int i = 0; i < kSides; ++i) {
      const float a = 2.0f * static_cast<float>(M_PI) * i / kSides;
      m.vertices.emplace_back(centre + Eigen::Vector3f(radius * std::cos(a), side * width, radius * std::sin(a)));
    }
  for (int i = 0; i < kSides; ++i) {
    const int j = (i + 1) % kSides;
    m.triangles.emplace_back(i, j, kSides + j);
    m.triangles.emplace_back(i, kSides + j, kSides + i);
  }
  for (int i = 1; i + 1 < kSides; ++i) {
    m.triangles.emplace_back(0, i, i + 1);
    m.triangles.emplace_back(kSides, kSides + i + 1, kSides + i);
  }
  return m;
}

TriangleMesh boxBody(const VehicleBody& b) {
  const float L = static_cast<float>(b.length), W = static_cast<float>(b.width);
  TriangleMesh body = box({0.0f, 0.0f, static_cast<float>(b.ground_clearance)}, {L, W, static_cast<float>(b.chassis_height)});
  const float roof = static_cast<float>(b.ground_clearance + b.chassis_height);
  body.append(box({-0.1f * L, 0.0f, roof}, {static_cast<float>(b.cabin_length), static_cast<float>(b.cabin_width), static_cast<float>(b.cabin_height)}));
  if (b.mirrors) {
    const float side = 0.5f * W + 0.5f * static_cast<float>(b.mirror_reach);
    const float z = static_cast<float>(b.mirror_height) - 0.08f;
    for (float s : {-1.0f, 1.0f}) body.append(box({0.18f * L, s * side, z}, {0.12f, static_cast<float>(b.mirror_reach) + 0.02f, 0.16f}));
  }
  return body;
}

TriangleMesh detailedBody(const VehicleBody& b) {
  const float hl = 0.5f * static_cast<float>(b.length), hw = 0.5f * static_cast<float>(b.width);
  const float rf = static_cast<float>(b.corner_radius_front), rr = static_cast<float>(b.corner_radius_rear);
  const float r = static_cast<float>(b.wheel_radius), gap = static_cast<float>(b.arch_gap);
  const float front_axle = hl - static_cast<float>(b.front_overhang), rear_axle = front_axle - static_cast<float>(b.wheelbase);
  const float arch_top = r + r + gap;  // the wheel stands on the road
  const float belt = static_cast<float>(b.belt_height), bumper = static_cast<float>(b.bumper_height);
  const float clearance = static_cast<float>(b.ground_clearance);
  // The outline of the lower body, shrunk by `inset` (rounded edges in section: the bumpers' lower lip,
  // the shoulder under the windows).
  const auto outline = [&](float inset) {
    return roundedRectangle(0.0f, hl - inset, hw - inset, std::max(rf - inset, 0.05f), std::max(rr - inset, 0.05f));
  };
  TriangleMesh m;
  // Below the arches' tops: front and rear overhangs (bumpers) and the sills between the wheels.
  struct Piece {
    float x0, x1, bottom;
  };
  const Piece pieces[] = {{front_axle + r + gap, hl, bumper}, {rear_axle + r + gap, front_axle - r - gap, clearance}, {-hl, rear_axle - r - gap, bumper}};
  constexpr float kLip = 0.08f;  // m of height over which the lower edge curves in
  for (const Piece& p : pieces) {
    m.append(prism(clipX(outline(0.07f), p.x0, p.x1), p.bottom, p.bottom + kLip));
    m.append(prism(clipX(outline(0.0f), p.x0, p.x1), p.bottom + kLip, arch_top));
  }
  // Above the arches, the full outline to the belt line, its top edge rounded.
  m.append(prism(outline(0.0f), arch_top, belt - 0.07f));
  m.append(prism(outline(0.05f), belt - 0.07f, belt));
  // The greenhouse narrows to the roof in three steps, set back from the body's centre.
  const float top = static_cast<float>(b.height);
  const float step = (top - belt) / 3.0f;
  const float lengths[] = {2.9f, 2.5f, 2.0f}, widths[] = {1.62f, 1.50f, 1.36f};
  for (int i = 0; i < 3; ++i)
    m.append(prism(roundedRectangle(-0.15f, 0.5f * lengths[i], std::min(0.5f * widths[i], hw - 0.05f), 0.25f, 0.25f), belt + i * step,
                   belt + (i + 1) * step));
  // Wheels set in from the side, and the wheel wells behind them.
  const float wheel_y = hw - static_cast<float>(b.wheel_inset) - 0.5f * static_cast<float>(b.wheel_width);
  for (float x : {front_axle, rear_axle}) {
    for (float s : {-1.0f, 1.0f}) m.append(wheel({x, s * wheel_y, r}, r, static_cast<float>(b.wheel_width)));
    m.append(box({x, 0.0f, r}, {2.0f * (r + gap), 2.0f * (wheel_y - 0.5f * static_cast<float>(b.wheel_width)), arch_top - r}));
  }
  if (b.mirrors) {
    const float reach = static_cast<float>(b.mirror_reach);
    for (float s : {-1.0f, 1.0f})
      m.append(box({-0.15f + 0.5f * lengths[0] - 0.15f, s * (hw + 0.5f * reach - 0.01f), static_cast<float>(b.mirror_height) - 0.08f},
                   {0.14f, reach + 0.02f, 0.16f}));
  }
  return m;
}

}  // namespace

VehicleBody VehicleBody::boxes() {
  VehicleBody b;
  b.detailed = false;
  b.length = 4.5;
  b.width = 1.8;
  b.height = 1.55;
  b.ground_clearance = 0.2;
  return b;
}

TriangleMesh VehicleBody::mesh(double x, double y, double yaw) const {
  return transformed(detailed ? detailedBody(*this) : boxBody(*this), {static_cast<float>(x), static_cast<float>(y), 0.0f},
                     static_cast<float>(yaw));
}

}  // namespace coloc::sim
