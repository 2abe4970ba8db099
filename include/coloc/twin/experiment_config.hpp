#pragma once
// What `coloc experiment` runs, with every default in one place: the paper's two sites, its two
// roadside LiDARs, its network grid, ten trials. A YAML file may override any key; unknown keys and bad
// values are errors that name the key and the line.
#include <optional>
#include <string>
#include <vector>

namespace coloc::twin {

/// How the fused RSU fixes' covariance is set: as the paper publishes it (its sigma figure in the
/// variance's place, 0.01486 / 0.00681 m^2), that figure read as a standard deviation (variance =
/// sigma^2), or estimated from the fixes' error on the site's first drive (a calibration pass, as an
/// RSU's `calibrated_variance` in rsu.yaml would be measured).
enum class RsuCovariance { kPublished, kStandardDeviation, kEstimated };
const char* toString(RsuCovariance c);
/// The covariance Table I compares the main one with: the paper's, or the estimate if the main one is the paper's.
RsuCovariance referenceCovariance(RsuCovariance main);

/// Where the NDT covariance the filter uses comes from (`ndt_covariance`).
enum class NdtCovarianceSource {
  kPublished,          ///< Autoware's fixed matrix, as the paper
  kEstimated,          ///< x/y and yaw measured on the noise calibration drive
  kEstimatedPosition,  ///< x/y measured there, yaw Autoware's
  /// ndt.covariance multi_ndt_score floored at kEstimatedPosition's matrix: NDT trusted as measured
  /// where its score holds it, less along a direction where the score is flat.
  kMultiNdtScore,
};

struct ExperimentConfig {
  /// Scenario files, or the names of the built-in scenarios (config/scenarios/). Sites A-C are where
  /// NDT is good (1.5-5.3 cm within coverage); sites D and E where it falls short, the paper's premise:
  /// D by its geometry (a cutting: NDT drifts along the road), E by the map's age (a street rebuilt
  /// since the survey: NDT matches sharply and 10 cm off across the road).
  std::vector<std::string> sites = {"site_a", "site_b", "site_c", "site_d", "site_e"};
  int trials = 10;
  std::vector<std::string> lidars = {"VLP-16", "VLP-32C"};  ///< roadside LiDAR models compared
  /// The network grid (Tables II and III): every delay crossed with every loss, on top of the fix's
  /// own processing time. The first cell must be the ideal network (0, 0).
  std::vector<double> delays = {0.0, 0.010, 0.030};  ///< s
  std::vector<double> losses = {0.0, 0.10, 0.20};    ///< probability
  bool network = true;                               ///< run the grid at all
  /// The grid runs on the first this many trials of each site (16 short replays per drive, ended at
  /// coverage: 0.14 s each). All ten by default: one trial's change at 30 ms / 20 % against its own
  /// ideal network spreads by 5-18 points from trial to trial, and a site's figure over three trials
  /// moved by up to 12 points from one three to the next ten.
  int network_trials = 10;
  /// The odometry's covariance as the filter gets it: `estimated` on the site's noise calibration drive
  /// (the twist's error against ground truth, after the speed scale the pipeline learns), or the
  /// messages' own (the twin's say 0.2 m/s and 0.1 rad/s, Autoware's defaults).
  bool twist_covariance_estimated = false;
  /// NDT's covariance as the filter gets it (NdtCovarianceSource). The fixed ones fail one way or
  /// the other: Autoware's 15 cm (`published`, the paper's) makes the filter less accurate than NDT
  /// wherever NDT is good (1.2-1.8x its error there); trusted as measured (`estimated`,
  /// `estimated_position`), NDT on site B's open stretch, started from the filter's prediction where
  /// the map holds it weakly, confirms that prediction and both drift off together (2 cm -> 0.1-5 m).
  /// `multi_ndt_score`, the default, trusts NDT as measured where its score holds it and not along a
  /// direction where the score is flat (docs/experiment.md, "The filter against its best input").
  NdtCovarianceSource ndt_covariance = NdtCovarianceSource::kMultiNdtScore;
  /// With multi_ndt_score: NDT's error measured by place on the site's noise calibration drive (10 m
  /// cells, pipeline::NdtQualityMap, `ndt.quality_map`) floors each pose where it is, instead of the
  /// drive's one figure for the whole site, which hid NDT's good matches where the rest of the site
  /// is poor (`ndt_quality_map: by_place | site`).
  bool ndt_quality_by_place = true;
  /// How often the noise calibration drive is replayed to measure NDT by place: NDT's match depends
  /// on the guess it starts from (in a weak direction it stays near it), and the guesses on the first
  /// replay are those of a filter without the map. Each further replay takes the map the last one
  /// measured, as the evaluated drives do, and measures it again (`ndt_quality_passes`; 1 = once).
  int ndt_quality_passes = 1;
  /// With NDT's error by place: the bias NDT's poses share as the filter's own state
  /// (fusion.map_match_bias_sd, its spread per place from that map, each pose at NDT's scan-to-scan
  /// noise from the same drive), fading over this much travel; 0 = not modelled, each pose floored at
  /// its place's whole error (`map_match_bias_length`).
  double map_match_bias_length = 10.0;
  /// Estimated by default: with the fixes carried to their tick (fusion.pose_time_alignment) the
  /// filter can trust them as much as they deserve; Table I shows the paper's figures beside it.
  RsuCovariance rsu_covariance = RsuCovariance::kEstimated;
  /// fusion.pose_gate_recovery for every replay (a fuse_config brings its own): a filter that
  /// trusts millimetre fixes must not lock them out when NDT has drifted before the RSU's coverage
  /// (at 15 m/s NDT is 35 cm off there). 0 = off.
  int gate_recovery = 3;
  double bin_length = 2.0;      ///< m of road per bin of the paper's metric (minimum error per bin)
  std::string fuse_config;      ///< optional fuse YAML applied to every replay (fusion, ndt, replay keys)
  int jobs = 2;                 ///< replays run side by side (each NDT on one thread)
  /// Keep each drive's rosbag2 log under recordings/ (a few hundred MB per drive, about 18 GB for the
  /// full run with the sweeps). Off, the drives are replayed from memory and only their CSVs are kept.
  bool recordings = false;
  bool sweeps = false;          ///< also run the sweeps beyond the paper (covariance, RSU height, speed)
  int sweep_trials = 2;
  /// Sweep values besides the paper's (RSU 2 m high, 10 m/s), whose runs are the main experiment's.
  std::vector<double> rsu_heights = {3.0, 4.5};  ///< m
  std::vector<double> speeds = {5.0, 15.0};      ///< m/s
  /// Smooth the main replays (NDT only, and NDT + each LiDAR on the ideal network) with the Ceres
  /// smoother too: Table I's smoother column.
  bool smoother = true;
  /// The calibration table: per site, every RSU miscalibrated by `calibration_error` and
  /// `calibration_clock_offset_ms`; one drive calibrates it (coloc smooth --calibrate-rsus), and the
  /// filter on a second drive runs with the miscalibrated registry, the calibrated one, and a perfect RSU.
  bool calibration = true;
  /// The road's error sources (sim/error_sources.hpp): `real` (each site's own, the published figures
  /// by default: RSU survey and clock, a real car's shape, range-dependent noise, dropouts) or `ideal`.
  bool ideal_twin = false;
  /// An `errors:` section applied to every site on top of its own error sources (the keys of a
  /// scenario's `errors:`, e.g. `{map_position_sd: 0}`), as YAML text; empty: none.
  std::string errors;
  /// Calibrate every RSU (survey and clock, `coloc smooth --calibrate-rsus`) on its site's noise
  /// calibration drive and replay the evaluated drives with the calibrated registry, as a deployment
  /// would after commissioning; the fixes' variance is then measured after the calibration.
  bool calibrate_rsus = true;
  std::vector<double> calibration_error = {0.15, 0.0, 0.5};  ///< [dx m, dy m, dyaw deg], surveyed minus true
  double calibration_clock_offset_ms = 20.0;                 ///< the RSU's clock minus the vehicle's
  /// An analysis bound on every drive (TwinRecordingOptions::oracle_fix_limit): the RSUs withhold each
  /// fix farther than this from the vehicle's true position, which no RSU can know. m; 0: off.
  double oracle_fix_limit = 0.0;
  /// How each RSU gets its background (`rsu_background`): learned from frames of the busy street before
  /// each drive, as an RSU on site does (TwinRecordingOptions::rsu_commissioning_frames), or the surveyed
  /// empty street, which no real RSU has (what the twin did before; for comparison).
  bool rsu_background_learned = true;
  /// With `rsu_covariance: estimated` and the RSUs calibrated (`rsu_fix_error`): `by_range`, the
  /// fixes' variance along the line of sight and the bearing's spread across it, both measured on the
  /// noise calibration drive (the registry's calibrated_variance and calibrated_bearing_sd), or `flat`,
  /// one mean square for every range (the default: by_range is not yet measured over ten trials).
  bool rsu_fix_error_by_range = false;
  /// `by_range_and_mean`: by range, and each band's mean error too, which the vehicle takes off its fixes.
  bool rsu_fix_error_mean = false;
};

/// The quick mode's defaults (`coloc experiment --quick`), a first look at the paper's results:
/// Table I on every site, one trial each (the sweeps and the network grid likewise); the network grid
/// at its corners only, 0 and 30 ms crossed with 0 and 20 % loss (the paper's headline cell: on one
/// trial a change spreads by 5-18 points from trial to trial, so the inner cells would say little); the
/// RSU calibration study left to the full run. A file's keys override them as they override the full
/// run's defaults.
ExperimentConfig quickExperiment();

/// `defaults`: what the file's keys override (the full run's, or quickExperiment()).
ExperimentConfig loadExperimentConfig(const std::string& path, const ExperimentConfig& defaults = {});
ExperimentConfig parseExperimentConfig(const std::string& yaml_text, const std::string& source_name, const ExperimentConfig& defaults = {});

/// The scenario's YAML text: a built-in one by name, else the file.
std::string scenarioText(const std::string& site);

}  // namespace coloc::twin
