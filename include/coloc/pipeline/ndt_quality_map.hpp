#pragma once
// Where NDT is good and where it falls short, learned from a drive with a reference (ground truth,
// RTK, a smoothed drive): NDT's mean square x/y error in each cell of the map. NDT's covariance from
// its score says how sharply the scan fits the map, not whether the map holds the place (a corridor
// alike along its length, facades changed since the survey give sharp fits that are decimetres off);
// one floor for a whole site either hides NDT's good matches where it is right or trusts it where it
// is not. Each NDT pose's x/y variance is held at least at its cell's figure (the default where the
// drive left too few poses). Nothing here knows NDT or the filter.
#include <Eigen/Core>
#include <cstddef>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace coloc::pipeline {

/// One NDT pose of the reference drive: where NDT put the vehicle (what a pose is looked up by, as
/// the vehicle cannot know the truth) and its error against the reference, x and y.
struct NdtQualitySample {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  Eigen::Vector2d error = Eigen::Vector2d::Zero();
  /// rad, the vehicle's heading there (the reference's), for NDT's noise along and across it; NaN:
  /// not known, and the pose counts in the noise per axis only.
  double heading = std::numeric_limits<double>::quiet_NaN();
  /// rad, NDT's yaw minus the reference's; NaN: not known, and no yaw noise is measured.
  double yaw_error = std::numeric_limits<double>::quiet_NaN();
};

class NdtQualityMap {
 public:
  /// Empty: no cell, and a default of 0 (nothing floored).
  NdtQualityMap() = default;

  /// Cells of `cell` m; a cell's variance is the mean square of its poses' x and y errors (pooled, a
  /// bias included: a map's error is NDT's error), kept where it holds at least `min_samples` poses.
  /// `default_variance` answers elsewhere; not given, the drive's own mean square over all its poses.
  /// The samples in drive order also give NDT's scan-to-scan noise: half the mean square change of the
  /// error between consecutive poses less than a cell apart (what a bias alike from one scan to the
  /// next leaves), per axis and, where the samples give the heading, along and across the vehicle.
  /// Gross errors (grossErrors) count in none of these. Throws coloc::Error for a cell or default out
  /// of range or a non-finite sample.
  static NdtQualityMap fromErrors(const std::vector<NdtQualitySample>& samples, double cell, std::size_t min_samples,
                                  std::optional<double> default_variance = std::nullopt);

  /// Which samples are gross errors: more than kGrossError times the median error of their cell's
  /// samples (cells of three or more). One scan NDT matched decimetres off is not the place's error:
  /// on site C's noise calibration drive a 34 cm match among ten of 1 cm raised its cell to 7.4 cm,
  /// and the filter then weighed NDT's good poses there at that for 10 m (1.2 cm NDT, 2.4 cm
  /// filter), and two such scans took NDT's scan-to-scan noise from 0.55 to 1.5 cm. A single such
  /// pose is for the travel check to catch as it comes. NDT's scatter about a bias stays well inside:
  /// a Rayleigh error exceeds 5 times its median once in 3e7. Throws as fromErrors.
  static std::vector<bool> grossErrors(const std::vector<NdtQualitySample>& samples, double cell);
  static constexpr double kGrossError = 5.0;

  /// The file `toYaml` writes; throws coloc::Error "FILE:LINE: KEY: WHY" for anything else.
  static NdtQualityMap load(const std::string& path);
  static NdtQualityMap parse(const std::string& yaml_text, const std::string& source_name);
  std::string toYaml() const;

  /// The least x/y variance an NDT pose at `xy` (map frame) is worth: its cell's, else the default.
  double varianceAt(const Eigen::Vector2d& xy) const;

