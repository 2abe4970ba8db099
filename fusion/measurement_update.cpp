#include "measurement_update.hpp"

#include <cmath>
#include <limits>

#include "motion_model.hpp"

namespace coloc::fusion {

namespace {

bool isAngle(int state_index) { return state_index == kYaw; }

// Solves S X = B for the top-left m x m block of S (m <= 3), via Cholesky; false if S is not
// positive definite. Written out: Eigen's LLT solves a block of right-hand sides through its general
// blocked triangular solver, which cost a fifth of a late pose's update.
template <int Cols>
bool solveSpd(const Eigen::Matrix3d& S, int m, const Eigen::Matrix<double, 3, Cols>& B,
              Eigen::Matrix<double, 3, Cols>& X) {
  if (m < 1 || m > 3) return false;
  double L[3][3] = {};
  for (int j = 0; j < m; ++j) {
    double d = S(j, j);
    for (int k = 0; k < j; ++k) d -= L[j][k] * L[j][k];
    if (!(d > 0.0) || !std::isfinite(d)) return false;
    L[j][j] = std::sqrt(d);
    for (int i = j + 1; i < m; ++i) {
      double v = S(i, j);
      for (int k = 0; k < j; ++k) v -= L[i][k] * L[j][k];
      L[i][j] = v / L[j][j];
    }
  }
  for (int c = 0; c < Cols; ++c) {
    double y[3];
    for (int i = 0; i < m; ++i) {  // L y = b
      double v = B(i, c);
      for (int k = 0; k < i; ++k) v -= L[i][k] * y[k];
      y[i] = v / L[i][i];
    }
    for (int i = m - 1; i >= 0; --i) {  // L^T x = y
      double v = y[i];
      for (int k = i + 1; k < m; ++k) v -= L[k][i] * X(k, c);
      X(i, c) = v / L[i][i];
    }
  }
  return true;
}

void updateAux(ScalarFilter& filter, double value, double variance, bool angle) {
  if (!filter.initialized) {
    filter = {value, variance, true};
    return;
  }
  const double residual = angle ? wrapAngle(value - filter.value) : value - filter.value;
  const double gain = filter.variance / (filter.variance + variance);
  filter.value += gain * residual;
  if (angle) filter.value = wrapAngle(filter.value);
  filter.variance *= 1.0 - gain;
}

// The measurement Jacobian rows and predicted values: a selection of the state, plus, for a
// measurement taken time_offset after its tick, the motion over that time (x, y along the heading
// at vx; yaw at wz).
struct Model {
  Eigen::Matrix<double, 3, 6> H = Eigen::Matrix<double, 3, 6>::Zero();
  Eigen::Matrix<double, 3, 4> He = Eigen::Matrix<double, 3, 4>::Zero();  ///< on the extra states
  bool with_extra = false;  ///< the state models extra states: the update runs on all ten
  Eigen::Vector3d predicted = Eigen::Vector3d::Zero();
};

Model model(const FilterState& state, const UpdateRecord& record) {
  Model out;
  const double dt = record.time_offset, heading = state.x[kYaw] + state.x[kYawBias], vx = state.x[kVx];
  const double c = std::cos(heading), s = std::sin(heading);
  const ExtraStates& extra = state.extra;
  out.with_extra = extra.any();
  for (int i = 0; i < record.m; ++i) {
    const int si = record.index[i];
    out.H(i, si) = 1.0;
    out.predicted[i] = state.x[si];
    if (extra.bias_modelled && record.biased && (si == kX || si == kY)) {
      out.He(i, si == kX ? ExtraStates::kBiasX : ExtraStates::kBiasY) = 1.0;
      out.predicted[i] += extra.v[si == kX ? ExtraStates::kBiasX : ExtraStates::kBiasY];
    }
    // The odometry measures (1 + scale) vx and wz + its gyro's bias.
    if (extra.odometry_modelled && si == kVx) {
      const double scale = extra.v[ExtraStates::kScale];
      out.H(i, kVx) = 1.0 + scale;
      out.He(i, ExtraStates::kScale) = state.x[kVx];
      out.predicted[i] = (1.0 + scale) * state.x[kVx];
    }
    if (extra.odometry_modelled && si == kWz) {
      out.He(i, ExtraStates::kGyroBias) = 1.0;
      out.predicted[i] += extra.v[ExtraStates::kGyroBias];
    }
    if (dt == 0.0) continue;
    if (si == kX || si == kY) {
      const double along = si == kX ? c : s, turn = si == kX ? -s : c;
      out.predicted[i] += vx * along * dt;
      out.H(i, kVx) += along * dt;
      out.H(i, kYaw) += vx * turn * dt;
      out.H(i, kYawBias) += vx * turn * dt;
    } else if (si == kYaw) {
      out.predicted[i] += state.x[kWz] * dt;
      out.H(i, kWz) += dt;
    }
  }
  return out;
}

Innovation innovationWith(const FilterState& state, const UpdateRecord& record, const Model& mdl, double scale) {
  Innovation out;
  out.m = record.m;
  Eigen::Matrix<double, 3, 3> HPHt = mdl.H * state.P * mdl.H.transpose();
  if (mdl.with_extra) {
    const Eigen::Matrix<double, 3, 3> HCHe = mdl.H * state.extra.cross * mdl.He.transpose();
    HPHt += HCHe + HCHe.transpose() + mdl.He * state.extra.P * mdl.He.transpose();
  }
  for (int i = 0; i < record.m; ++i) {
    const int si = record.index[i];
    const double residual = record.value[i] - mdl.predicted[i];
    out.e[i] = isAngle(si) ? wrapAngle(residual) : residual;
    for (int j = 0; j < record.m; ++j) out.S(i, j) = HPHt(i, j) + scale * record.R(i, j);
  }
  return out;
}

// The update on all ten states, the six and the extra ones as blocks: P H^T, the gain and the
// downdate of each block, the same Kalman update as applyUpdate's on the six.
bool applyWithExtra(FilterState& state, const Model& mdl, const Innovation& in) {
  ExtraStates& extra = state.extra;
  Eigen::Matrix<double, 10, 3> PHt;
  PHt.topRows<6>() = state.P * mdl.H.transpose() + extra.cross * mdl.He.transpose();
  PHt.bottomRows<4>() = extra.cross.transpose() * mdl.H.transpose() + extra.P * mdl.He.transpose();
  Eigen::Matrix<double, 3, 10> KT = Eigen::Matrix<double, 3, 10>::Zero();
  if (!solveSpd<10>(in.S, in.m, PHt.transpose(), KT)) return false;
  const Eigen::Matrix<double, 10, 3> K = KT.transpose();
  state.x += K.topRows<6>() * in.e;
  state.x[kYaw] = wrapAngle(state.x[kYaw]);
  extra.v += K.bottomRows<4>() * in.e;
  state.P -= K.topRows<6>() * PHt.topRows<6>().transpose();
  state.P = 0.5 * (state.P + state.P.transpose());
  extra.cross -= K.topRows<6>() * PHt.bottomRows<4>().transpose();
  extra.P -= K.bottomRows<4>() * PHt.bottomRows<4>().transpose();
  extra.P = 0.5 * (extra.P + extra.P.transpose());
  return true;
}

}  // namespace

Innovation innovation(const FilterState& state, const UpdateRecord& record, double scale) {
  return innovationWith(state, record, model(state, record), scale);
}

namespace {

// Each measured component's e_i^2 / S_ii and (H P H')_ii / S_ii; x and y turned into the vehicle's
// frame first (along = (cos, sin) . e, across = (-sin, cos) . e), where a road's weak direction lies.
void componentsOf(const FilterState& state, const UpdateRecord& record, const Innovation& in, NormalizedInnovation& out) {
  out.components.fill(std::numeric_limits<double>::quiet_NaN());
  out.prediction_share.fill(std::numeric_limits<double>::quiet_NaN());
  const auto set = [&](int k, double e, double s, double r) {
    if (!(s > 0.0)) return;
    out.components[k] = e * e / s;
    out.prediction_share[k] = (s - r) / s;
  };
  int row_x = -1, row_y = -1;
  for (int i = 0; i < in.m; ++i) {
    const int si = record.index[i];
    if (si == kX) row_x = i;
    if (si == kY) row_y = i;
    if (si == kYaw) set(kNisYaw, in.e[i], in.S(i, i), record.R(i, i));
    if (si == kVx) set(kNisSpeed, in.e[i], in.S(i, i), record.R(i, i));
    if (si == kWz) set(kNisYawRate, in.e[i], in.S(i, i), record.R(i, i));
  }
  if (row_x >= 0 && row_y >= 0) {
    const double c = std::cos(state.x[kYaw]), s = std::sin(state.x[kYaw]);
    Eigen::Matrix2d turn;
    turn << c, s, -s, c;
    const auto block = [&](const Eigen::Matrix3d& m) {
      Eigen::Matrix2d b;
      b << m(row_x, row_x), m(row_x, row_y), m(row_y, row_x), m(row_y, row_y);
      return Eigen::Matrix2d(turn * b * turn.transpose());
    };
    const Eigen::Vector2d e_body = turn * Eigen::Vector2d(in.e[row_x], in.e[row_y]);
    const Eigen::Matrix2d S_body = block(in.S), R_body = block(record.R);
    set(kNisAlong, e_body.x(), S_body(0, 0), R_body(0, 0));
    set(kNisAcross, e_body.y(), S_body(1, 1), R_body(1, 1));
  }
}

}  // namespace

NormalizedInnovation normalizedInnovation(const FilterState& state, const UpdateRecord& record) {
  NormalizedInnovation out;
  if (record.m == 0) {
    componentsOf(state, record, Innovation{}, out);  // every component NaN: none measured
    return out;
  }
  const Innovation in = innovation(state, record, 1.0);
  componentsOf(state, record, in, out);
  Eigen::Matrix<double, 3, 1> solved = Eigen::Matrix<double, 3, 1>::Zero();
  if (!solveSpd<1>(in.S, in.m, in.e, solved)) {
    out.d2 = kInfinity;
    return out;
  }
  // A plain loop over the measured rows: GCC's array-bounds analysis misreads head(m).dot() on fixed 3-vectors.
  for (int i = 0; i < in.m; ++i) out.d2 += in.e[i] * solved[i];
  return out;
}

bool applyUpdate(FilterState& state, const UpdateRecord& record) {
  // Smoothing applies a record `scale` times: each takes its share, and together the whole.
  if (record.yaw_variance_added > 0.0) state.P(kYaw, kYaw) += record.yaw_variance_added / record.scale;
  if (record.m > 0) {
    const Model mdl = model(state, record);
    const Innovation in = innovationWith(state, record, mdl, record.scale);
    if (mdl.with_extra) {
      if (!applyWithExtra(state, mdl, in)) return false;
    } else {
      // PHt = P H^T (rows of H beyond m are zero).
      const Eigen::Matrix<double, 6, 3> PHt = state.P * mdl.H.transpose();
      // K = PHt S^-1, computed as (S^-1 PHt^T)^T since S is symmetric.
      Eigen::Matrix<double, 3, 6> KT = Eigen::Matrix<double, 3, 6>::Zero();
      if (!solveSpd<6>(in.S, in.m, PHt.transpose(), KT)) return false;
      const Eigen::Matrix<double, 6, 3> K = KT.transpose();
      state.x += K * in.e;
      state.x[kYaw] = wrapAngle(state.x[kYaw]);
      state.P -= K * PHt.transpose();
      state.P = 0.5 * (state.P + state.P.transpose());
    }
  }
  for (int a = 0; a < 3; ++a) {
    if (record.aux_mask & (1 << a))
      updateAux(state.aux[a], record.aux_value[a], record.aux_variance[a] * record.scale, a != kAuxZ);
  }
  return true;
}

void predictAux(FilterState& state, const std::array<double, 3>& proc_dev, double dt) {
  // The height follows the road's slope as the vehicle drives (ROS: pitch positive nose down), so that
  // a late pose's height, applied at its own tick, is carried to now as Autoware carries it
  // (z + vx * delay * sin(-pitch)). Roll and pitch are held: the state has no roll or pitch rate.
  ScalarFilter& z = state.aux[kAuxZ];
  const ScalarFilter& pitch = state.aux[kAuxPitch];
  if (z.initialized && pitch.initialized) z.value += state.x[kVx] * dt * std::sin(-pitch.value);
  for (int a = 0; a < 3; ++a) {
    if (state.aux[a].initialized) state.aux[a].variance += (proc_dev[a] * dt) * (proc_dev[a] * dt);
  }
}

}  // namespace coloc::fusion
