#pragma once
// A batch smoother over the filter's inputs: every measurement is used for every pose. States sit at
// the filter's tick rate with the filter's motion model (x, y, yaw, yaw bias, vx, wz) as motion
// residuals weighted by its process noise; poses are residuals with their full covariance on the
// components they measure (an infinite variance leaves its component out exactly), each at its own
// stamp by propagating the state before it; twists likewise. The filter's hard gate becomes a Cauchy
// loss at the gate, the gate applied with hindsight at that solution, and a Huber loss at the gate for
// what passed; what was down-weighted or left out is reported. Each source's noise, the odometry's
// calibration and, optionally, a slow bias of map-matching poses and RSU calibrations are estimated
// with the states. Ceres solves it; its summary and the marginal covariances come back with the
// states. Depends on core and Ceres only.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "coloc/core/types.hpp"

namespace coloc::smoother {

struct SmootherOptions {
  double rate = 50.0;              ///< Hz, the states' spacing (the filter's predict_frequency)
  // The filter's process noise, per second (Autoware's defaults, as fusion.proc_stddev_*).
  double proc_stddev_yaw_c = 0.005;  ///< rad/s
  double proc_stddev_vx_c = 10.0;    ///< m/s^2
  double proc_stddev_wz_c = 5.0;     ///< rad/s^2
  /// The filter's model moves x, y and the yaw bias without noise; a batch problem needs a finite
  /// weight, so they get this much (small: the motion model's own error, not a source of freedom).
  double proc_stddev_position_c = 0.02;  ///< m/s
  double proc_stddev_yaw_bias_c = 1e-4;  ///< rad/s
  /// The least of each process noise the smoother takes from a filter whose figure is zero (a heading
  /// that is its yaw rate's integral): a batch problem weighs the motion by its inverse, and zero would
  /// be an infinite weight the solver cannot evaluate. Per second, in each figure's own unit.
  static constexpr double kLeastProcessNoise = 1e-4;
  /// Motion between states by the trapezoid rule (exact for constant acceleration); false: the filter's
  /// forward step, its model exactly (the smoother then reproduces the filter's last state on a linear
  /// problem).
  bool trapezoid = true;
  double initial_yaw_bias_variance = 1e-4;  ///< rad^2, a prior pulling the bias to 0 (as the filter starts)
  /// Chance that a correct measurement is down-weighted: the Huber loss starts at the square root of
  /// the chi-square (1 - alpha) quantile of its dimension, where the filter's gate refuses; a
  /// measurement still beyond it at the robust solution is then left out and the problem solved again.
  double gate_alpha = 1e-10;
  bool robust = true;
  /// Measure each source's noise on the drive (variance components): its covariances are scaled by
  /// the factor that makes its residuals as large as their redundancy says they should be. Messages'
  /// covariances are claims: the twin's odometry says 0.2 m/s and is 0.05 m/s good, the published fix
  /// sigma is 12 cm for fixes millimetres good. Sources with fewer measurements keep their covariances.
  bool estimate_noise = true;
  /// Map-matching poses (NDT) err slowly: the same centimetre or two for seconds, not afresh each
  /// scan. With this, sources named by setPoseBias measure the position plus a shared bias (bx, by), a
  /// first-order Gauss-Markov process of pose_bias_time, estimated with the states, whose size is
  /// measured where something absolute (the fixes) shows it. Without it, noise estimation takes such
  /// a source's scan-to-scan scatter for its whole error, and what it anchors (an RSU's calibration)
  /// comes out with an uncertainty too small. Beyond pose_bias_time of any pose that carries no bias
  /// (a fix), the bias is held (it fades without new spread), as the filter holds it: there nothing
  /// tells it apart, and the odometry's own slow errors would pass for NDT's (test
  /// PoseBias.AwayFromTheFixes...); not while RSUs are calibrated, whose fixes carry an offset of their
  /// own. Off by default; `coloc smooth` turns it on when calibrating (smoother.pose_bias:
  /// when_calibrating). Without it the smoother takes NDT's poses at their place's whole error, as the
  /// pipeline reports them (Pipeline::onPoseInput), whether or not the filter models the bias.
  bool pose_bias = false;
  double pose_bias_sd = 0.05;   ///< m, the start before it is measured
  double pose_bias_time = 2.0;  ///< s
  /// Estimate each twist source's speed scale and yaw-rate bias with the trajectory (the odometry
  /// reads scale * vx and wz + bias), each with a prior at (1, 0) of these standard deviations: an
  /// odometry whose white noise is measured small must not carry its systematic error into the track.
  bool calibrate_odometry = true;
  double odometry_scale_sd = 0.05;
  double odometry_yaw_rate_bias_sd = 0.01;  ///< rad/s
  int noise_rounds = 4;
  int noise_min_measurements = 20;
  int max_iterations = 50;
  int threads = 2;
  bool covariances = true;  ///< marginal covariance of every state's position
};

/// A measurement the robust loss weighed less than its covariance says.
struct DownWeighted {
  std::string source;
  Stamp stamp = 0;
  double mahalanobis = 0.0;  ///< sqrt of the whitened squared residual at the solution
  double weight = 1.0;       ///< the loss's weight there (1 = full, 0 = left out: beyond the gate)
};

/// A source's noise as the drive measured it: its covariances' standard deviations times `scale`.
struct NoiseScale {
  std::string source;
  double scale = 1.0;
};

struct SmootherSummary {
  int iterations = 0;
  double initial_cost = 0.0, final_cost = 0.0;
  double seconds = 0.0;
  std::string termination;   ///< Ceres' CONVERGENCE, NO_CONVERGENCE, FAILURE...
  std::string report;        ///< Ceres' BriefReport
  int states = 0, pose_residuals = 0, twist_residuals = 0;
  std::vector<DownWeighted> down_weighted;
  std::vector<NoiseScale> noise;  ///< per source whose noise was measured (estimate_noise)
  std::optional<double> pose_bias_sd;  ///< m, the pose bias's size as measured (pose_bias)
  bool usable() const { return termination == "CONVERGENCE" || termination == "NO_CONVERGENCE"; }
};

/// An RSU's calibration as estimated: the offset of its surveyed pose (surveyed minus true: dx, dy,
/// and dyaw about its surveyed position) and of its clock (its clock minus the vehicle's), in the
/// convention of the twin's survey_error and clock_offset_ms.
struct RsuCalibration {
  std::string source;
  double dx = 0.0, dy = 0.0, dyaw = 0.0, clock_offset = 0.0;  ///< m, m, rad, s
  double sd_dx = 0.0, sd_dy = 0.0, sd_dyaw = 0.0, sd_clock_offset = 0.0;
  /// False when the drive does not determine it (no anchoring pose source, a degenerate geometry):
  /// the values are then the starting point, not an estimate.
  bool observable = false;
  /// False when the clock offset could not be told from the survey offset on this drive (one speed
  /// on a straight road): it is then held at 0 and the survey offset absorbs its effect.
  bool clock_observable = true;
  int fixes = 0;     ///< the RSU's fixes that entered (the gate's misfits left out)
  std::string note;  ///< why not, when not; what was held, when something was
};

/// A twist source's calibration as estimated (SmootherOptions::calibrate_odometry).
struct OdometryCalibration {
  std::string source;
  double speed_scale = 1.0, yaw_rate_bias = 0.0;  ///< the odometry reads scale * vx, wz + bias (rad/s)
  double sd_speed_scale = 0.0, sd_yaw_rate_bias = 0.0;
};

struct SmoothedState {
  Stamp stamp = 0;
  Vector6d state = Vector6d::Zero();  ///< [x, y, yaw, yaw_bias, vx, wz]
  Eigen::Vector2d pose_bias = Eigen::Vector2d::Zero();  ///< m, what setPoseBias sources were off by
  std::optional<Eigen::Matrix2d> position_covariance;
};

struct SmootherResult {
  std::vector<SmoothedState> states;
  SmootherSummary summary;
  std::vector<RsuCalibration> calibrations;  ///< one per calibrateRsu, in that order
  std::vector<OdometryCalibration> odometry;  ///< one per twist source, with calibrate_odometry
};

class Smoother {
 public:
  /// Throws coloc::Error naming a process noise that is not finite and > 0.
  explicit Smoother(SmootherOptions options = {});
  ~Smoother();
  Smoother(Smoother&&) noexcept;
  Smoother& operator=(Smoother&&) noexcept;

