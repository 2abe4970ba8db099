#pragma once
// An independent re-implementation of Autoware's time-delay EKF (autoware_kalman_filter's
// TimeDelayKalmanFilter driven as ekf_localizer drives it): the state of the last N ticks stacked into
// one 6N vector with a dense 6N x 6N covariance. It is the reference the tests compare coloc's
// history-replay filter against, and the baseline the benchmark measures coloc's cost against.
// It follows the upstream algorithm and its costs on purpose (a fresh zeroed 6N x 6N matrix per
// prediction, a dense rank-m downdate per update); do not optimise it.
#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <vector>

#include "motion_model.hpp"

namespace coloc::testing {

class AugmentedStateEkf {
 public:
  AugmentedStateEkf(int steps, const fusion::ProcessNoise& noise, double dt)
      : n_(steps), dt_(dt), Q_(fusion::processNoise(noise, dt)) {}

  /// As ekf_localizer's initial pose: the same state and covariance in every slot, no cross terms.
  void initialize(const Vector6d& x, const Matrix6d& P) {
    x_.resize(6 * n_);
    P_ = Eigen::MatrixXd::Zero(6 * n_, 6 * n_);
    for (int i = 0; i < n_; ++i) {
      x_.segment<6>(6 * i) = x;
      P_.block<6, 6>(6 * i, 6 * i) = P;
    }
  }

  void predict() {
    const Vector6d x0 = x_.head<6>();
    const Matrix6d A = fusion::motionJacobian(x0, dt_);
    const int d = 6 * n_;
    Eigen::VectorXd x_next(d);
    x_next.head<6>() = fusion::predictState(x0, dt_);
    x_next.tail(d - 6) = x_.head(d - 6);
    Eigen::MatrixXd P_next = Eigen::MatrixXd::Zero(d, d);
    P_next.block<6, 6>(0, 0) = A * P_.block<6, 6>(0, 0) * A.transpose() + Q_;
    P_next.block(0, 6, 6, d - 6) = A * P_.block(0, 0, 6, d - 6);
    P_next.block(6, 0, d - 6, 6) = P_.block(0, 0, d - 6, 6) * A.transpose();
    P_next.block(6, 6, d - 6, d - 6) = P_.block(0, 0, d - 6, d - 6);
    x_ = std::move(x_next);
    P_ = std::move(P_next);
  }

  /// Update of slot `delay` by the state components `index` (yaw innovation wrapped).
  bool update(int delay, const std::vector<int>& index, const Eigen::VectorXd& y, const Eigen::MatrixXd& R) {
    if (delay < 0 || delay >= n_) return false;
    const int m = static_cast<int>(index.size());
    const int d = 6 * n_;
    Eigen::VectorXd e(m);
    Eigen::MatrixXd S(m, m), G(d, m);
    for (int i = 0; i < m; ++i) {
      const int si = 6 * delay + index[i];
      e[i] = y[i] - x_[si];
      if (index[i] == fusion::kYaw) e[i] = wrapAngle(e[i]);
      for (int j = 0; j < m; ++j) S(i, j) = P_(si, 6 * delay + index[j]) + R(i, j);
      G.col(i) = P_.col(si);
    }
    Eigen::LLT<Eigen::MatrixXd> llt(S);
    if (llt.info() != Eigen::Success) return false;
    const Eigen::MatrixXd K = llt.solve(G.transpose()).transpose();
    x_ += K * e;
    P_.noalias() -= K * G.transpose();
    return true;
  }

  Vector6d latest() const { return x_.head<6>(); }
  Matrix6d latestCovariance() const { return P_.block<6, 6>(0, 0); }
  int steps() const { return n_; }

 private:
  int n_;
  double dt_;
  Matrix6d Q_;
  Eigen::VectorXd x_;
  Eigen::MatrixXd P_;
};

}  // namespace coloc::testing