  /// NDT's scan-to-scan noise variance per axis (0: not measured, as in files written before it was).
  /// What an NDT pose is worth where the filter models the bias its poses share.
  double noiseVariance() const { return noise_variance_; }
  /// The same noise along the vehicle and across it (m^2; nullopt where not measured: samples without
  /// a heading, files written before it was). NDT's scan-to-scan noise is far from round: on the twin's
  /// sites A-C 0.7-1.3 cm along the vehicle and 0.1-0.7 cm across it, where the figure per axis is
  /// 0.6-1.0 cm (docs/filter.md, *The odometry's slow errors*).
  std::optional<Eigen::Vector2d> noiseAlongAcross() const { return noise_along_across_; }
  /// That noise as an x/y covariance for a vehicle heading `heading` (rad, map frame); nullopt where
  /// not measured.
  std::optional<Eigen::Matrix2d> noiseAt(double heading) const;
  /// The same at `xy`: its cell's own noise along and across, drawn towards the median cell's by
  /// kNoisePriorPairs (not towards the map's own figure, a mean that a few bad cells decide). NDT's
  /// noise changes with the place as much as its error does: along the vehicle on the twin's noise
  /// calibration drives, the 10 m cells' figures span 40x on site A (7e-6 to 3e-4 m^2 from the tenth
  /// to the ninetieth percentile) and 140x on site D, whose cutting alone makes the map's figure 50x
  /// its median cell's. nullopt where the map has no noise along and across.
  std::optional<Eigen::Matrix2d> noiseAt(const Eigen::Vector2d& xy, double heading) const;
  /// NDT's scan-to-scan yaw noise (rad^2), the map's and at `xy` (its cell's, drawn towards the
  /// median cell's as noiseAt); nullopt where not measured (samples without a yaw error, files written before).
  std::optional<double> yawNoise() const { return noise_yaw_; }
  /// NDT's mean square error at `xy` along the vehicle and across it (its cell's, the bias included),
  /// turned to the map for a vehicle heading `heading`; nullopt where the cell did not measure it (no
  /// cell, or samples without a heading). What NDT was there: where NDT's covariance from its score
  /// claims more (probes half a metre apart that cannot tell a centimetre match from a decimetre one,
  /// site E's open square: 0.03-0.14 m^2 along against innovations of 1e-4), this is the better word.
  std::optional<Eigen::Matrix2d> errorAt(const Eigen::Vector2d& xy, double heading) const;
  /// NDT's mean square yaw error at `xy` (rad^2, its cell's, the heading's bias by place included);
  /// nullopt as errorAt. What NDT's yaw is worth on its own (the smoother, NDT's own topic), where the
  /// filter takes it at its noise: taken at its noise on its own, the smoother held the trajectory to
  /// NDT's heading and with it to NDT's bias (site E's VLP-16 in coverage: 5.1 cm against 1.0).
  std::optional<double> yawErrorAt(const Eigen::Vector2d& xy) const;
  std::optional<double> yawNoiseAt(const Eigen::Vector2d& xy) const;
  /// A cell's noise figures count as this many more consecutive pairs with the median cell's: a 10 m
  /// cell driven at 10 m/s and 10 Hz holds 9 pairs, whose mean square is off by +-47 % (chi-square, 9
  /// degrees of freedom) and whose inverse, which weighs NDT's poses, runs 29 % high on average.
  static constexpr double kNoisePriorPairs = 5.0;

  double cellSize() const { return cell_; }
  double defaultVariance() const { return default_variance_; }
  std::size_t cells() const { return cells_.size(); }
  std::size_t grossErrorsLeftOut() const { return gross_left_out_; }  ///< by fromErrors; 0 for a loaded map

 private:
  struct Cell {
    double variance = 0.0;
    std::size_t samples = 0;
    /// Consecutive pairs ending in the cell and their noise figures (m^2, m^2, rad^2), as the map's.
    std::size_t pairs = 0;
    Eigen::Vector2d error_along_across = Eigen::Vector2d::Zero();  ///< mean square, m^2 (with pairs > 0)
    double error_yaw = 0.0;                                          ///< mean square, rad^2 (with pairs > 0)
    Eigen::Vector2d noise_along_across = Eigen::Vector2d::Zero();
    double noise_yaw = 0.0;
  };
  double cell_ = 10.0;
  double default_variance_ = 0.0;
  double noise_variance_ = 0.0;
  std::optional<Eigen::Vector2d> noise_along_across_;
  std::optional<double> noise_yaw_;
  /// The median cell's noise along, across and in yaw, what a cell's own figures are drawn towards;
  /// the map's figures where no cell measured them.
  Eigen::Vector3d noise_prior_ = Eigen::Vector3d::Zero();
  void setNoisePrior();
  std::size_t gross_left_out_ = 0;
  std::map<std::pair<long long, long long>, Cell> cells_;  ///< by (floor(x / cell), floor(y / cell))
  std::pair<long long, long long> indexOf(const Eigen::Vector2d& xy) const;
  const Cell* cellAt(const Eigen::Vector2d& xy) const;
};

}  // namespace coloc::pipeline
