#include "motion_model.hpp"

#include <cmath>

namespace coloc::fusion {

namespace {

Vector6d predictWith(const Vector6d& x, double dt, double c, double s) {
  Vector6d next = x;
  next[kX] += x[kVx] * c * dt;
  next[kY] += x[kVx] * s * dt;
  next[kYaw] = wrapAngle(x[kYaw] + x[kWz] * dt);
  return next;
}

Matrix6d jacobianWith(const Vector6d& x, double dt, double c, double s) {
  Matrix6d A = Matrix6d::Identity();
  A(kX, kYaw) = A(kX, kYawBias) = -x[kVx] * s * dt;
  A(kY, kYaw) = A(kY, kYawBias) = x[kVx] * c * dt;
  A(kX, kVx) = c * dt;
  A(kY, kVx) = s * dt;
  A(kYaw, kWz) = dt;
  return A;
}

}  // namespace

Vector6d predictState(const Vector6d& x, double dt) {
  const double heading = x[kYaw] + x[kYawBias];
  return predictWith(x, dt, std::cos(heading), std::sin(heading));
}

Matrix6d motionJacobian(const Vector6d& x, double dt) {
  const double heading = x[kYaw] + x[kYawBias];
  return jacobianWith(x, dt, std::cos(heading), std::sin(heading));
}

Vector6d predictState(const Vector6d& x, double dt, Matrix6d& jacobian) {
  const double heading = x[kYaw] + x[kYawBias];
  const double c = std::cos(heading), s = std::sin(heading);
  jacobian = jacobianWith(x, dt, c, s);
  return predictWith(x, dt, c, s);
}

Matrix6d processNoise(const ProcessNoise& noise, double dt) {
  Matrix6d Q = Matrix6d::Zero();
  Q(kYaw, kYaw) = (noise.yaw_c * dt) * (noise.yaw_c * dt);
  Q(kVx, kVx) = (noise.vx_c * dt) * (noise.vx_c * dt);
  Q(kWz, kWz) = (noise.wz_c * dt) * (noise.wz_c * dt);
  Q(kYawBias, kYawBias) = noise.yaw_bias_walk * noise.yaw_bias_walk * dt;
  return Q;
}

Matrix6d propagateCovariance(const Matrix6d& A, const Matrix6d& P, const Matrix6d& Q) {
  // A P: the rows of A that are the identity's copy P's rows; A P A^T: the columns likewise. Every
  // replayed tick of a late measurement pays this, and the dense product was a tenth of its cost.
  constexpr int kMoved[] = {kX, kY, kYaw};
  Matrix6d AP = P;
  for (int i : kMoved) AP.row(i).noalias() = A.row(i) * P;
  Matrix6d next = AP;
  for (int j : kMoved) next.col(j).noalias() = AP * A.row(j).transpose();
  next += Q;
  return 0.5 * (next + next.transpose());
}

void propagateExtra(ExtraStates& extra, const Matrix6d& A, double vx, double dt, const ExtraNoise& noise) {
  extra.cross = A * extra.cross;
  if (extra.bias_modelled) {
    const double phi = std::exp(-std::abs(vx) * dt / noise.bias_length);
    extra.v.head<2>() *= phi;
    extra.cross.leftCols<2>() *= phi;
    extra.P.topLeftCorner<2, 2>() = phi * phi * extra.P.topLeftCorner<2, 2>();
    extra.P.topRightCorner<2, 2>() *= phi;
    extra.P.bottomLeftCorner<2, 2>() *= phi;
    extra.P(ExtraStates::kBiasX, ExtraStates::kBiasX) += (1.0 - phi * phi) * noise.bias_variance;
    extra.P(ExtraStates::kBiasY, ExtraStates::kBiasY) += (1.0 - phi * phi) * noise.bias_variance;
  }
  if (extra.odometry_modelled) {
    extra.P(ExtraStates::kScale, ExtraStates::kScale) += noise.scale_walk * noise.scale_walk * std::abs(vx) * dt;
    extra.P(ExtraStates::kGyroBias, ExtraStates::kGyroBias) += noise.gyro_bias_walk * noise.gyro_bias_walk * dt;
  }
}

}  // namespace coloc::fusion
