#pragma once
// The roadside units a vehicle trusts: where each stands in the map, which LiDAR it carries, how far
// it sees, and the identity its DDS certificate carries. Loaded from config/rsu.yaml.
#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace coloc::rsu_client {

/// The longest frame name the registry and a fix may carry: ROS frame names are short; a longer one is
/// malformed or hostile.
inline constexpr std::size_t kMaxFrameIdBytes = 256;

/// A roadside LiDAR model with the paper's figures.
struct LidarModel {
  std::string name;
  double sigma;  ///< the paper's per-LiDAR figure for x and y
  double range;  ///< m, effective range for vehicle detection
  /// deg between the LiDAR's columns: a Velodyne's 0.2 at 10 Hz, a 1024-column LiDAR's 0.35. The
  /// roadside perception bounds a face's ends and each fix's doubt by it.
  double azimuth_step_deg = 0.2;
};

/// The models coloc knows: VLP-16 (0.01486, 30 m) and VLP-32C (0.00681, 50 m), the paper's; OS1-64
/// (0.00681, 60 m, 1024 columns), a pole's 64-beam LiDAR without a published figure.
const std::vector<LidarModel>& lidarModels();
const LidarModel* findLidarModel(const std::string& name);

/// How the model's sigma becomes a covariance. The paper writes sigma values into Autoware's
/// covariance matrix where Autoware's NDT puts 0.0225, a variance: `published` keeps that placement
/// (variance = sigma, the figure read in m^2); `standard_deviation` reads it as metres (variance = sigma^2).
enum class CovariancePlacement { kPublished, kStandardDeviation };

/// An RSU's calibration found by driving past it (`coloc smooth --calibrate-rsus`): its surveyed pose
/// minus its true pose (dx, dy, and dyaw about its surveyed position) and its clock minus the
/// vehicle's. Its fixes are corrected by it before anything else looks at them.
struct RsuCalibrationEntry {
  double dx = 0.0, dy = 0.0;  ///< m
  double dyaw = 0.0;          ///< rad (dyaw_deg in the file)
  double clock_offset = 0.0;  ///< s (clock_offset_ms in the file)
};

struct RsuInfo {
  std::string id;
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  ///< map frame, m
  double height = 2.0;                                  ///< m, LiDAR above the road
  /// The LiDAR's mounting (yaw_deg, roll_deg, pitch_deg in the file): its x axis's heading in the map,
  /// and its tilt (roll about its x axis, then pitch about its y axis, before the yaw). What the RSU's
  /// own node needs to put its frames in the map; a vehicle does not use them.
  double yaw = 0.0, roll = 0.0, pitch = 0.0;  ///< rad
  LidarModel lidar;
  double coverage_radius = 0.0;  ///< m; fixes farther than this from the RSU are refused
  std::string identity;          ///< subject of its DDS Security certificate, e.g. "CN=rsu_a"
  /// x/y variance measured for this RSU (m^2), e.g. by driving a surveyed vehicle past it; when set,
  /// its fixes carry it instead of the model's figure, whatever the placement.
  std::optional<double> calibrated_variance;
  /// With calibrated_variance: the fixes' error by their range from the RSU (calibrated_error_by_range
  /// in the file), each row a range (m), the standard deviations (m) along and across the line of
  /// sight measured there and, optionally, the mean error (m) forward and to the left of the vehicle,
  /// which the vehicle takes off each fix by its heading; a fix between two rows takes the figures
  /// interpolated in range, one beyond the first or last row that row's. The mean is in the vehicle's
  /// frame because a far car's fit is pulled towards the side it shows the RSU: across the line of
  /// sight that pull has one sign as the car comes and the other as it goes. A LiDAR measures range to a centimetre at any distance, but
  /// its beams thin out and its fit sees other faces as the car passes: what it gets wrong depends on
  /// the range and the direction, and one figure for all overstates the near fixes and understates the
  /// far ones (docs/rsu-protocol.md).
  struct ErrorAtRange {
    double range = 0.0, along_sd = 0.0, across_sd = 0.0;
    double forward_mean = 0.0, left_mean = 0.0;  ///< the mean error (fix minus truth) in the vehicle's frame
  };
  std::vector<ErrorAtRange> calibrated_error_by_range;
  std::optional<RsuCalibrationEntry> calibration;
};

class RsuRegistry {
 public:
  RsuRegistry() = default;
  /// From entries made in code, checked as a file's would be (throws coloc::Error naming the entry).
  RsuRegistry(const std::vector<RsuInfo>& rsus, CovariancePlacement placement, const std::string& map_frame = "map");
  /// The registry as a file that `load` reads back to the same registry.
  /// Throws coloc::Error naming the file, line and key for unknown keys, unknown LiDAR models,
  /// duplicate ids and values out of range.
  std::string toYaml() const;
  static RsuRegistry load(const std::string& path);
  static RsuRegistry parse(const std::string& yaml_text, const std::string& source_name);

  const RsuInfo* find(const std::string& id) const;
  const std::vector<RsuInfo>& rsus() const { return rsus_; }
  CovariancePlacement placement() const { return placement_; }
  /// The frame fixes are expressed in (`map_frame`, default "map"): a fix naming another is refused.
  const std::string& mapFrame() const { return map_frame_; }
  /// The x/y variance a fix from this RSU carries: its calibrated variance, else the model's figure
  /// placed as the registry says.
  double variance(const RsuInfo& rsu) const;
  /// The x/y covariance a fix from this RSU at `fix` (map frame) carries: variance(rsu) on each axis,
  /// or, where the calibration has it by range, its error at this fix's range along and across the
  /// line of sight from the RSU.
  Eigen::Matrix2d covarianceAt(const RsuInfo& rsu, const Eigen::Vector2d& fix) const;
  /// The mean error (fix minus truth, map frame) the calibration by range measured at `fix`'s range
  /// for a vehicle heading `yaw` (rad, map frame); zero without one.
  Eigen::Vector2d meanErrorAt(const RsuInfo& rsu, const Eigen::Vector2d& fix, double yaw) const;
  /// The model's figure alone, placed as the registry says: the least an RSU of this LiDAR may send.
  double lidarVariance(const RsuInfo& rsu) const;

 private:
  std::vector<RsuInfo> rsus_;
  CovariancePlacement placement_ = CovariancePlacement::kPublished;
  std::string map_frame_ = "map";
};

}  // namespace coloc::rsu_client
