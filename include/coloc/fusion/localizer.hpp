#pragma once
// The Localizer: the one object a vehicle stack or a log replayer talks to. Feed it poses from any
// number of named sources and twists, advance its clock, read the estimate. It owns the EKF, its
// state history (delay compensation), the smoothing queues, the gates and the counters.
//
// Threading: not thread-safe; call it from one thread (or guard it), as a ROS node's single executor does.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "coloc/core/types.hpp"
#include "coloc/fusion/ekf_config.hpp"
#include "coloc/fusion/integrity.hpp"
#include "coloc/fusion/verdict.hpp"

namespace coloc::fusion {

enum class SourceKind : std::uint8_t { kPose, kTwist };

using SourceId = int;

/// The fused estimate at the filter's newest tick.
struct Estimate {
  Stamp stamp = 0;
  Pose pose;  ///< yaw is the heading of motion: measured yaw + estimated yaw bias
  Matrix6d pose_covariance = Matrix6d::Zero();  ///< (x, y, z, roll, pitch, yaw); +inf where never measured
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();   ///< (vx, 0, 0), body frame
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  ///< (0, 0, wz)
  Matrix6d twist_covariance = Matrix6d::Zero();  ///< (vx .. wz); only vx and wz entries are estimated
  double yaw_bias = 0.0;
  Vector6d state = Vector6d::Zero();  ///< raw EKF state [x, y, yaw, yaw_bias, vx, wz]
  Matrix6d state_covariance = Matrix6d::Zero();
  /// The bias NDT's poses share (EkfConfig::map_match_bias_sd; zero where not modelled): NDT's pose
  /// minus the position, map frame, and its covariance.
  Eigen::Vector2d map_match_bias = Eigen::Vector2d::Zero();
  Eigen::Matrix2d map_match_bias_covariance = Eigen::Matrix2d::Zero();
  /// The odometry's slow errors as the filter learned them (EkfConfig::odometry_scale_sd; zero where
  /// not modelled): the share by which its speed reads high, its gyro's bias (rad/s), and their
  /// covariance.
  double odometry_scale_error = 0.0;
  double odometry_yaw_rate_bias = 0.0;
  Eigen::Matrix2d odometry_error_covariance = Eigen::Matrix2d::Zero();
  /// Whether to believe it (see integrity.hpp); degraded or lost, pose_covariance includes the
  /// disagreement that made it so (state_covariance is the filter's own).
  LocalizationState localization = LocalizationState::kInitialising;
};

/// The estimate's pose with the yaw as the pose sources measure it, before the yaw bias (the EKF's
/// own yaw state): where a map matcher must start. Started from the heading of motion, a scan match
/// the scene holds loosely in yaw returns that heading, the filter takes it as a measured yaw one yaw
/// bias off, and in a bend the heading runs away by the bias at every scan (Autoware's NDT likewise
/// starts from the EKF's biased pose).
Pose measuredPose(const Estimate& estimate);

struct SourceReport {
  std::string name;
  SourceKind kind;
  SourceCounters counters;
};

class Localizer {
 public:
  /// Throws coloc::Error naming the key if the config is out of range.
  explicit Localizer(const EkfConfig& config = {});
  ~Localizer();
  Localizer(Localizer&&) noexcept;
  Localizer& operator=(Localizer&&) noexcept;

  /// Registers a named input. Names are unique across kinds; registering a name twice returns its id.
  /// `smoothing_steps`: ticks over which each of the source's poses is applied (0: the configuration's
  /// pose_smoothing_steps); a source registered again keeps what it was registered with first.
  /// `anchor`: a position independent of the vehicle's own map matching (a roadside fix, GNSS), whose
  /// sustained disagreement means the filter, not the source, is wrong (integrity.hpp).
  SourceId addPoseSource(const std::string& name, int smoothing_steps = 0, bool anchor = false);
  SourceId addTwistSource(const std::string& name);
  std::optional<SourceId> findSource(std::string_view name) const;

  /// Starts (or restarts) the filter at a pose; x, y and yaw must be measured. `moving`: the vehicle's
  /// twist then (the odometry's latest), which sets the speed and yaw rate the start otherwise leaves
  /// unknown; components without a finite variance are ignored.
  Verdict initialize(const PoseMeasurement& pose, const std::optional<TwistMeasurement>& moving = std::nullopt);
  bool initialized() const;
  /// Back to before the first initial pose (a clock that went back): the estimate, the history and
  /// every waiting measurement go; sources and counters stay.
  void reset();
  /// The filter's state and its reason, as the estimate carries it.
  const IntegrityStatus& integrity() const;
  /// Tells the filter that another part of the system (a search of the map around a pose given by
  /// hand) doubts its position by `offset` (m, x and y): it becomes degraded, with `reason`, and its
  /// reported covariance covers the offset until an anchor's pose agrees with it.
  void doubt(const std::string& reason, const Eigen::Vector2d& offset);
  /// The same where several places might be the vehicle's: `spread` is added to the reported x/y
  /// covariance (the sum over the places of each offset times itself covers every one within 1 sd).
  void doubt(const std::string& reason, const Eigen::Matrix2d& spread);
  /// The part that doubted vouches for the position after all (a later search finds no place that
  /// matches as well): a doubt that no other disagreement has overtaken since ends.
  void confirm();
  /// Where the map-matching bias is modelled: its spread here (m^2, per axis), which the bias fades
  /// towards from now on (the place's, from an NDT quality map); ignored where it is not modelled.
  /// Throws coloc::Error for a variance that is negative, NaN, infinite or above 1e6.
  void setMapMatchBiasVariance(double variance);
  /// The bias let in at `stamp`'s tick (the newest where it is older than the history), with its
  /// spread per axis (m^2): where the bias was held and NDT's poses followed it (ndt.quality_floor:
  /// noise), the position carries it, and the roadside fix that now tells it apart must be able to
  /// move the position by it. Nothing without the bias state or before the filter started.
  void releaseMapMatchBias(Stamp stamp, double variance);

  Verdict feedPose(SourceId source, const PoseMeasurement& measurement);
  Verdict feedPose(std::string_view source, const PoseMeasurement& measurement);
  Verdict feedTwist(SourceId source, const TwistMeasurement& measurement);
  Verdict feedTwist(std::string_view source, const TwistMeasurement& measurement);

  /// Runs the fixed-rate prediction up to `now` on the caller's clock (live or log time). Measurements
  /// waiting for their tick and the remaining smoothing steps are applied as ticks pass.
  Verdict advanceTo(Stamp now);

  /// The estimate at the newest tick; nullopt before initialisation.
  std::optional<Estimate> estimate();

  /// The estimate at the tick nearest `stamp` (what a scan matcher needs as its initial guess for a
  /// scan taken then), or predicted forward from the newest tick for a later stamp, leaving the filter
  /// unchanged. nullopt before initialisation or for a stamp older than the history.
  std::optional<Estimate> estimateAt(Stamp stamp);

  /// Verdicts decided later than the call that fed them (pending measurements) reach this listener;
  /// every verdict returned from a call also does.
  void setVerdictListener(std::function<void(const Verdict&)> listener);

  std::vector<SourceReport> sources() const;
  const SourceCounters& counters(SourceId source) const;
  const EkfConfig& config() const;
  /// Inputs naming a source that was never registered.
  std::uint64_t unknownSourceCount() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace coloc::fusion
