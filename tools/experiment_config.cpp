#include "experiment_config.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "builtin_scenarios.hpp"
#include "coloc/core/config_error.hpp"
#include "coloc/rsu_client/rsu_registry.hpp"

namespace coloc::tools {

namespace {

struct Reader {
  std::string source;
  [[noreturn]] void fail(const YAML::Node& n, const std::string& key, const std::string& why) const {
    throwConfigError(source, n.Mark().line, key, why);
  }
  double number(const YAML::Node& n, const std::string& key, double lo, double hi) const {
    double v = 0.0;
    try {
      v = n.as<double>();
    } catch (const YAML::Exception&) {
      fail(n, key, "expected a number");
    }
    if (!(v >= lo && v <= hi)) fail(n, key, "must be in [" + trim(lo) + ", " + trim(hi) + "]");
    return v;
  }
  int integer(const YAML::Node& n, const std::string& key, int lo, int hi) const {
    int v = 0;
    try {
      v = n.as<int>();
    } catch (const YAML::Exception&) {
      fail(n, key, "expected an integer");
    }
    if (v < lo || v > hi) fail(n, key, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return v;
  }
  std::string text(const YAML::Node& n, const std::string& key) const {
    if (!n.IsScalar()) fail(n, key, "expected a string");
    return n.as<std::string>();
  }
  bool flag(const YAML::Node& n, const std::string& key) const {
    try {
      return n.as<bool>();
    } catch (const YAML::Exception&) {
      fail(n, key, "expected true or false");
    }
  }
  std::vector<double> numbers(const YAML::Node& n, const std::string& key, double lo, double hi) const {
    if (!n.IsSequence() || n.size() == 0) fail(n, key, "expected a non-empty list of numbers");
    std::vector<double> v;
    for (const auto& e : n) v.push_back(number(e, key, lo, hi));
    return v;
  }
  std::vector<std::string> texts(const YAML::Node& n, const std::string& key) const {
    if (!n.IsSequence() || n.size() == 0) fail(n, key, "expected a non-empty list");
    std::vector<std::string> v;
    for (const auto& e : n) v.push_back(text(e, key));
    return v;
  }
  static std::string trim(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  }
};

}  // namespace

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

ExperimentConfig quickExperiment(ExperimentConfig config) {
  config.trials = 1;
  config.sweep_trials = 1;
  config.network_trials = 1;
  return config;
}

ExperimentConfig parseExperimentConfig(const std::string& yaml_text, const std::string& source_name) {
  const Reader r{source_name};
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throwConfigError(source_name, e.mark.line, "(file)", "not valid YAML: " + e.msg);
  }
  ExperimentConfig c;
  if (root.IsNull()) return c;
  if (!root.IsMap()) r.fail(root, "(file)", "expected a mapping of keys to values");
  for (const auto& entry : root) {
    const std::string key = entry.first.as<std::string>();
    const YAML::Node& v = entry.second;
    if (key == "sites") c.sites = r.texts(v, key);
    else if (key == "trials") c.trials = r.integer(v, key, 1, 1000);
    else if (key == "lidars") {
      c.lidars = r.texts(v, key);
      for (const std::string& l : c.lidars)
        if (!rsu_client::findLidarModel(l)) r.fail(v, key, "unknown LiDAR model '" + l + "' (VLP-16 or VLP-32C)");
    } else if (key == "delays") c.delays = r.numbers(v, key, 0.0, 1.0);
    else if (key == "losses") c.losses = r.numbers(v, key, 0.0, 0.99);
    else if (key == "network") c.network = r.flag(v, key);
    else if (key == "rsu_covariance") {
      const std::string t = r.text(v, key);
      if (t == "published") c.rsu_covariance = RsuCovariance::kPublished;
      else if (t == "standard_deviation") c.rsu_covariance = RsuCovariance::kStandardDeviation;
      else if (t == "estimated") c.rsu_covariance = RsuCovariance::kEstimated;
      else r.fail(v, key, "expected published, standard_deviation or estimated");
    } else if (key == "network_trials") c.network_trials = r.integer(v, key, 1, 1000);
    else if (key == "gate_recovery") c.gate_recovery = r.integer(v, key, 0, 1000);
    else if (key == "bin_length") c.bin_length = r.number(v, key, 0.1, 100.0);
    else if (key == "fuse_config") c.fuse_config = r.text(v, key);
    else if (key == "jobs") c.jobs = r.integer(v, key, 1, 64);
    else if (key == "sweeps") c.sweeps = r.flag(v, key);
    else if (key == "sweep_trials") c.sweep_trials = r.integer(v, key, 1, 1000);
    else if (key == "rsu_heights") c.rsu_heights = r.numbers(v, key, 0.5, 20.0);
    else if (key == "speeds") c.speeds = r.numbers(v, key, 1.0, 40.0);
    else r.fail(entry.first, key, "unknown key (sites, trials, lidars, delays, losses, network, network_trials, rsu_covariance, gate_recovery, bin_length, fuse_config, jobs, sweeps, "
                                  "sweep_trials, rsu_heights, speeds)");
  }
  if (c.delays.front() != 0.0 || c.losses.front() != 0.0)
    throwConfigError(source_name, -1, "delays/losses", "the first delay and the first loss must be 0: the ideal network is the reference");
  return c;
}

ExperimentConfig loadExperimentConfig(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot read the experiment file");
  std::ostringstream text;
  text << in.rdbuf();
  return parseExperimentConfig(text.str(), path);
}

std::string scenarioText(const std::string& site) {
  if (const char* builtin = builtinScenario(site)) return builtin;
  std::ifstream in(site);
  if (!in) throw Error(site + ": neither a built-in scenario (site_a, site_b) nor a readable scenario file");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace coloc::tools
