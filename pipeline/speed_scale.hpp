#pragma once
// Online calibration of the odometry's speed scale against NDT. Wheel odometry reads speed through a
// wheel radius that is never exact (tyre pressure, wear, load: 0.5-2 %), and the filter trusts it as
// unbiased: a 1 % scale error at 10 m/s puts the estimate 10-30 cm ahead of NDT's own poses. Autoware
// takes the factor as a fixed parameter (vehicle_velocity_converter's speed_scale_factor); here it is
// measured as the ratio of the distance NDT's poses travel to the distance the odometry integrates,
// over chords of a few metres, with exponential forgetting so that it follows slow changes. Each chord
// counts by how well NDT said it placed the chord's two ends: where the scene does not hold NDT along
// the road (a cutting, a corridor) NDT's poses slide with the filter's own guess, and their chords read
// that slide rather than the wheels. On the twin's site D (a 200 m cutting, NDT stating 0.2-0.9 m
// there) the scale learned from every chord alike carried the filter 13.4 cm off along the road within
// the RSU's coverage with NDT alone; weighted, 8.6 cm (the quick run; the fused error 1.05 -> 1.00 cm).
#include <optional>

#include "coloc/core/time.hpp"
#include "coloc/core/types.hpp"
#include "odometry_integral.hpp"

namespace coloc::pipeline {

struct SpeedScaleConfig {
  bool enabled = true;
  double chord = 5.0;          ///< m of odometry travel between the two poses of one comparison
  double memory = 500.0;       ///< m of travel over which old comparisons fade to 1/e
  double min_distance = 5.0;   ///< m of odometry travel before the estimate is used (one chord)
  double max_error = 0.1;      ///< a scale further than this from 1 is refused (counted)
  /// The first chord starts at a pose whose successor agrees with it within this (travel against the
  /// odometry's): a lone bad match there would bias every comparison until the memory forgets it,
  /// where one in the middle of the travel cancels between its two chords.
  double anchor_agreement = 0.1;  ///< m
  /// m: each chord counts by the inverse of its two end poses' variance as NDT stated it (the larger
  /// standard deviation of each), this added to both: where the scene does not hold NDT along the
  /// road (site D's cutting: 0.2-0.9 m stated) its chords read its slide, which it took from the
  /// filter's own guess, not the wheels. <= 0: every chord counts by its length alone.
  double pose_sd_floor = 0.01;
  /// The scale's standard deviation before it is usable: a wheel radius's error (0.5-2 %).
  double prior_sd = 0.02;
};

class SpeedScaleEstimator {
 public:
  explicit SpeedScaleEstimator(SpeedScaleConfig config = {}) : config_(config) {}

  /// A twist as measured: integrates the distance the odometry claims.
  void addTwist(Stamp stamp, double vx);
  /// A pose of the anchoring source (NDT) that the filter accepted, and the larger standard deviation of
  /// its x/y covariance as NDT stated it (m; 0: not stated).
  void addPose(Stamp stamp, const Eigen::Vector2d& position, double sd = 0.0);
  /// True speed per measured speed; 1 until enough travel was compared.
  double scale() const { return usable() ? estimate_ : 1.0; }
  bool usable() const { return config_.enabled && compared_ >= config_.min_distance; }
  /// The standard deviation of scale(): prior_sd until usable, then the chords' own, each chord's
  /// error its two ends' stated variances (at least pose_sd_floor each) over the weighted travel, the
  /// chords taken as independent (consecutive chords share an end, so this is the larger figure).
  double scaleSd() const;
  double comparedDistance() const { return compared_; }

 private:
  SpeedScaleConfig config_;
  OdometryIntegral odometry_;  ///< distance the odometry claims (integral of |vx|)
  // The pose the current chord starts at.
  struct Anchor {
    Eigen::Vector2d position;
    double odometry;  ///< the odometry's distance there
    double sd;        ///< NDT's stated standard deviation there
  };
  std::optional<Anchor> anchor_;
  std::optional<Anchor> candidate_;  ///< a first anchor waiting for its successor's word
  double weighted_pose_ = 0.0, weighted_odometry_ = 0.0;       ///< forgetful sums of chord lengths
  double weighted_variance_ = 0.0;                               ///< forgetful sum of the chords' weighted error variances, m^2
  double estimate_ = 1.0, compared_ = 0.0;
};

}  // namespace coloc::pipeline
