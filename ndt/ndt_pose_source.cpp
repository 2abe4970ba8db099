#include "coloc/ndt/ndt_pose_source.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <string>

#include "coloc/ndt/alignment_memo.hpp"

namespace coloc::ndt {

namespace {

Eigen::Matrix4d matrixOf(const Pose& pose) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = pose.orientation.normalized().toRotationMatrix();
  T.topRightCorner<3, 1>() = pose.position;
  return T;
}

// The deskew's twist is taken to 1 mm/s and 1e-5 rad/s: over a 0.1 s sweep the rounding moves a point
// by at most 0.05 mm (0.03 mm at 60 m for the turn), a four-hundredth of a LiDAR's range noise. Replays
// of one log whose filters agree that closely preprocess each scan once (AlignmentMemo): on the quick
// experiment's drives 46 % of the preprocessing, which was a sixth of the full run's time.
constexpr double kDeskewSpeedStep = 1e-3, kDeskewYawRateStep = 1e-5;

// The prediction NDT starts from is taken to 5 mm and 0.25 mrad in roll, pitch and yaw: the rounding
// moves a scan point by at most 2.5 mm plus 7.5 mm at the 60 m it reaches, within the last step NDT
// takes before it stops (transformation_epsilon: 1 cm), and the match converges to the same optimum
// (a step apart, within a micrometre: test AlignmentMemo.PredictionsWithinTheGuesssRounding...).
// Replays of one log whose filters agree that closely then match each scan once (AlignmentMemo).
constexpr double kGuessStep = 5e-3, kGuessAngleStep = 2.5e-4;

double roundedTo(double value, double step) { return std::isfinite(value) ? std::round(value / step) * step : value; }

// Why `predicted` is no pose to start from, or empty.
std::string notAPose(const Pose& predicted) {
  if (!predicted.position.allFinite()) return "the predicted position is not finite";
  if (!predicted.orientation.coeffs().allFinite()) return "the predicted orientation is not finite";
  if (!(predicted.orientation.norm() > 1e-9)) return "the predicted orientation is a quaternion of no length";
  return {};
}

Pose roundedGuess(const Pose& predicted) {
  Pose out;
  for (int i = 0; i < 3; ++i) out.position[i] = roundedTo(predicted.position[i], kGuessStep);
  const Eigen::Vector3d rpy = rollPitchYaw(predicted.orientation.normalized());
  out.orientation = quaternionFromRollPitchYaw(roundedTo(rpy.x(), kGuessAngleStep), roundedTo(rpy.y(), kGuessAngleStep), roundedTo(rpy.z(), kGuessAngleStep));
  return out;
}

}  // namespace

NdtPoseSource::NdtPoseSource(TileMap map, const NdtPoseSourceConfig& config, std::shared_ptr<TargetCache> targets,
                             std::shared_ptr<AlignmentMemo> alignments)
    : config_((validate(config), config)),
      map_(std::move(map), config.ndt, config.map, std::move(targets)),
      alignments_(std::move(alignments)),
      fingerprint_(alignments_ ? configFingerprint(config_) : std::string()),
      preprocess_fingerprint_(alignments_ ? preprocessFingerprint(config_.preprocess) : std::string()) {
  const Vector6d& p = config.lidar_pose;
  Pose lidar;
  lidar.position = p.head<3>();
  lidar.orientation = quaternionFromRollPitchYaw(p[3], p[4], p[5]);
  base_to_lidar_ = matrixOf(lidar);
}

NdtPoseSource::~NdtPoseSource() = default;

ScanOutcome NdtPoseSource::process(const PointCloud& scan, Stamp stamp, const Pose& predicted, double vx, double wz) {
  return process(scan, nullptr, stamp, predicted, vx, wz);
}

ScanOutcome NdtPoseSource::process(const std::shared_ptr<const PointCloud>& scan, Stamp stamp, const Pose& predicted, double vx, double wz) {
  return process(*scan, alignments_ ? &scan : nullptr, stamp, predicted, vx, wz);
}

ScanOutcome NdtPoseSource::process(const PointCloud& scan, const std::shared_ptr<const PointCloud>* shared, Stamp stamp, const Pose& prediction,
                                   double vx, double wz) {
  ++counters_.scans;
  if (const std::string why = notAPose(prediction); !why.empty()) {
    ++counters_.bad_prediction;
    ScanOutcome out;
    out.detail = why;
    return out;
  }
  const Pose predicted = roundedGuess(prediction);
  vx = roundedTo(vx, kDeskewSpeedStep);
  wz = roundedTo(wz, kDeskewYawRateStep);
  // The map moves with the prediction whether or not the outcome is shared: its state is this source's.
  map_.update(predicted.position.head<2>());
  const auto target = map_.target();
  if (!target) {
    ++counters_.no_map;
    ScanOutcome out;
    out.detail = "no map tile within reach of the predicted position";
    return out;
  }
  ScanOutcome out;
  if (shared) {
    bool computed = false;
    out = alignments_->answer(fingerprint_, {*shared, stamp, target, predicted, vx, wz}, [&] {
      computed = true;
      return match(*alignments_->preprocessed(preprocess_fingerprint_, *shared, vx, wz,
                                              [&] { return preprocessScan(scan, config_.preprocess, vx, wz); }),
                   stamp, predicted, *target);
    });
    if (!computed) ++counters_.shared;
  } else {
    out = match(preprocessScan(scan, config_.preprocess, vx, wz), stamp, predicted, *target);
  }
  count(out);
  return out;
}

ScanOutcome NdtPoseSource::match(const PointCloud& cloud, Stamp stamp, const Pose& predicted, const NdtTarget& target) const {
  ScanOutcome out;
  out.points_used = cloud.size();
  if (cloud.empty()) {
    out.alignment.rejection = AlignRejection::kEmptySource;
    out.detail = "no point left after preprocessing";
    return out;
  }
  // NDT aligns the LiDAR frame; the filter wants the vehicle: map_T_base = map_T_lidar * lidar_T_base.
  const Eigen::Matrix4d guess = matrixOf(predicted) * base_to_lidar_;
  out.alignment = align(target, cloud, guess, config_.ndt);
  if (!out.alignment.accepted()) {
    out.detail = std::string(toString(out.alignment.rejection)) + ": " + out.alignment.detail;
    return out;
  }
  producePose(out, stamp);
  return out;
}

void NdtPoseSource::producePose(ScanOutcome& out, Stamp stamp) const {
  const Eigen::Matrix4d base = out.alignment.transform * base_to_lidar_.inverse();
  out.pose.stamp = stamp;
  out.pose.pose.position = base.topRightCorner<3, 1>();
  out.pose.pose.orientation = Eigen::Quaterniond(base.topLeftCorner<3, 3>()).normalized();
  out.pose.covariance = out.alignment.covariance;
  out.produced = true;
}

void NdtPoseSource::count(const ScanOutcome& out) {
  counters_.align_ms_total += out.alignment.elapsed_ms;
  switch (out.alignment.rejection) {
    case AlignRejection::kNone: break;
    case AlignRejection::kMaxIterations: ++counters_.max_iterations; break;
    case AlignRejection::kOscillation: ++counters_.oscillation; break;
    case AlignRejection::kLowScore: ++counters_.low_score; break;
    case AlignRejection::kEmptySource: ++counters_.empty_scan; break;
  }
  if (out.produced) ++counters_.poses;
}

}  // namespace coloc::ndt
