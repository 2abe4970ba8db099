#include "motion_model.hpp"

#include <cmath>

namespace coloc::fusion {

Vector6d predictState(const Vector6d& x, double dt) {
  const double heading = x[kYaw] + x[kYawBias];
  Vector6d next = x;
  next[kX] += x[kVx] * std::cos(heading) * dt;
  next[kY] += x[kVx] * std::sin(heading) * dt;
  next[kYaw] = wrapAngle(x[kYaw] + x[kWz] * dt);
  return next;
}

Matrix6d motionJacobian(const Vector6d& x, double dt) {
  const double heading = x[kYaw] + x[kYawBias];
  const double c = std::cos(heading), s = std::sin(heading);
  Matrix6d A = Matrix6d::Identity();
  A(kX, kYaw) = A(kX, kYawBias) = -x[kVx] * s * dt;
  A(kY, kYaw) = A(kY, kYawBias) = x[kVx] * c * dt;
  A(kX, kVx) = c * dt;
  A(kY, kVx) = s * dt;
  A(kYaw, kWz) = dt;
  return A;
}

Matrix6d processNoise(const ProcessNoise& noise, double dt) {
  Matrix6d Q = Matrix6d::Zero();
  Q(kYaw, kYaw) = (noise.yaw_c * dt) * (noise.yaw_c * dt);
  Q(kVx, kVx) = (noise.vx_c * dt) * (noise.vx_c * dt);
  Q(kWz, kWz) = (noise.wz_c * dt) * (noise.wz_c * dt);
  return Q;
}

Matrix6d propagateCovariance(const Matrix6d& A, const Matrix6d& P, const Matrix6d& Q) {
  // Fixed-size 6x6 products are already unrolled by Eigen; the sparsity of A would save little
  // and make the frozen-linearisation replay (arbitrary A) a second code path.
  Matrix6d next = A * P * A.transpose() + Q;
  return 0.5 * (next + next.transpose());
}

}  // namespace coloc::fusion
