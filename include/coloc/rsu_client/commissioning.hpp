#pragma once
// Commissioning an RSU against a reference vehicle: a probe vehicle with an RTK/INS reference drives
// past the RSU, and its fixes, matched by stamp to the reference trajectory, give the RSU's survey
// error (dx, dy, dyaw: its surveyed pose minus its true pose) and its clock offset, as a registry
// calibration entry. Unlike `coloc smooth --calibrate-rsus`, which is anchored by NDT and inherits
// NDT's bias near the RSU, this is anchored by the reference alone; what limits it is the fixes' own
// error.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "coloc/rsu_client/rsu_registry.hpp"

namespace coloc::rsu_client {

/// One fix as the RSU reported it (through its surveyed pose) and the reference vehicle's position
/// and velocity at the fix's stamp (read on the vehicle's clock).
struct CommissioningSample {
  Eigen::Vector2d fix, reference, velocity;
};

struct CommissioningResult {
  RsuCalibrationEntry calibration;
  Eigen::Vector4d sd = Eigen::Vector4d::Constant(-1.0);  ///< of dx, dy (m), dyaw (rad), clock (s); < 0: not estimated
  bool determined = false;        ///< sd within 1 cm / 0.1 deg with at least `min_fixes` inliers
  bool clock_observable = false;  ///< the drive separates the clock from the along-road shift; else held at 0
  std::size_t inliers = 0, outliers = 0;
  std::size_t not_finite = 0;     ///< samples with a NaN or infinite value, left out
  double residual_sd = 0.0;       ///< m per axis, of the corrected fixes against the reference
  std::string note;               ///< why not determined
  /// Per finite sample: the corrected fix minus the reference at its stamp (corrected for the clock), m.
  std::vector<Eigen::Vector2d> residuals;
};

struct CommissioningConfig {
  std::size_t min_fixes = 10;
  double max_position_sd = 0.01;                            ///< m
  double max_yaw_sd = 0.1 * 3.14159265358979323846 / 180.0;  ///< rad
  double max_clock_sd = 0.005;                              ///< s; a clock less well determined is held at 0
};

/// Least squares over the samples (rotation exact, Gauss-Newton), with residuals beyond 3 robust
/// standard deviations left out and the fit repeated. `registry_position` is the RSU's position as its
/// registry lists it (the surveyed one), about which a yaw error turns its fixes.
CommissioningResult commissionRsu(const Eigen::Vector2d& registry_position, const std::vector<CommissioningSample>& samples,
                                  const CommissioningConfig& config = {});

/// Each sample's residual under a calibration (the corrected fix minus the reference at its corrected
/// stamp), as CommissioningResult::residuals has them for the samples it was fitted on: for fixes it
/// was not fitted on (a probe of entered size commissioned the RSU; these are what it sends others).
std::vector<Eigen::Vector2d> commissioningResiduals(const Eigen::Vector2d& registry_position, const std::vector<CommissioningSample>& samples,
                                                    const RsuCalibrationEntry& calibration);

}  // namespace coloc::rsu_client
