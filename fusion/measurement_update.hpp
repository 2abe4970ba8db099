#pragma once
// One Kalman update of a FilterState by the measured components of a pose or twist. Components whose
// variance is +infinity are simply absent from the record, so the update runs on the others exactly.
#include <array>
#include <cstdint>

#include "coloc/fusion/filter_state.hpp"
#include "coloc/fusion/verdict.hpp"

namespace coloc::fusion {

struct UpdateRecord {
  int m = 0;                              ///< number of EKF components measured (0..3)
  std::array<int, 3> index{};             ///< state index of each component
  std::array<double, 3> value{};          ///< measured value (angles unwrapped at use time)
  Eigen::Matrix3d R = Eigen::Matrix3d::Zero();  ///< covariance of the measured components (top-left m x m)
  int aux_mask = 0;                       ///< bit i set: aux filter i (z, roll, pitch) measured
  std::array<double, 3> aux_value{};
  std::array<double, 3> aux_variance{};
  /// Multiplies every covariance when applied: smoothing applies a measurement n times at n R.
  double scale = 1.0;
  /// s; the measurement was taken this long after the tick it is applied at (negative: before). The
  /// measurement model then carries the tick's state to that moment with its speed and yaw rate.
  double time_offset = 0.0;
  /// The pose measures the position plus the map-matching bias (a source that is not an anchor), where
  /// the state models it (FilterState::bias); otherwise ignored.
  bool biased = false;
  /// rad^2; added to the yaw variance before the update, a share per use (EkfConfig::
  /// yaw_rate_sampling_noise: a twist's yaw rate changed since the source's previous one).
  double yaw_variance_added = 0.0;
};

/// Innovation e = y - H x (angles wrapped) and its covariance S = H P H^T + R (R unscaled).
struct Innovation {
  int m = 0;
  Eigen::Vector3d e = Eigen::Vector3d::Zero();
  Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
};
Innovation innovation(const FilterState& state, const UpdateRecord& record, double scale);

/// The innovation against the measurement's own covariance, from one innovation: the whole
/// d^2 = e^T S^-1 e (0 with nothing measured, +inf if S is not positive definite), and each measured
/// component's e_i^2 / S_ii alone (NisComponent order; NaN where not measured or S_ii is not
/// positive), x and y turned to along and across the state's yaw where both are measured.
struct NormalizedInnovation {
  double d2 = 0.0;
  std::array<double, kNisComponents> components{};
  /// Each component's (H P H')_ii / S_ii: the share of its S that is the state's (NaN where not measured).
  std::array<double, kNisComponents> prediction_share{};
};
NormalizedInnovation normalizedInnovation(const FilterState& state, const UpdateRecord& record);

/// Applies the record with covariance x record.scale. Returns false (state untouched) only if the
/// innovation covariance is not positive definite, which validated input cannot produce.
bool applyUpdate(FilterState& state, const UpdateRecord& record);

/// One tick of the aux filters: the height moved along the slope (vx dt sin(-pitch)), each variance
/// grown by (q dt)^2.
void predictAux(FilterState& state, const std::array<double, 3>& proc_dev, double dt);

}  // namespace coloc::fusion
