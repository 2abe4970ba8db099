#pragma once
// The smoother's residuals: what each measurement and each step of the motion says about the states,
// whitened by its covariance. Most are written once for doubles and Ceres' dual numbers (automatic
// derivatives); the twist's and the pose bias's, one per tick each and linear, have their derivatives
// written out (TwistCost, BiasProcessCost), the same bits as the dual numbers carry (tested).
// Private to smoother/.
#include <ceres/ceres.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "coloc/core/types.hpp"

namespace coloc::smoother::residuals {

// The state blocks: the filter's six (x, y, yaw, yaw bias, vx, wz), then the slowly varying error
// (bx, by) that map-matching pose sources share (SmootherOptions::pose_bias).
constexpr int kState = 8;

// The filter's motion model, written once for doubles and Ceres' Jets: constant speed and yaw rate,
// moving along yaw + yaw bias.
template <typename T, typename D>
void propagate(const T* s, D dt, T* out) {
  using std::cos;
  using std::sin;
  const T heading = s[2] + s[3];
  out[0] = s[0] + s[4] * cos(heading) * dt;
  out[1] = s[1] + s[4] * sin(heading) * dt;
  out[2] = s[2] + s[5] * dt;
  out[3] = s[3];
  out[4] = s[4];
  out[5] = s[5];
}

template <typename T>
T wrapped(const T& angle) {
  using std::atan2;
  using std::cos;
  using std::sin;
  return atan2(sin(angle), cos(angle));
}

// r = L e over the first m components, L lower triangular (the inverse of the measurement's
// covariance factor): a residual whitened by its covariance.
template <typename T, typename Lower>
void whiten(const Lower& lower, const T* e, int m, T* r) {
  for (int i = 0; i < m; ++i) {
    r[i] = T(0.0);
    for (int j = 0; j <= i; ++j) r[i] += lower(i, j) * e[j];
  }
}

struct MotionResidual {
  double dt;
  bool trapezoid;
  Vector6d inverse_sigma;
  template <typename T>
  bool operator()(const T* a, const T* b, T* r) const {
    // The trapezoid rule (mean speed, mean heading, mean yaw rate) is exact for constant acceleration,
    // where the filter's forward step is off by a dt^2 / 2, which over a drive of exact measurements
    // biases what is estimated with it (RSU calibration). The forward step is the filter's model exactly.
    using std::cos;
    using std::sin;
    T predicted[6];
    if (trapezoid) {
      const T speed = 0.5 * (a[4] + b[4]);
      const T heading = a[2] + a[3] + 0.5 * wrapped(T(b[2] + b[3] - a[2] - a[3]));
      predicted[0] = a[0] + speed * cos(heading) * dt;
      predicted[1] = a[1] + speed * sin(heading) * dt;
      predicted[2] = a[2] + 0.5 * (a[5] + b[5]) * dt;
      predicted[3] = a[3];
      predicted[4] = a[4];
      predicted[5] = a[5];
    } else {
      propagate(a, dt, predicted);
    }
    for (int i = 0; i < 6; ++i) {
      T d = b[i] - predicted[i];
      if (i == 2) d = wrapped(d);
      r[i] = d * inverse_sigma[i];
    }
    return true;
  }
};

// A measurement of some of (x, y, yaw) at `dt` after the state it hangs on.
struct PoseResidual {
  double dt;
  bool biased;  ///< the source measures the position plus the shared pose bias
  int m;
  int component[3];  ///< state index of each measured component: 0 x, 1 y, 2 yaw
  double value[3];
  Eigen::Matrix3d whitening;  ///< L^-1 of the measured block's covariance (upper-left m x m)
  template <typename T>
  bool operator()(const T* s, T* r) const {
    T p[6];
    propagate(s, dt, p);
    T e[3];
    for (int j = 0; j < m; ++j) {
      e[j] = p[component[j]] - value[j];
      if (biased && component[j] < 2) e[j] += s[6 + component[j]];
      if (component[j] == 2) e[j] = wrapped(e[j]);
    }
    whiten(whitening, e, m, r);
    return true;
  }
};

// A measurement of vx and/or wz at a fraction `w` of the way from one state to the next, read by an
// odometry of speed scale `scale` and yaw-rate bias `bias` (1 and 0 unless calibrated).
struct TwistResidual {
  double w;
  int m;
  int component[2];  ///< 4 vx, 5 wz
  double value[2];
  Eigen::Matrix2d whitening;
  template <typename T>
  void residual(const T* a, const T* b, const T& scale, const T& bias, T* r) const {
    T e[2];
    for (int j = 0; j < m; ++j) {
      const int c = component[j];
      const T state = (1.0 - w) * a[c] + w * b[c];
      e[j] = (c == 4 ? scale * state : state + bias) - value[j];
    }
    whiten(whitening, e, m, r);
  }
  template <typename T>
  bool operator()(const T* a, const T* b, T* r) const {
    residual(a, b, T(1.0), T(0.0), r);
    return true;
  }
};

// A twist through its source's calibration o = (speed scale, yaw-rate bias).
struct CalibratedTwistResidual {
  TwistResidual twist;
  template <typename T>
  bool operator()(const T* a, const T* b, const T* o, T* r) const {
    twist.residual(a, b, o[0], o[1], r);
    return true;
  }
};

// The twist residual with its derivatives written out. It is linear in the two states (bilinear with
// the odometry's calibration) and there is one per twist: automatic differentiation through 16 or 18
// dual numbers cost a solve 6-8 % more (build/bench/smoother_bench). The derivatives are the ones the
// dual numbers carry, computed in the same order: the same bits (test SmootherResiduals.*).
class TwistCost final : public ceres::CostFunction {
 public:
  TwistCost(const TwistResidual& r, bool calibrated) : r_(r), calibrated_(calibrated) {
    set_num_residuals(r.m);
    mutable_parameter_block_sizes()->push_back(kState);
    mutable_parameter_block_sizes()->push_back(kState);
    if (calibrated) mutable_parameter_block_sizes()->push_back(2);
  }
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const double* a = parameters[0];
    const double* b = parameters[1];
    const double scale = calibrated_ ? parameters[2][0] : 1.0, bias = calibrated_ ? parameters[2][1] : 0.0;
    // Per component: the error and its derivatives by a[c], b[c], the scale and the bias.
    double e[2], by_a[2], by_b[2], by_scale[2], by_bias[2];
    for (int j = 0; j < r_.m; ++j) {
      const int c = r_.component[j];
      const double state = (1.0 - r_.w) * a[c] + r_.w * b[c];
      if (c == 4) {
        e[j] = scale * state - r_.value[j];
        by_a[j] = scale * (1.0 - r_.w), by_b[j] = scale * r_.w, by_scale[j] = state, by_bias[j] = 0.0;
      } else {
        e[j] = state + bias - r_.value[j];
        by_a[j] = 1.0 - r_.w, by_b[j] = r_.w, by_scale[j] = 0.0, by_bias[j] = 1.0;
      }
    }
    whiten(r_.whitening, e, r_.m, residuals);
    if (!jacobians) return true;
    // Row i of a Jacobian: sum over j <= i of L(i, j) times component j's derivative, as whiten sums.
    const auto row = [&](int i, const double* d) {
      double sum = 0.0;
      for (int j = 0; j <= i; ++j) sum += r_.whitening(i, j) * d[j];
      return sum;
    };
    for (int k = 0; k < 2; ++k) {
      double* J = jacobians[k];
      if (!J) continue;
      std::fill(J, J + r_.m * kState, 0.0);
      for (int i = 0; i < r_.m; ++i)
        for (int j = 0; j <= i; ++j) {
          // Each component's derivative lies in its own column; a column two components share (the
          // same state twice) does not occur.
          double d[2] = {0.0, 0.0};
          d[j] = k == 0 ? by_a[j] : by_b[j];
          J[i * kState + r_.component[j]] += row(i, d);
        }
    }
    if (calibrated_ && jacobians[2]) {
      double* J = jacobians[2];
      for (int i = 0; i < r_.m; ++i) J[i * 2 + 0] = row(i, by_scale), J[i * 2 + 1] = row(i, by_bias);
    }
    return true;
  }

