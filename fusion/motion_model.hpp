#pragma once
// The constant-velocity, constant-yaw-rate model of Autoware's ekf_localizer on the state
// [x, y, yaw, yaw_bias, vx, wz]. The vehicle moves along yaw + yaw_bias; yaw is the heading the pose
// sources measure.
#include "coloc/core/types.hpp"
#include "coloc/fusion/filter_state.hpp"

namespace coloc::fusion {

enum StateIndex : int { kX = 0, kY = 1, kYaw = 2, kYawBias = 3, kVx = 4, kWz = 5 };
constexpr int kStateSize = 6;

struct ProcessNoise {
  double yaw_c = 0.005;
  double vx_c = 10.0;
  double wz_c = 5.0;
  double yaw_bias_walk = 0.0;  ///< rad/sqrt(s): Q = walk^2 dt
};

/// x + f(x) dt; yaw wrapped to (-pi, pi].
Vector6d predictState(const Vector6d& x, double dt);

/// d predictState / dx, evaluated at x.
Matrix6d motionJacobian(const Vector6d& x, double dt);

/// Both at once, the heading's sine and cosine taken once (the same values as the two apart).
Vector6d predictState(const Vector6d& x, double dt, Matrix6d& jacobian);

/// diag(0, 0, (yaw_c dt)^2, 0, (vx_c dt)^2, (wz_c dt)^2), Autoware's discrete process noise.
Matrix6d processNoise(const ProcessNoise& noise, double dt);

/// P' = A P A^T + Q for A of motionJacobian's form: the identity but in the rows of x, y and yaw,
/// which is what the product visits (half the multiplications of the dense one).
Matrix6d propagateCovariance(const Matrix6d& A, const Matrix6d& P, const Matrix6d& Q);

/// How the extra states wander (FilterState::extra): the map-matching bias a Gauss-Markov process in
/// distance (it fades to 1/e over bias_length of travel towards a stationary `bias_variance` per axis);
/// the odometry's scale error a random walk in distance and its gyro's bias one in time.
struct ExtraNoise {
  double bias_length = 10.0;    ///< m
  double bias_variance = 0.0;   ///< m^2
  double scale_walk = 0.0;      ///< 1/sqrt(m): the scale error's variance grows by scale_walk^2 per metre
  double gyro_bias_walk = 0.0;  ///< rad/s/sqrt(s)
};

/// The extra states over one step of dt at speed vx: the bias fades by phi = exp(-|vx| dt / length)
/// and its covariance goes to phi^2 P + (1 - phi^2) variance I, which stays at `variance` once there;
/// the odometry's errors are held, their variances grown by their walks; the six states' covariance
/// with them is carried by A and phi.
void propagateExtra(ExtraStates& extra, const Matrix6d& A, double vx, double dt, const ExtraNoise& noise);

}  // namespace coloc::fusion
