#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "builtin_scenarios.hpp"
#include "coloc/core/error.hpp"
#include "coloc/pipeline/config.hpp"
#include "coloc/sim/scene.hpp"
#include "coloc/twin/experiment.hpp"
#include "coloc/twin/experiment_config.hpp"
#include "coloc/twin/experiment_report.hpp"

namespace coloc::twin {
namespace {

std::string errorOf(const std::string& yaml) {
  try {
    parseExperimentConfig(yaml, "exp.yaml");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(ExperimentConfig, DefaultsAreThePapersExperiment) {
  const ExperimentConfig c = parseExperimentConfig("", "exp.yaml");
  EXPECT_EQ(c.sites, (std::vector<std::string>{"site_a", "site_b", "site_c", "site_d", "site_e"}));
  EXPECT_EQ(c.trials, 10);
  EXPECT_EQ(c.lidars, (std::vector<std::string>{"VLP-16", "VLP-32C"}));
  EXPECT_EQ(c.delays, (std::vector<double>{0.0, 0.010, 0.030}));
  EXPECT_EQ(c.losses, (std::vector<double>{0.0, 0.10, 0.20}));
  EXPECT_DOUBLE_EQ(c.bin_length, 2.0);
  EXPECT_EQ(c.rsu_covariance, RsuCovariance::kEstimated);
  EXPECT_EQ(referenceCovariance(c.rsu_covariance), RsuCovariance::kPublished);
  EXPECT_EQ(c.gate_recovery, 3);
  EXPECT_EQ(c.ndt_covariance, NdtCovarianceSource::kMultiNdtScore);
  EXPECT_FALSE(c.twist_covariance_estimated);
  EXPECT_TRUE(c.errors.empty());
  EXPECT_FALSE(c.recordings);  // the drives are replayed from memory unless asked
  EXPECT_EQ(c.oracle_fix_limit, 0.0);  // the analysis bound is off
  EXPECT_TRUE(c.rsu_background_learned);  // as an RSU on site learns it, from the busy street
  EXPECT_FALSE(c.rsu_fix_error_by_range);  // one mean square for every range, until measured over ten trials
  EXPECT_EQ(c.network_trials, 10);  // the grid on every trial: one trial's change spreads by 5-18 points
}

TEST(ExperimentConfig, TheQuickRunIsAFirstLookWhoseDefaultsAFilesKeysOverride) {
  const ExperimentConfig full, quick = quickExperiment();
  EXPECT_EQ(quick.trials, 1);
  EXPECT_EQ(quick.sweep_trials, 1);
  EXPECT_EQ(quick.network_trials, 1);
  EXPECT_EQ(quick.delays, (std::vector<double>{0.0, 0.030}));  // the grid's corners: the paper's headline cell
  EXPECT_EQ(quick.losses, (std::vector<double>{0.0, 0.20}));
  EXPECT_FALSE(quick.calibration);  // the RSU calibration study is the full run's
  EXPECT_EQ(quick.sites, full.sites);  // Table I on every site, as the full run
  EXPECT_EQ(quick.lidars, full.lidars);
  EXPECT_EQ(quick.smoother, full.smoother);
  // A file's keys override the quick run's defaults, and only those keys.
  const ExperimentConfig c = parseExperimentConfig("calibration: true\ntrials: 2\n", "exp.yaml", quick);
  EXPECT_TRUE(c.calibration);
  EXPECT_EQ(c.trials, 2);
  EXPECT_EQ(c.delays, quick.delays);
  EXPECT_EQ(c.network_trials, 1);
  EXPECT_EQ(parseExperimentConfig("", "exp.yaml", quick).delays, quick.delays);  // an empty file changes nothing
  // Without them given, a file overrides the full run's.
  EXPECT_TRUE(parseExperimentConfig("trials: 2\n", "exp.yaml").calibration);
  EXPECT_EQ(parseExperimentConfig("trials: 2\n", "exp.yaml").delays, full.delays);
}

TEST(ExperimentConfig, BadKeysAndValuesNameTheKeyAndLine) {
  EXPECT_EQ(errorOf("trials: 3\ntrails: 4\n").rfind("exp.yaml:2: trails: unknown key", 0), 0u) << errorOf("trails: 4");
  EXPECT_NE(errorOf("trials: 0\n").find("exp.yaml:1: trials: must be in [1, 1000]"), std::string::npos);
  EXPECT_NE(errorOf("lidars: [VLP-64]\n").find("unknown LiDAR model 'VLP-64'"), std::string::npos);
  EXPECT_NE(errorOf("losses: [0.0, .nan]\n").find("losses: must not be NaN"), std::string::npos);
  EXPECT_NE(errorOf("delays: [0.01, 0.03]\n").find("the ideal network is the reference"), std::string::npos);
  EXPECT_NE(errorOf("- a list\n").find("expected a mapping"), std::string::npos);
  EXPECT_NE(errorOf("rsu_covariance: guessed\n").find("exp.yaml:1: rsu_covariance: expected one of published, standard_deviation, estimated"),
            std::string::npos);
  EXPECT_EQ(parseExperimentConfig("rsu_covariance: estimated\n", "exp.yaml").rsu_covariance, RsuCovariance::kEstimated);
  EXPECT_TRUE(parseExperimentConfig("error_sources: ideal\n", "exp.yaml").ideal_twin);
  EXPECT_FALSE(parseExperimentConfig("rsu_calibration: none\n", "exp.yaml").calibrate_rsus);
  EXPECT_NE(errorOf("error_sources: perfect\n").find("error_sources: expected one of real, ideal"), std::string::npos);
  EXPECT_EQ(parseExperimentConfig("ndt_covariance: estimated\n", "exp.yaml").ndt_covariance, NdtCovarianceSource::kEstimated);
  EXPECT_EQ(parseExperimentConfig("ndt_covariance: estimated_position\n", "exp.yaml").ndt_covariance, NdtCovarianceSource::kEstimatedPosition);
  EXPECT_EQ(parseExperimentConfig("ndt_covariance: multi_ndt_score\n", "exp.yaml").ndt_covariance, NdtCovarianceSource::kMultiNdtScore);
  EXPECT_NE(parseExperimentConfig("errors: {map_position_sd: 0}\n", "exp.yaml").errors.find("map_position_sd"), std::string::npos);
  EXPECT_NE(errorOf("trials: 2\nerrors: {map_position_sd: 9}\n").find("exp.yaml:2: errors.map_position_sd"), std::string::npos)
      << errorOf("trials: 2\nerrors: {map_position_sd: 9}\n");
  EXPECT_NE(errorOf("errors: {smog: 1}\n").find("errors.smog: unknown key"), std::string::npos);
  EXPECT_NE(errorOf("ndt_covariance: laplace\n").find("ndt_covariance: expected one of estimated, estimated_position, multi_ndt_score, published"), std::string::npos);
  EXPECT_NE(errorOf("rsu_calibration: yes\n").find("rsu_calibration: expected one of noise_drive, none"), std::string::npos);
  EXPECT_TRUE(parseExperimentConfig("recordings: true\n", "exp.yaml").recordings);
  EXPECT_NE(errorOf("recordings: often\n").find("exp.yaml:1: recordings"), std::string::npos) << errorOf("recordings: often\n");
  EXPECT_DOUBLE_EQ(parseExperimentConfig("oracle_fix_limit: 0.02\n", "exp.yaml").oracle_fix_limit, 0.02);
  EXPECT_FALSE(parseExperimentConfig("rsu_background: surveyed\n", "exp.yaml").rsu_background_learned);
  EXPECT_TRUE(parseExperimentConfig("rsu_fix_error: by_range\n", "exp.yaml").rsu_fix_error_by_range);
  EXPECT_FALSE(parseExperimentConfig("rsu_fix_error: by_range\n", "exp.yaml").rsu_fix_error_mean);
  EXPECT_TRUE(parseExperimentConfig("rsu_fix_error: by_range_and_mean\n", "exp.yaml").rsu_fix_error_mean);
  EXPECT_NE(errorOf("rsu_fix_error: linear\n").find("exp.yaml:1: rsu_fix_error: expected one of by_range, by_range_and_mean, flat"), std::string::npos)
      << errorOf("rsu_fix_error: linear\n");
  EXPECT_NE(errorOf("rsu_background: empty\n").find("exp.yaml:1: rsu_background: expected one of learned, surveyed"), std::string::npos)
      << errorOf("rsu_background: empty\n");
  EXPECT_NE(errorOf("oracle_fix_limit: -0.02\n").find("exp.yaml:1: oracle_fix_limit: must be in [0, 100]"), std::string::npos)
      << errorOf("oracle_fix_limit: -0.02\n");
  EXPECT_TRUE(parseExperimentConfig("", "exp.yaml").ndt_quality_by_place);
  EXPECT_FALSE(parseExperimentConfig("ndt_quality_map: site\n", "exp.yaml").ndt_quality_by_place);
  EXPECT_NE(errorOf("ndt_quality_map: yes\n").find("exp.yaml:1: ndt_quality_map: expected one of by_place, site"), std::string::npos)
      << errorOf("ndt_quality_map: yes\n");
  EXPECT_DOUBLE_EQ(parseExperimentConfig("", "exp.yaml").map_match_bias_length, 10.0);
  EXPECT_DOUBLE_EQ(parseExperimentConfig("map_match_bias_length: 0\n", "exp.yaml").map_match_bias_length, 0.0);
  EXPECT_NE(errorOf("map_match_bias_length: -5\n").find("exp.yaml:1: map_match_bias_length: must be in [0, 10000]"), std::string::npos)
      << errorOf("map_match_bias_length: -5\n");
  EXPECT_NE(errorOf("map_match_bias_length: .nan\n").find("map_match_bias_length"), std::string::npos);
  EXPECT_EQ(parseExperimentConfig("", "exp.yaml").ndt_quality_passes, 1) << "the noise calibration drive replayed once";
  EXPECT_EQ(parseExperimentConfig("ndt_quality_passes: 3\n", "exp.yaml").ndt_quality_passes, 3);
  EXPECT_NE(errorOf("ndt_quality_passes: 0\n").find("exp.yaml:1: ndt_quality_passes: must be in [1, 10]"), std::string::npos)
      << errorOf("ndt_quality_passes: 0\n");
  EXPECT_NE(errorOf("ndt_quality_passes: 1.5\n").find("exp.yaml:1: ndt_quality_passes"), std::string::npos) << errorOf("ndt_quality_passes: 1.5\n");
}

TEST(ExperimentConfig, ShippedPaperConfigurationLoadsWithItsFuseFileFoundBesideIt) {
  const ExperimentConfig c = loadExperimentConfig(COLOC_SOURCE_DIR "/config/experiments/paper_configuration.yaml");
  EXPECT_EQ(c.rsu_covariance, RsuCovariance::kPublished);
  EXPECT_EQ(c.ndt_covariance, NdtCovarianceSource::kPublished);
  EXPECT_FALSE(c.twist_covariance_estimated);
  const pipeline::Config fuse = pipeline::loadConfig(c.fuse_config);
  EXPECT_FALSE(fuse.fusion.pose_time_alignment);  // Autoware's nearest tick
  EXPECT_EQ(fuse.fusion.pose_gate_recovery, 0);
}

TEST(ExperimentConfig, ShippedNdtAtItsNoiseConfigurationLoadsWithItsFuseFileFoundBesideIt) {
  const ExperimentConfig c = loadExperimentConfig(COLOC_SOURCE_DIR "/config/experiments/ndt_at_its_noise.yaml");
  EXPECT_TRUE(c.twist_covariance_estimated);
  EXPECT_EQ(c.ndt_quality_passes, 2) << "NDT measured again under the filter that takes its map";
  EXPECT_TRUE(c.rsu_fix_error_by_range) << "the fixes at their error by range, as the noise calibration drive measures it";
  EXPECT_TRUE(c.rsu_fix_error_mean) << "and its mean taken off";
  EXPECT_EQ(c.ndt_covariance, NdtCovarianceSource::kMultiNdtScore) << "the experiment's own, which hands each replay its quality map";
  const pipeline::Config fuse = pipeline::loadConfig(c.fuse_config);
  EXPECT_EQ(fuse.ndt.quality_floor, "noise");
  EXPECT_DOUBLE_EQ(fuse.fusion.yaw_bias_walk, 0.002);
  EXPECT_DOUBLE_EQ(fuse.fusion.proc_stddev_yaw_c, 0.0) << "the twin's heading is its yaw rate's integral";
  EXPECT_TRUE(fuse.fusion.yaw_rate_sampling_noise);
  EXPECT_TRUE(fuse.pipeline.speed_scale_uncertainty);
  EXPECT_DOUBLE_EQ(fuse.pipeline.travel_check_turn_tolerance, 0.002);
  EXPECT_EQ(fuse.fusion.pose_gate_recovery, 3) << "the experiment's base, which a fuse file replaces whole";
  EXPECT_DOUBLE_EQ(fuse.pipeline.fix_agreement_window, 0.0);
  EXPECT_EQ(fuse.ndt.source.ndt.covariance, ndt::CovarianceMode::kFixed);
}

TEST(ExperimentConfig, BuiltInScenariosAreTheShippedFiles) {
  for (const char* name : {"site_a", "site_b", "site_c", "site_d", "site_e"}) {
    std::ifstream in(std::string(COLOC_SOURCE_DIR) + "/config/scenarios/" + name + ".yaml");
    std::ostringstream text;
    text << in.rdbuf();
    ASSERT_NE(builtinScenario(name), nullptr) << name;
    EXPECT_EQ(text.str(), builtinScenario(name));
    EXPECT_EQ(sim::parseScenario(scenarioText(name), name).name, name);
  }
  EXPECT_EQ(builtinScenario("site_z"), nullptr);
  EXPECT_THROW(scenarioText("site_z"), Error);
}

// A run along 10 m of road, 4 samples per metre; the error is 0.1 m except one 0.5 m sample per 2 m bin.
ExperimentRun syntheticRun() {
  ExperimentRun r;
  for (int i = 0; i < 40; ++i) {
    r.along.push_back(i * 0.25);
    r.to_rsu.push_back(std::abs(i * 0.25 - 5.0));  // the RSU stands at 5 m
    r.error.push_back(i % 8 == 3 ? 0.5 : 0.1 + 0.01 * (i / 8));
  }
  return r;
}

TEST(ErrorInCoverage, PaperMetricIsTheMeanOfEachBinsMinimumAndIgnoresTheRestOfTheRoad) {
  const ExperimentRun r = syntheticRun();
  // Everything in range: bins of 2 m hold samples 0-7, 8-15, ...; minima 0.10, 0.11, 0.12, 0.13, 0.14.
  const ErrorInCoverage all = errorInCoverage(r, 100.0, 2.0);
  EXPECT_NEAR(all.paper, 0.12, 1e-12);
  EXPECT_EQ(all.samples, 40u);
  double plain = 0.0;
  for (double e : r.error) plain += e;
  EXPECT_NEAR(all.plain, plain / 40, 1e-12);
  EXPECT_GT(all.plain, all.paper);  // the outliers count in the plain mean only
  // Within 1 m of the RSU (4 to 6 m along): bins [4, 6) with minimum 0.12, [6, 8) holds only the 6 m sample (0.13).
  const ErrorInCoverage near = errorInCoverage(r, 1.0, 2.0);
  EXPECT_EQ(near.samples, 9u);
  EXPECT_NEAR(near.paper, 0.5 * (0.12 + 0.13), 1e-12);
  EXPECT_EQ(errorInCoverage(r, -1.0, 2.0).samples, 0u);
}


// A run with one error everywhere, all within coverage: both metrics are that error.
ExperimentRun flatRun(const std::string& site, int trial, const std::string& lidar, double delay, double loss, double error) {
  ExperimentRun r;
  r.site = site, r.trial = trial, r.lidar = lidar, r.delay = delay, r.loss = loss;
  for (int i = 0; i < 20; ++i) r.along.push_back(i * 1.0), r.to_rsu.push_back(1.0), r.error.push_back(error);
  return r;
}

std::string fileText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The network figure on the sites where NDT falls short is the ratio of their means, with the
// standard error of their drives' own changes: one site where NDT is good (2 cm) and two where it falls
// short (10 and 8 cm); at 30 ms and 20 % loss the fused error grows by 10, 20 and 30 % on one's three
// drives and 20 % on each of the other's.
TEST(ExperimentReport, TheNetworkChangeIsPooledOverTheSitesWhereNdtFallsShortWithItsStandardError) {
  ExperimentResults results;
  ExperimentConfig& c = results.config;
  c.sites = {"site_x", "site_y", "site_z"};
  c.trials = c.network_trials = 3;
  c.lidars = {"VLP-16"};
  c.delays = {0.0, 0.03};
  c.losses = {0.0, 0.2};
  c.network = true;
  c.smoother = c.calibration = c.sweeps = false;
  const std::map<std::string, std::pair<double, double>> site_errors = {{"site_x", {0.02, 0.01}}, {"site_y", {0.10, 0.02}}, {"site_z", {0.08, 0.01}}};
  const std::map<std::string, std::array<double, 3>> growth = {{"site_x", {1.1, 1.1, 1.1}}, {"site_y", {1.1, 1.2, 1.3}}, {"site_z", {1.2, 1.2, 1.2}}};
  for (const auto& [site, errors] : site_errors) {
    SiteInfo info;
    info.name = site;
    info.drive_length = 20.0;
    info.cruise_speed = 10.0;
    results.sites.push_back(info);
    for (int t = 0; t < 3; ++t) {
      results.runs.push_back(flatRun(site, t, "", 0.0, 0.0, errors.first));
      for (double delay : c.delays)
        for (double loss : c.losses)
          results.runs.push_back(flatRun(site, t, "VLP-16", delay, loss, errors.second * (delay > 0.0 && loss > 0.0 ? growth.at(site)[t] : 1.0)));
    }
  }
  const std::string dir = ::testing::TempDir() + "/coloc_network_report";
  std::filesystem::create_directories(dir);
  writeExperimentReport(results, dir, "coloc experiment");
  std::map<std::string, double> change;  // scope -> the change at 30 ms and 20 % loss, paper's metric
  std::istringstream csv(fileText(dir + "/network.csv"));
  for (std::string line; std::getline(csv, line);) {
    std::vector<std::string> field;  // site, lidar, delay_s, loss, error_paper_m, error_mean_m, change_pct, ...
    std::istringstream fields(line);
    for (std::string f; std::getline(fields, f, ',');) field.push_back(f);
    if (field.size() == 9 && field[1] == "VLP-16" && field[2] == "0.03" && field[3] == "0.2") change[field[0]] = std::stod(field[6]);
  }
  // y and z: (3 x 0.02 x 1.2 + 3 x 0.01 x 1.2) / (3 x 0.02 + 3 x 0.01) = 1.2; all three: 0.141 / 0.12.
  ASSERT_EQ(change.count("ndt_falls_short"), 1u) << fileText(dir + "/network.csv");
  EXPECT_NEAR(change["ndt_falls_short"], 20.0, 1e-9);
  EXPECT_NEAR(change["all"], 100.0 * (0.141 / 0.12 - 1.0), 1e-9);
  EXPECT_NEAR(change["site_x"], 10.0, 1e-9);
  // The drives' changes 10, 20, 30, 20, 20, 20 %: sd sqrt(40 / 5), over sqrt(6): 2.6 points.
  const std::string report = fileText(dir + "/README.md");
  EXPECT_NE(report.find("| where NDT falls short (site_y, site_z) | VLP-16 | 1.80 cm | +20.0 % (± 2.6) |"), std::string::npos) << report;
  // With every site where NDT falls short, the pooled row would be "all sites" again: there is none.
  results.sites.erase(results.sites.begin());
  writeExperimentReport(results, dir, "coloc experiment");
  EXPECT_EQ(fileText(dir + "/network.csv").find("ndt_falls_short"), std::string::npos);
  std::filesystem::remove_all(dir);
}

// The filter beside NDT where NDT is accurate: the pooled ratio (weighted by scans) with the standard
// error of its replays' own ratios, so that a ratio near 1 is read against what the drives can tell.
// Three trials of one site, NDT alone: settled / NDT there 0.9, 1.0 and 1.1 on 10, 20 and 10 scans.
TEST(ExperimentReport, TheFilterBesideNdtWhereNdtIsAccurateCarriesItsReplaysStandardError) {
  ExperimentResults results;
  ExperimentConfig& c = results.config;
  c.sites = {"site_x"};
  c.trials = 3;
  c.lidars = {"VLP-16"};
  c.network = c.smoother = c.calibration = c.sweeps = false;
  SiteInfo info;
  info.name = "site_x";
  info.drive_length = 20.0;
  info.cruise_speed = 10.0;
  results.sites.push_back(info);
  const double ratios[3] = {0.9, 1.0, 1.1};
  const std::size_t scans[3] = {10, 20, 10};
  for (int t = 0; t < 3; ++t) {
    ExperimentRun r = flatRun("site_x", t, "", 0.0, 0.0, 0.02);
    replay::InputComparison& k = r.ndt;
    k.samples = 100, k.input_mean = 0.03, k.fused_mean = k.settled_mean = 0.03;
    k.stretch_length = 10.0, k.accurate_below = 0.02;
    k.accurate_samples = scans[t], k.accurate_input_mean = 0.01, k.accurate_fused_mean = k.accurate_settled_mean = 0.01 * ratios[t];
    if (t == 0) k.place_samples = 5, k.place_input_mean = 0.01, k.place_fused_mean = k.place_settled_mean = 0.012;  // one replay only
    results.runs.push_back(r);
  }
  const std::string dir = ::testing::TempDir() + "/coloc_ndt_vs_fused_report";
  std::filesystem::create_directories(dir);
  writeExperimentReport(results, dir, "coloc experiment");
  std::istringstream csv(fileText(dir + "/ndt_vs_fused.csv"));
  std::string header, line;
  std::getline(csv, header);
  EXPECT_EQ(header.substr(header.rfind(",place_settled_mean_m")), ",place_settled_mean_m,accurate_replays,accurate_ratio_se,place_replays,place_ratio_se");
  std::vector<std::string> field;
  while (std::getline(csv, line))
    if (line.find(",site_x,") != std::string::npos) {
      std::istringstream fields(line);
      for (std::string f; std::getline(fields, f, ',');) field.push_back(f);
      if (line.back() == ',') field.push_back("");
    }
  ASSERT_EQ(field.size(), 19u) << fileText(dir + "/ndt_vs_fused.csv");
  // Pooled by scans: (10 x 0.9 + 20 x 1.0 + 10 x 1.1) / 40 = 1.0; the replays' ratios: sd 0.1, over sqrt(3).
  EXPECT_NEAR(std::stod(field[10]) / std::stod(field[8]), 1.0, 1e-9);
  EXPECT_EQ(field[15], "3");
  EXPECT_NEAR(std::stod(field[16]), 0.1 / std::sqrt(3.0), 1e-6);
  EXPECT_EQ(field[17], "1");
  EXPECT_EQ(field[18], "");  // one replay tells no spread
  const std::string report = fileText(dir + "/README.md");
  EXPECT_NE(report.find("| 1.00 ± 0.058 |"), std::string::npos) << report;
  EXPECT_NE(report.find("| 1.20 |"), std::string::npos) << report;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace coloc::twin