 private:
  TwistResidual r_;
  bool calibrated_;
};

// What an odometry's calibration is before the drive says otherwise: scale 1, no bias.
struct OdometryPrior {
  double inverse_sd_scale, inverse_sd_bias;
  template <typename T>
  bool operator()(const T* o, T* r) const {
    r[0] = (o[0] - 1.0) * inverse_sd_scale;
    r[1] = o[1] * inverse_sd_bias;
    return true;
  }
};

// A roadside fix corrected by its RSU's calibration c = (dx, dy, dyaw, clock offset): the RSU computed
// it through its surveyed pose, so the vehicle was at ps - d + R(-dyaw) (z - ps), at the fix's stamp
// minus the clock offset.
struct CalibratedFixResidual {
  double dt;  ///< from the state to the fix's stamp (on the RSU's clock)
  double zx, zy, px, py;
  Eigen::Matrix2d whitening;
  template <typename T>
  bool operator()(const T* s, const T* c, T* r) const {
    using std::cos;
    using std::sin;
    T p[6];
    propagate(s, T(dt) - c[3], p);
    const T cy = cos(-c[2]), sy = sin(-c[2]);
    const double lx = zx - px, ly = zy - py;
    const T x = px - c[0] + cy * lx - sy * ly;
    const T y = py - c[1] + sy * lx + cy * ly;
    const T e0 = p[0] - x, e1 = p[1] - y;
    r[0] = whitening(0, 0) * e0;
    r[1] = whitening(1, 0) * e0 + whitening(1, 1) * e1;
    return true;
  }
};

