#pragma once
// Online calibration of the vehicle LiDAR's mounting yaw against the direction of travel. An extrinsic
// calibration leaves a few tenths of a degree between the LiDAR's axis and the car's (KITTI: 0.2-0.6
// deg); NDT then reports the car's heading off by that much while the car drives straight on, and the
// filter, which moves the car along its heading, drifts sideways between NDT poses (0.3 deg at 10 m/s:
// 5 mm per scan). The filter's yaw-bias state absorbs it only through that drift, which is below NDT's
// noise scan by scan and takes tens of seconds. Measured directly instead: over a chord of a few metres
// of NDT's own poses, the chord's direction is the direction of travel (on a circular arc, the mean of
// the headings at its ends), and NDT's heading minus it is the mounting yaw.
#include <optional>

#include "coloc/core/types.hpp"

namespace coloc::pipeline {

struct MountYawConfig {
  bool enabled = true;
  double chord = 5.0;           ///< m between the two poses of one comparison
  double memory = 500.0;        ///< m of travel over which old comparisons fade to 1/e
  double min_distance = 5.0;    ///< m compared before the estimate is used: one chord, while the filter still doubts its heading
  double max_yaw = 0.0873;      ///< rad (5 deg): a chord that says more is a jump of NDT or a reversal (refused)
};

class MountYawEstimator {
 public:
  explicit MountYawEstimator(MountYawConfig config = {}) : config_(config) {}

  /// A pose of the anchoring source (NDT) that the filter accepted, as NDT gave it.
  void addPose(const Eigen::Vector2d& position, double yaw);
  /// NDT's heading minus the direction of travel, rad; 0 until enough travel was compared.
  double yaw() const { return usable() ? estimate_ : 0.0; }
  bool usable() const { return config_.enabled && compared_ >= config_.min_distance; }
  double comparedDistance() const { return compared_; }

 private:
  MountYawConfig config_;
  std::optional<std::pair<Eigen::Vector2d, double>> anchor_;  ///< position, heading
  double weighted_offset_ = 0.0, weighted_length_ = 0.0;      ///< forgetful sums, by chord length
  double estimate_ = 0.0, compared_ = 0.0;
};

}  // namespace coloc::pipeline
