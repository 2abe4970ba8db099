#include "coloc/twin/experiment_config.hpp"

#include "coloc/sim/scene.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <sstream>

#include "builtin_scenarios.hpp"
#include "coloc/core/config_error.hpp"
#include "coloc/core/yaml_reader.hpp"
#include "coloc/rsu_client/rsu_registry.hpp"

namespace coloc::twin {

const char* toString(RsuCovariance c) {
  switch (c) {
    case RsuCovariance::kPublished: return "published";
    case RsuCovariance::kStandardDeviation: return "standard_deviation";
    case RsuCovariance::kEstimated: return "estimated";
  }
  return "?";
}

RsuCovariance referenceCovariance(RsuCovariance main) {
  return main == RsuCovariance::kPublished ? RsuCovariance::kEstimated : RsuCovariance::kPublished;
}

ExperimentConfig quickExperiment() {
  ExperimentConfig config;
  config.trials = 1;
  config.sweep_trials = 1;
  config.network_trials = 1;
  config.delays = {0.0, 0.030};
  config.losses = {0.0, 0.20};
  config.calibration = false;
  return config;
}

ExperimentConfig parseExperimentConfig(const std::string& yaml_text, const std::string& source_name, const ExperimentConfig& defaults) {
  const YamlReader r(source_name);
  const YAML::Node root = r.parse(yaml_text);
  ExperimentConfig c = defaults;
  if (root.IsNull()) return c;
  if (!root.IsMap()) r.fail(root, "(file)", "expected a mapping of keys to values");
  for (const auto& entry : root) {
    const std::string key = r.key(entry.first);
    const YAML::Node& v = entry.second;
    if (key == "sites") c.sites = r.textList(v, key);
    else if (key == "trials") c.trials = static_cast<int>(r.integer(v, key, 1, 1000));
    else if (key == "lidars") {
      c.lidars = r.textList(v, key);
      for (const std::string& l : c.lidars)
        if (!rsu_client::findLidarModel(l)) r.fail(v, key, "unknown LiDAR model '" + l + "' (VLP-16 or VLP-32C)");
    } else if (key == "delays") c.delays = r.numberList(v, key, 0.0, 1.0);
    else if (key == "losses") c.losses = r.numberList(v, key, 0.0, 0.99);
    else if (key == "network") c.network = r.flag(v, key);
    else if (key == "rsu_covariance") {
      const std::string t = r.choice(v, key, {"published", "standard_deviation", "estimated"});
      c.rsu_covariance = t == "published" ? RsuCovariance::kPublished
                         : t == "standard_deviation" ? RsuCovariance::kStandardDeviation : RsuCovariance::kEstimated;
    } else if (key == "network_trials") c.network_trials = static_cast<int>(r.integer(v, key, 1, 1000));
    else if (key == "gate_recovery") c.gate_recovery = static_cast<int>(r.integer(v, key, 0, 1000));
    else if (key == "bin_length") c.bin_length = r.inRange(v, key, 0.1, 100.0);
    else if (key == "fuse_config") c.fuse_config = r.text(v, key);
    else if (key == "jobs") c.jobs = static_cast<int>(r.integer(v, key, 1, 64));
    else if (key == "sweeps") c.sweeps = r.flag(v, key);
    else if (key == "sweep_trials") c.sweep_trials = static_cast<int>(r.integer(v, key, 1, 1000));
    else if (key == "rsu_heights") c.rsu_heights = r.numberList(v, key, 0.5, 20.0);
    else if (key == "speeds") c.speeds = r.numberList(v, key, 1.0, 40.0);
    else if (key == "smoother") c.smoother = r.flag(v, key);
    else if (key == "recordings") c.recordings = r.flag(v, key);
    else if (key == "twist_covariance") c.twist_covariance_estimated = r.choice(v, key, {"estimated", "message"}) == "estimated";
    else if (key == "ndt_covariance") {
      const std::string source = r.choice(v, key, {"estimated", "estimated_position", "multi_ndt_score", "published"});
      c.ndt_covariance = source == "estimated"            ? NdtCovarianceSource::kEstimated
                         : source == "estimated_position" ? NdtCovarianceSource::kEstimatedPosition
                         : source == "multi_ndt_score"    ? NdtCovarianceSource::kMultiNdtScore
                                                          : NdtCovarianceSource::kPublished;
    }
    else if (key == "calibration") c.calibration = r.flag(v, key);
    else if (key == "rsu_calibration") c.calibrate_rsus = r.choice(v, key, {"noise_drive", "none"}) == "noise_drive";
    else if (key == "error_sources") c.ideal_twin = r.choice(v, key, {"real", "ideal"}) == "ideal";
    else if (key == "errors") {
      sim::readErrorSources(r, v, {});  // checked here, where the file and line are known
      YAML::Emitter out;
      out << v;
      c.errors = out.c_str();
    }
    else if (key == "calibration_error") {
      c.calibration_error = r.numberList(v, key, -30.0, 30.0);
      if (c.calibration_error.size() != 3 || std::abs(c.calibration_error[0]) > 10.0 || std::abs(c.calibration_error[1]) > 10.0)
        r.fail(v, key, "expected [dx, dy, dyaw_deg] within 10 m and 30 deg");
    } else if (key == "calibration_clock_offset_ms") c.calibration_clock_offset_ms = r.inRange(v, key, -1000.0, 1000.0);
    else if (key == "oracle_fix_limit") c.oracle_fix_limit = r.inRange(v, key, 0.0, 100.0);
    else if (key == "rsu_background") c.rsu_background_learned = r.choice(v, key, {"learned", "surveyed"}) == "learned";
    else if (key == "rsu_fix_error") {
      const std::string how = r.choice(v, key, {"by_range", "by_range_and_mean", "flat"});
      c.rsu_fix_error_by_range = how != "flat";
      c.rsu_fix_error_mean = how == "by_range_and_mean";
    }
    else if (key == "ndt_quality_map") c.ndt_quality_by_place = r.choice(v, key, {"by_place", "site"}) == "by_place";
    else if (key == "map_match_bias_length") c.map_match_bias_length = r.inRange(v, key, 0.0, 10000.0);
    else if (key == "ndt_quality_passes") c.ndt_quality_passes = static_cast<int>(r.integer(v, key, 1, 10));
    else r.fail(entry.first, key, "unknown key (sites, trials, lidars, delays, losses, network, network_trials, rsu_covariance, gate_recovery, bin_length, fuse_config, jobs, sweeps, "
                                  "sweep_trials, rsu_heights, speeds, smoother, recordings, calibration, calibration_error, calibration_clock_offset_ms, twist_covariance, ndt_covariance, error_sources, errors, rsu_calibration, "
                                  "oracle_fix_limit, rsu_background, rsu_fix_error, ndt_quality_map, ndt_quality_passes, map_match_bias_length)");
  }
  if (c.delays.front() != 0.0 || c.losses.front() != 0.0)
    throwConfigError(source_name, -1, "delays/losses", "the first delay and the first loss must be 0: the ideal network is the reference");
  return c;
}

ExperimentConfig loadExperimentConfig(const std::string& path, const ExperimentConfig& defaults) {
  ExperimentConfig c = parseExperimentConfig(YamlReader::readFile(path, "experiment file"), path, defaults);
  // Files the experiment names are found beside it, as a configuration's registry is.
  const std::filesystem::path folder = std::filesystem::path(path).parent_path();
  if (!c.fuse_config.empty() && std::filesystem::path(c.fuse_config).is_relative()) c.fuse_config = (folder / c.fuse_config).string();
  for (std::string& site : c.sites)
    if (!builtinScenario(site) && std::filesystem::path(site).is_relative() && std::filesystem::exists(folder / site)) site = (folder / site).string();
  return c;
}

std::string scenarioText(const std::string& site) {
  if (const char* builtin = builtinScenario(site)) return builtin;
  try {
    return YamlReader::readFile(site, "scenario file");
  } catch (const Error&) {
    throw Error(site + ": neither a built-in scenario (" + builtinScenarioNames() + ") nor a readable scenario file");
  }
}

}  // namespace coloc::twin