// The pose bias as a first-order Gauss-Markov process: b' = phi b, with the noise that keeps its
// standard deviation steady.
struct BiasProcess {
  double phi, inverse_sigma;
  template <typename T>
  bool operator()(const T* a, const T* b, T* r) const {
    r[0] = (b[6] - phi * a[6]) * inverse_sigma;
    r[1] = (b[7] - phi * a[7]) * inverse_sigma;
    return true;
  }
};

// The pose bias's process, linear, with its derivatives written out (one per tick).
class BiasProcessCost final : public ceres::SizedCostFunction<2, kState, kState> {
 public:
  explicit BiasProcessCost(const BiasProcess& p) : p_(p) {}
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const double* a = parameters[0];
    const double* b = parameters[1];
    residuals[0] = (b[6] - p_.phi * a[6]) * p_.inverse_sigma;
    residuals[1] = (b[7] - p_.phi * a[7]) * p_.inverse_sigma;
    if (!jacobians) return true;
    for (int k = 0; k < 2; ++k) {
      double* J = jacobians[k];
      if (!J) continue;
      std::fill(J, J + 2 * kState, 0.0);
      const double d = (k == 0 ? -p_.phi : 1.0) * p_.inverse_sigma;
      J[0 * kState + 6] = d;
      J[1 * kState + 7] = d;
    }
    return true;
  }

 private:
  BiasProcess p_;
};

struct BiasPrior {
  double inverse_sigma;
  template <typename T>
  bool operator()(const T* s, T* r) const {
    r[0] = s[6] * inverse_sigma;
    r[1] = s[7] * inverse_sigma;
    return true;
  }
};

struct StatePrior {
  Vector6d mean;
  Matrix6d whitening;  ///< L^-1 of its covariance
  template <typename T>
  bool operator()(const T* s, T* r) const {
    T e[6];
    for (int j = 0; j < 6; ++j) e[j] = s[j] - mean[j];
    e[2] = wrapped(e[2]);
    whiten(whitening, e, 6, r);
    return true;
  }
};

struct YawBiasPrior {
  double inverse_sigma;
  template <typename T>
  bool operator()(const T* s, T* r) const {
    r[0] = s[3] * inverse_sigma;
    return true;
  }
};

}  // namespace coloc::smoother::residuals
