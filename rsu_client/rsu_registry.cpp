#include "coloc/rsu_client/rsu_registry.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "coloc/core/config_error.hpp"

namespace coloc::rsu_client {

const std::vector<LidarModel>& lidarModels() {
  // Sigmas from the paper (Section III-C), effective ranges from its Section IV.
  static const std::vector<LidarModel> models = {{"VLP-16", 0.01486, 30.0}, {"VLP-32C", 0.00681, 50.0}};
  return models;
}

const LidarModel* findLidarModel(const std::string& name) {
  for (const LidarModel& m : lidarModels())
    if (m.name == name) return &m;
  return nullptr;
}

namespace {

[[noreturn]] void fail(const std::string& source, const YAML::Node& node, const std::string& key, const std::string& why) {
  throwConfigError(source, node.Mark().line, key, why);
}

double number(const std::string& source, const YAML::Node& node, const std::string& key) {
  try {
    const double v = node.as<double>();
    if (!std::isfinite(v)) fail(source, node, key, "must be finite");
    return v;
  } catch (const YAML::Exception&) {
    fail(source, node, key, "expected a number");
  }
}

std::string text(const std::string& source, const YAML::Node& node, const std::string& key) {
  try {
    return node.as<std::string>();
  } catch (const YAML::Exception&) {
    fail(source, node, key, "expected a string");
  }
}

RsuInfo readRsu(const std::string& source, const YAML::Node& node, std::size_t index) {
  const std::string where = "rsus[" + std::to_string(index) + "]";
  if (!node.IsMap()) fail(source, node, where, "expected a mapping");
  RsuInfo rsu;
  bool has_position = false, has_model = false;
  std::optional<double> radius;
  for (const auto& entry : node) {
    const std::string key = entry.first.as<std::string>();
    const std::string full = where + "." + key;
    if (key == "id") {
      rsu.id = text(source, entry.second, full);
    } else if (key == "position") {
      if (!entry.second.IsSequence() || entry.second.size() != 2) fail(source, entry.second, full, "expected [x, y] in the map frame");
      rsu.position = {number(source, entry.second[0], full), number(source, entry.second[1], full)};
      has_position = true;
    } else if (key == "height") {
      rsu.height = number(source, entry.second, full);
      if (rsu.height <= 0.0 || rsu.height > 30.0) fail(source, entry.second, full, "must be in (0, 30] m");
    } else if (key == "lidar_model") {
      const std::string name = text(source, entry.second, full);
      const LidarModel* model = findLidarModel(name);
      if (!model) fail(source, entry.second, full, "unknown LiDAR model '" + name + "' (known: VLP-16, VLP-32C)");
      rsu.lidar = *model;
      has_model = true;
    } else if (key == "coverage_radius") {
      radius = number(source, entry.second, full);
      if (*radius <= 0.0) fail(source, entry.second, full, "must be > 0 m");
    } else if (key == "identity") {
      rsu.identity = text(source, entry.second, full);
    } else if (key == "calibrated_variance") {
      rsu.calibrated_variance = number(source, entry.second, full);
      if (*rsu.calibrated_variance <= 0.0) fail(source, entry.second, full, "must be > 0 m^2");
    } else {
      fail(source, entry.first, full, "unknown key (id, position, height, lidar_model, coverage_radius, identity, calibrated_variance)");
    }
  }
  if (rsu.id.empty()) fail(source, node, where, "needs an id");
  if (!has_position) fail(source, node, where + " (" + rsu.id + ")", "needs a position");
  if (!has_model) fail(source, node, where + " (" + rsu.id + ")", "needs a lidar_model");
  for (char c : rsu.id)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_')
      fail(source, node, where + ".id", "'" + rsu.id + "': use letters, digits and _ (it becomes part of a DDS topic name)");
  rsu.coverage_radius = radius.value_or(rsu.lidar.range);
  if (rsu.identity.empty()) rsu.identity = "CN=" + rsu.id;
  return rsu;
}

}  // namespace

RsuRegistry RsuRegistry::parse(const std::string& yaml_text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw Error(source + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg);
  }
  RsuRegistry registry;
  if (!root.IsMap()) fail(source, root, "(top level)", "expected a mapping with covariance_placement and rsus");
  std::set<std::string> ids;
  for (const auto& entry : root) {
    const std::string key = entry.first.as<std::string>();
    if (key == "covariance_placement") {
      const std::string v = text(source, entry.second, key);
      if (v == "published") registry.placement_ = CovariancePlacement::kPublished;
      else if (v == "standard_deviation") registry.placement_ = CovariancePlacement::kStandardDeviation;
      else fail(source, entry.second, key, "expected published or standard_deviation, got '" + v + "'");
    } else if (key == "rsus") {
      if (!entry.second.IsSequence()) fail(source, entry.second, key, "expected a list of roadside units");
      for (std::size_t i = 0; i < entry.second.size(); ++i) {
        RsuInfo rsu = readRsu(source, entry.second[i], i);
        if (!ids.insert(rsu.id).second) fail(source, entry.second[i], "rsus[" + std::to_string(i) + "].id", "'" + rsu.id + "' appears twice");
        registry.rsus_.push_back(std::move(rsu));
      }
    } else {
      fail(source, entry.first, key, "unknown key (covariance_placement, rsus)");
    }
  }
  return registry;
}

RsuRegistry RsuRegistry::load(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open the RSU registry");
  std::stringstream s;
  s << in.rdbuf();
  return parse(s.str(), path);
}

const RsuInfo* RsuRegistry::find(const std::string& id) const {
  for (const RsuInfo& r : rsus_)
    if (r.id == id) return &r;
  return nullptr;
}

double RsuRegistry::variance(const RsuInfo& rsu) const {
  if (rsu.calibrated_variance) return *rsu.calibrated_variance;
  return placement_ == CovariancePlacement::kPublished ? rsu.lidar.sigma : rsu.lidar.sigma * rsu.lidar.sigma;
}

}  // namespace coloc::rsu_client
