#include "coloc/sim/vehicle_body.hpp"

namespace coloc::sim {

TriangleMesh VehicleBody::mesh(double x, double y, double yaw) const {
  const float L = static_cast<float>(length), W = static_cast<float>(width);
  TriangleMesh body = box({0.0f, 0.0f, static_cast<float>(ground_clearance)}, {L, W, static_cast<float>(chassis_height)});
  const float roof = static_cast<float>(ground_clearance + chassis_height);
  body.append(box({-0.1f * L, 0.0f, roof}, {static_cast<float>(cabin_length), static_cast<float>(cabin_width), static_cast<float>(cabin_height)}));
  if (mirrors) {
    const float side = 0.5f * W + 0.5f * static_cast<float>(mirror_reach);
    const float z = static_cast<float>(mirror_height) - 0.08f;
    for (float s : {-1.0f, 1.0f})
      body.append(box({0.18f * L, s * side, z}, {0.12f, static_cast<float>(mirror_reach) + 0.02f, 0.16f}));
  }
  return transformed(body, {static_cast<float>(x), static_cast<float>(y), 0.0f}, static_cast<float>(yaw));
}

}  // namespace coloc::sim
