#pragma once
// The paper's experiment on the digital twin. Per site and trial one drive is simulated with every
// roadside LiDAR model at the site's RSU, and that one recording is replayed through NDT + EKF once per
// configuration (NDT only; NDT + each LiDAR's fixes; the same under each network cell), with the fused
// pose as NDT's initial guess as on a vehicle. The configurations of a trial share the drive and the
// scans, so their comparison is paired.
#include <Eigen/Core>
#include <array>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "coloc/replay/evaluation.hpp"
#include "coloc/rsu_client/commissioning.hpp"
#include "coloc/smoother/smoother.hpp"
#include "coloc/twin/experiment_config.hpp"
#include "coloc/twin/twin_recording.hpp"

namespace coloc::twin {

/// One replay: which site, trial and configuration, and the error along the road.
struct ExperimentRun {
  std::string site;
  int trial = 0;
  std::string lidar;           ///< empty: NDT only
  double delay = 0.0, loss = 0.0;
  std::string variant;         ///< sweep runs: what was varied ("" in the main experiment)
  // At every fused tick with ground truth:
  std::vector<double> along;   ///< m along the drive
  std::vector<double> to_rsu;  ///< m from the nearest RSU
  std::vector<double> error;   ///< m, planar
  std::uint64_t fixes_applied = 0, fixes_gated = 0, fixes_lost = 0;
  double replay_seconds = 0.0;
  /// NDT's own poses beside the fused pose at their stamps (never worse than the best input?).
  replay::InputComparison ndt;
  /// NDT's normalized innovation squared in the filter: d^2 summed over its poses, and their degrees of
  /// freedom (fusion::SourceCounters::nis_sum, nis_dof; the ratio is 1 when the covariances are honest).
  double ndt_nis_sum = 0.0;
  std::uint64_t ndt_nis_dof = 0;
  /// The same per component, along and across the vehicle and yaw (fusion::kNisAlong, kNisAcross,
  /// kNisYaw): e_i^2 / S_ii summed, and the poses that measured it.
  std::array<double, 3> ndt_nis_component_sum{};
  std::array<std::uint64_t, 3> ndt_nis_component_samples{};
  /// And each component's share of S that is the filter's prediction, (H P H')_ii / S_ii, summed.
  std::array<double, 3> ndt_nis_prediction_share_sum{};

  std::string label() const;  ///< "NDT only", "NDT + VLP-16", "NDT + VLP-16, 30 ms, 20 % loss"
};

/// One RSU's calibration on a site: what was injected and what one drive past it found. The next
/// drive's replays (variants kNextMiscalibrated, kNextCalibrated, kNextPerfect) show what it is worth.
struct CalibrationResult {
  std::string site, lidar;
  std::string rsu;  ///< the site's RSU id (a site may have several RSUs of a model)
  double dx = 0.0, dy = 0.0, dyaw = 0.0, clock_offset = 0.0;  ///< injected: m, m, rad, s
  smoother::RsuCalibration found;
};
/// An RSU commissioned against the reference vehicle on its site's noise calibration drive.
struct Commissioning {
  std::string site, lidar;
  std::string rsu;  ///< the site's RSU id
  double dx = 0.0, dy = 0.0, dyaw = 0.0, clock_offset = 0.0;  ///< drawn: m, m, rad, s
  rsu_client::CommissioningResult found;
  /// The fixes as sent, once calibrated, against their own fit's covariance (d^2 = e' C^-1 e, 2 on
  /// average and above 9, three standard deviations, for 1.1 % of fixes when the covariance is honest).
  std::size_t fixes = 0, beyond_3sd = 0;
  double mean_nes = 0.0;
};
inline constexpr const char* kSmootherVariant = "smoother";
inline constexpr const char* kCalibrationDrive = "calibration drive";
inline constexpr const char* kNoiseCalibrationDrive = "noise calibration drive";
inline constexpr const char* kNextMiscalibrated = "next drive, registry as surveyed";
inline constexpr const char* kNextCalibrated = "next drive, calibrated registry";
inline constexpr const char* kNextPerfect = "next drive, perfect RSU";

struct ExperimentTiming {
  double total = 0.0, survey = 0.0, simulation = 0.0, replay = 0.0;  ///< s; replay summed over the jobs
  double ray_casting = 0.0, lidar = 0.0, perception = 0.0;            ///< s, within simulation (TwinRecordingSummary's)
  std::uint64_t rays = 0, reused_sweeps = 0, replays = 0;           ///< rays cast; sweeps and frames taken from an earlier drive's
  double driven_seconds = 0.0;  ///< s of simulated driving
  /// What a drive's replays shared (ndt::AlignmentMemo, summed over the drives): NDT's matches asked and
  /// computed, and the scans' preprocessings computed (one asked per match computed).
  std::uint64_t matches_asked = 0, matches_computed = 0, preprocessings_computed = 0;
};

struct SiteInfo {
  std::string name;
  double drive_length = 0.0;            ///< m
  double cruise_speed = 0.0;            ///< m/s of the main drives
  std::vector<double> rsu_along;        ///< m along the drive where each RSU is nearest the road
};

struct ExperimentResults {
  ExperimentConfig config;
  std::vector<SiteInfo> sites;
  std::vector<ExperimentRun> runs;
  ExperimentTiming timing;
  /// "SITE LIDAR" ("SITE LIDAR (RSU)" where a site has several RSUs) -> the fixes' variance estimated
  /// on the site's noise calibration drive, m^2.
  std::map<std::string, double> estimated_variance;
  /// Per site: the odometry's variance of speed ((m/s)^2) and yaw rate ((rad/s)^2) on that drive.
  std::map<std::string, Eigen::Vector2d> estimated_twist_variance;
  /// Per site: NDT's mean square error per axis on that drive, x/y (m^2) and yaw (rad^2), when estimated.
  std::map<std::string, Eigen::Vector2d> estimated_ndt_variance;
  /// Per site: the cells of NDT's error by place measured on that drive (ExperimentConfig::ndt_quality_by_place).
  std::map<std::string, std::size_t> ndt_quality_cells;
  std::vector<CalibrationResult> calibrations;
  /// Each RSU's survey and clock error as drawn and as its commissioning on the noise calibration
  /// drive found it (when `calibrate_rsus`).
  std::vector<Commissioning> commissioning;
  /// "SITE LIDAR" -> every RSU frame within coverage of the evaluated trials (attribution, refusals).
  std::map<std::string, std::vector<RsuFrameRecord>> rsu_frames;
  /// The same on each site's noise calibration drive, with the ideal twin's fix beside each.
  std::map<std::string, std::vector<RsuFrameRecord>> ideal_comparison;
  std::string work_dir;  ///< the recordings
  /// What the run could not do as asked and did instead (an RSU too rarely in reach to measure, ...).
  std::vector<std::string> notes;
};

struct ExperimentProgress {
  std::function<void(const std::string& line)> step;  ///< a line per finished stage
  std::function<void(double fraction)> fraction;
};

/// Runs everything `config` asks for; recordings go to out_dir/recordings. Throws coloc::Error for
/// bad scenarios or unwritable folders.
ExperimentResults runExperiment(const ExperimentConfig& config, const std::string& out_dir, const ExperimentProgress& progress);

}  // namespace coloc::twin
