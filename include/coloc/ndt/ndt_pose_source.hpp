#pragma once
// NDT as a pose source for the filter, without ROS: a scan and the filter's prediction for its stamp
// in, a vehicle pose with covariance (or the reason there is none) out.
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "coloc/core/types.hpp"
#include "coloc/ndt/aligner.hpp"
#include "coloc/ndt/preprocess.hpp"
#include "coloc/ndt/tile_map.hpp"

namespace coloc::ndt {

struct NdtPoseSourceConfig {
  NdtConfig ndt;
  PreprocessConfig preprocess;
  MapUpdateConfig map;
  /// The LiDAR's pose on the vehicle (base frame): x, y, z [m], roll, pitch, yaw [rad].
  Vector6d lidar_pose = Vector6d::Zero();
};

/// Range checks of every setting, as the filter checks its own: throws coloc::Error naming the
/// config key ("ndt.resolution: must be a finite number > 0"). NdtPoseSource's constructor calls it.
void validate(const NdtPoseSourceConfig& config);

struct NdtPoseSourceCounters {
  std::uint64_t scans = 0;
  std::uint64_t shared = 0;           ///< outcomes taken from an AlignmentMemo, not computed here
  std::uint64_t poses = 0;            ///< accepted results handed on
  std::uint64_t no_map = 0;           ///< no tile near the predicted position
  std::uint64_t bad_prediction = 0;   ///< a prediction that is no pose (not finite, or a quaternion of no length)
  std::uint64_t empty_scan = 0;       ///< nothing left after preprocessing
  std::uint64_t max_iterations = 0;
  std::uint64_t oscillation = 0;
  std::uint64_t low_score = 0;
  std::uint64_t searches = 0;  ///< scans matched from many starting poses (searchHeading, searchAround); a heading search's scan counts among `scans` too
  double align_ms_total = 0.0;
};

/// How searchHeading tries headings.
struct HeadingSearch {
  int candidates = 16;            ///< evenly spread around the circle
  std::optional<double> near;     ///< rad; only candidates within `within` of it (the direction of travel)
  double within = M_PI / 2;       ///< rad
  double vx = 0.0;                ///< m/s, for deskewing
};

struct ScanOutcome {
  bool produced = false;
  PoseMeasurement pose;  ///< the vehicle (base frame) in the map, stamped with the scan's stamp
  AlignResult alignment;
  std::size_t points_used = 0;
  std::string detail;    ///< why nothing was produced
};

/// Where an accepted match of a search puts the vehicle (map x, y) and how well it matched.
struct Landing {
  Eigen::Vector2d position;
  double nvtl;
};

class AlignmentMemo;

class NdtPoseSource {
 public:
  /// `targets`: a cache of NDT targets shared with other sources on the same map (see target_cache.hpp);
  /// `alignments`: outcomes shared with other sources asked the same (alignment_memo.hpp).
  NdtPoseSource(TileMap map, const NdtPoseSourceConfig& config, std::shared_ptr<TargetCache> targets = nullptr,
                std::shared_ptr<AlignmentMemo> alignments = nullptr);
  ~NdtPoseSource();

  /// `scan` in the LiDAR frame, `predicted` the vehicle pose the filter predicts for `stamp`, `vx` and
  /// `wz` its twist (for deskewing). NDT starts from `predicted` taken to 5 mm and 0.25 mrad, and
  /// deskews with the twist taken to 1 mm/s and 1e-5 rad/s (docs/ndt.md: below NDT's own stop, so
  /// that callers agreeing that closely share a match). Never throws for bad scans or a prediction
  /// that is no pose: the outcome says what happened.
  ScanOutcome process(const PointCloud& scan, Stamp stamp, const Pose& predicted, double vx, double wz);
  /// The same for a scan shared with other sources (replays of one log): with an AlignmentMemo, asked of it.
  ScanOutcome process(const std::shared_ptr<const PointCloud>& scan, Stamp stamp, const Pose& predicted, double vx, double wz);

  /// A vehicle at `position` (map x, y; the height is the map's ground there) with an unknown heading:
  /// the scan matched from every candidate heading, the accepted match with the best NVTL kept (one
  /// scan in the counters). Never throws for bad scans: the outcome says what happened.
  ScanOutcome searchHeading(const PointCloud& scan, Stamp stamp, const Eigen::Vector2d& position, const HeadingSearch& search);
  /// Whether the map matches better away from a pose given by hand: the scan matched from the pose and
  /// from offsets on rings of `radii` (m) in `directions` directions, the best accepted match by NVTL
  /// returned (a search, not a scan, in the counters: the scan is matched as usual too); `at_pose`
  /// gets the match from the pose itself; `landings`, when given, where each accepted match from the
  /// rings puts the vehicle and its NVTL (for a caller that weighs every place, not only the best).
  ScanOutcome searchAround(const PointCloud& scan, Stamp stamp, const Pose& around, const std::vector<double>& radii, int directions, double vx,
                           ScanOutcome& at_pose, std::vector<Landing>* landings = nullptr);

  const NdtPoseSourceCounters& counters() const { return counters_; }
  const DynamicMap& map() const { return map_; }

 private:
  /// `shared`: the scan as shared, to ask alignments_ about; null: computed here.
  ScanOutcome process(const PointCloud& scan, const std::shared_ptr<const PointCloud>* shared, Stamp stamp, const Pose& predicted, double vx, double wz);
  /// The preprocessed `cloud` matched from the prediction.
  ScanOutcome match(const PointCloud& cloud, Stamp stamp, const Pose& predicted, const NdtTarget& target) const;
  void count(const ScanOutcome& out);
  /// The scan preprocessed once and matched from each base pose (the first also reported in `first`),
  /// the best accepted match by NVTL kept; the map is moved to `near`. `as_scan`: counted as one of
  /// this source's scans (a heading search's), else as a search only (the scan is matched as usual too).
  /// `landings`: each accepted match but the first's, where it puts the vehicle and its NVTL.
  ScanOutcome matchFromEach(const PointCloud& scan, Stamp stamp, const Eigen::Vector2d& near, double vx, const std::vector<Eigen::Matrix4d>& bases,
                            ScanOutcome* first, bool as_scan, std::vector<Landing>* landings = nullptr);
  /// The vehicle's pose from an accepted alignment of the LiDAR: map_T_base = map_T_lidar * lidar_T_base.
  void producePose(ScanOutcome& out, Stamp stamp) const;

  NdtPoseSourceConfig config_;
  DynamicMap map_;
  std::shared_ptr<AlignmentMemo> alignments_;
  std::string fingerprint_;  ///< of config_, for alignments_
  std::string preprocess_fingerprint_;  ///< of config_.preprocess, for alignments_
  Eigen::Matrix4d base_to_lidar_;
  NdtPoseSourceCounters counters_;
};

}  // namespace coloc::ndt
