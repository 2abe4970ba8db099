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
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace coloc::pipeline {

/// One NDT pose of the reference drive: where NDT put the vehicle (what a pose is looked up by, as
/// the vehicle cannot know the truth) and its error against the reference, x and y.
struct NdtQualitySample {
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  Eigen::Vector2d error = Eigen::Vector2d::Zero();
};

class NdtQualityMap {
 public:
  /// Empty: no cell, and a default of 0 (nothing floored).
  NdtQualityMap() = default;

  /// Cells of `cell` m; a cell's variance is the mean square of its poses' x and y errors (pooled, a
  /// bias included: a map's error is NDT's error), kept where it holds at least `min_samples` poses.
  /// `default_variance` answers elsewhere. The samples in drive order also give NDT's scan-to-scan
  /// noise: half the mean square change of the error between consecutive poses less than a cell
  /// apart (what a bias alike from one scan to the next leaves). Throws coloc::Error for a cell or
  /// default out of range or a non-finite sample.
  static NdtQualityMap fromErrors(const std::vector<NdtQualitySample>& samples, double cell, std::size_t min_samples, double default_variance);

  /// The file `toYaml` writes; throws coloc::Error "FILE:LINE: KEY: WHY" for anything else.
  static NdtQualityMap load(const std::string& path);
  static NdtQualityMap parse(const std::string& yaml_text, const std::string& source_name);
  std::string toYaml() const;

  /// The least x/y variance an NDT pose at `xy` (map frame) is worth: its cell's, else the default.
  double varianceAt(const Eigen::Vector2d& xy) const;

  /// NDT's scan-to-scan noise variance per axis (0: not measured, as in files written before it was).
  /// What an NDT pose is worth where the filter models the bias its poses share.
  double noiseVariance() const { return noise_variance_; }

  double cellSize() const { return cell_; }
  double defaultVariance() const { return default_variance_; }
  std::size_t cells() const { return cells_.size(); }

 private:
  struct Cell {
    double variance = 0.0;
    std::size_t samples = 0;
  };
  double cell_ = 10.0;
  double default_variance_ = 0.0;
  double noise_variance_ = 0.0;
  std::map<std::pair<long long, long long>, Cell> cells_;  ///< by (floor(x / cell), floor(y / cell))
  std::pair<long long, long long> indexOf(const Eigen::Vector2d& xy) const;
};

}  // namespace coloc::pipeline
