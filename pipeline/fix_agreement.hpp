#pragma once
// NDT's position held against the roadside's fixes. NDT's covariance from its score says how sharply
// the scan fits the map, not where the map is: a map surveyed a few centimetres off the world, or a
// scene whose optimum lies off the truth (a street alike along its length), gives poses that agree
// with each other to a centimetre and are all off by the same decimetre. No scan-to-scan test can see
// that; a fix can, where the vehicle is within an RSU's coverage. So each NDT pose is compared with
// the fixes of the last seconds (each carried to the pose's stamp by the odometry's distance along
// NDT's heading), and the median disagreement's part beyond the tolerance is added to NDT's x/y
// covariance, as the travel check adds its own: the fixes then weigh as much as what they show. Away
// from an RSU nothing changes. The fixes are those that passed the registry's checks; an RSU surveyed
// off is the commissioning's matter, and a fix off by more than the gate is the filter's.
#include <deque>
#include <optional>
#include <Eigen/Core>

#include "coloc/core/time.hpp"
#include "odometry_integral.hpp"

namespace coloc::pipeline {

struct FixAgreementConfig {
  double window = 2.0;       ///< s: fixes this old or newer than an NDT pose are compared with it; 0 = off
  double tolerance = 0.03;   ///< m of disagreement the fixes' and NDT's noise and the RSU's survey explain
  int min_fixes = 3;         ///< fixes in the window before anything is said
};

class FixAgreement {
 public:
  explicit FixAgreement(FixAgreementConfig config = {});

  /// The odometry's speed as the filter takes it (its learned scale applied), m/s.
  void addSpeed(Stamp stamp, double speed);
  /// A fix that passed the registry's checks, with the x/y variance it is taken at (m^2; 0: unknown).
  void addFix(Stamp stamp, const Eigen::Vector2d& position, double variance = 0.0);
  /// An NDT pose: the fixes' median disagreement with it beyond the tolerance (zero within it);
  /// nullopt with fewer than min_fixes in the window, no odometry, a non-finite pose or the check off.
  /// `ndt_variance`: what NDT is worth where the pose is (ndt.quality_map; 0: unknown). Known, and the
  /// fixes' variance known, the excess is NDT's in the share its variance has of the two: an RSU a few
  /// centimetres off where a drive with a reference found NDT a centimetre good widens NDT by little,
  /// and where NDT was found poor the fixes' word stands. Unknown, the disagreement is all NDT's.
  std::optional<Eigen::Vector2d> check(Stamp stamp, const Eigen::Vector2d& position, double yaw, double ndt_variance = 0.0);
  void reset();

 private:
  struct Fix {
    Stamp stamp;
    Eigen::Vector2d position;
    double variance;  ///< m^2; 0: unknown
  };
  FixAgreementConfig config_;
  OdometryIntegral distance_;
  std::deque<Fix> fixes_;
};

}  // namespace coloc::pipeline