  /// A pose measurement; x, y and yaw enter where their variance is finite (z, roll and pitch are not
  /// in the planar state). Returns false, leaving the problem unchanged, for a measurement with no
  /// finite x, y or yaw variance, a NaN or negative one, or a covariance not positive definite on them.
  bool addPose(const std::string& source, const PoseMeasurement& measurement);
  /// A twist; vx and wz enter where their variance is finite.
  bool addTwist(const std::string& source, const TwistMeasurement& measurement);
  /// A first guess of the state at a stamp (the filter's estimates, say); states between guesses are
  /// interpolated, and the first guess also anchors a weak prior on the yaw bias.
  void addGuess(Stamp stamp, const Vector6d& state);
  /// A prior on the state at `stamp` (a fixed-lag window's start: what the filter or an earlier window
  /// knew there). Its covariance must be positive definite on the six states.
  bool addPrior(Stamp stamp, const Vector6d& state, const Matrix6d& covariance);
  /// The source's positions carry the slowly varying error of map matching (SmootherOptions::pose_bias).
  void setPoseBias(const std::string& source);
  /// Estimates the survey and clock offsets of the RSU whose fixes come as `source`, jointly with the
  /// trajectory: its fixes are corrected by them before they are compared with the state. Other pose
  /// sources (NDT) anchor the trajectory; without them nothing here is observable, and is said so.
  void calibrateRsu(const std::string& source, const Eigen::Vector2d& surveyed_position, bool clock = true);

  /// Solves for states every 1/rate from `first` to `last`. Throws coloc::Error when there are no
  /// guesses to start from or the span is empty.
  SmootherResult solve(Stamp first, Stamp last) const;

 private:
  SmootherResult solveWith(Stamp first, Stamp last, const std::vector<bool>& clock) const;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace coloc::smoother
