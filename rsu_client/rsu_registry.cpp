#include "coloc/rsu_client/rsu_registry.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <sstream>

#include "coloc/core/error.hpp"
#include "coloc/core/yaml_reader.hpp"

namespace coloc::rsu_client {

const std::vector<LidarModel>& lidarModels() {
  // Sigmas from the paper (Section III-C), effective ranges from its Section IV.
  // OS1-64 (64 even beams, as on roadside poles) has no published figure: the VLP-32C's, whose fixes
  // it matches on the twin from poles (median 2.6 cm); each fix's own covariance says more.
  static const std::vector<LidarModel> models = {
      {"VLP-16", 0.01486, 30.0, 0.2}, {"VLP-32C", 0.00681, 50.0, 0.2}, {"OS1-64", 0.00681, 60.0, 360.0 / 1024.0}};
  return models;
}

const LidarModel* findLidarModel(const std::string& name) {
  for (const LidarModel& m : lidarModels())
    if (m.name == name) return &m;
  return nullptr;
}

namespace {

RsuInfo readRsu(const YamlReader& r, const YAML::Node& node, std::size_t index) {
  const std::string where = "rsus[" + std::to_string(index) + "]";
  r.allowKeys(node, where,
              {"id", "position", "height", "yaw_deg", "roll_deg", "pitch_deg", "lidar_model", "coverage_radius", "identity", "calibrated_variance",
               "calibrated_error_by_range", "calibration"});
  RsuInfo rsu;
  bool has_position = false, has_model = false;
  std::optional<double> radius;
  for (const auto& entry : node) {
    const std::string key = r.key(entry.first);
    const std::string full = where + "." + key;
    if (key == "id") {
      rsu.id = r.text(entry.second, full);
    } else if (key == "position") {
      const auto v = r.numbers(entry.second, full, 2, "[x, y] in the map frame");
      rsu.position = {v[0], v[1]};
      if (!rsu.position.allFinite()) r.fail(entry.second, full, "must be finite");
      has_position = true;
    } else if (key == "height") {
      rsu.height = r.inRange(entry.second, full, 0.0, 30.0);
      if (rsu.height == 0.0) r.fail(entry.second, full, "must be above the road (> 0 m)");
    } else if (key == "yaw_deg") {
      rsu.yaw = r.inRange(entry.second, full, -360.0, 360.0) * M_PI / 180.0;
    } else if (key == "roll_deg") {
      rsu.roll = r.inRange(entry.second, full, -45.0, 45.0) * M_PI / 180.0;
    } else if (key == "pitch_deg") {
      rsu.pitch = r.inRange(entry.second, full, -45.0, 45.0) * M_PI / 180.0;
    } else if (key == "lidar_model") {
      const std::string name = r.text(entry.second, full);
      const LidarModel* model = findLidarModel(name);
      if (!model) r.fail(entry.second, full, "unknown LiDAR model '" + name + "' (known: VLP-16, VLP-32C, OS1-64)");
      rsu.lidar = *model;
      has_model = true;
    } else if (key == "coverage_radius") {
      radius = r.positive(entry.second, full);
    } else if (key == "identity") {
      rsu.identity = r.text(entry.second, full);
    } else if (key == "calibrated_variance") {
      rsu.calibrated_variance = r.positive(entry.second, full);
    } else if (key == "calibrated_error_by_range") {
      if (!entry.second.IsSequence() || entry.second.size() == 0)
        r.fail(entry.second, full, "expected a list of [range m, sd along m, sd across m(, mean forward m, mean left m)], by increasing range");
      for (std::size_t i = 0; i < entry.second.size(); ++i) {
        const std::string row = full + "[" + std::to_string(i) + "]";
        const bool with_mean = entry.second[i].IsSequence() && entry.second[i].size() == 5;
        const auto v = r.numbers(entry.second[i], row, with_mean ? 5 : 3,
                                 "[range m, sd along the line of sight m, sd across it m] or with the mean error forward and left of the vehicle after them");
        if (!(v[0] >= 0.0 && v[0] <= 1000.0)) r.fail(entry.second[i], row, "the range must be within 0-1000 m");
        if (!(v[1] > 0.0 && v[1] <= 10.0 && v[2] > 0.0 && v[2] <= 10.0)) r.fail(entry.second[i], row, "each standard deviation must be within (0, 10] m");
        if (with_mean && !(std::abs(v[3]) <= 10.0 && std::abs(v[4]) <= 10.0)) r.fail(entry.second[i], row, "each mean error must be within 10 m of 0");
        if (!rsu.calibrated_error_by_range.empty() && !(v[0] > rsu.calibrated_error_by_range.back().range))
          r.fail(entry.second[i], row, "the ranges must increase from row to row");
        rsu.calibrated_error_by_range.push_back({v[0], v[1], v[2], with_mean ? v[3] : 0.0, with_mean ? v[4] : 0.0});
      }
    } else if (key == "calibration") {
      r.allowKeys(entry.second, full, {"dx", "dy", "dyaw_deg", "clock_offset_ms"});
      RsuCalibrationEntry c;
      for (const auto& e : entry.second) {
        const std::string k = r.key(e.first);
        const std::string kk = full + "." + k;
        if (k == "dx") c.dx = r.inRange(e.second, kk, -10.0, 10.0);
        else if (k == "dy") c.dy = r.inRange(e.second, kk, -10.0, 10.0);
        else if (k == "dyaw_deg") c.dyaw = r.inRange(e.second, kk, -30.0, 30.0) * M_PI / 180.0;
        else c.clock_offset = 1e-3 * r.inRange(e.second, kk, -1000.0, 1000.0);
      }
      rsu.calibration = c;
    }
  }
  if (rsu.id.empty()) r.fail(node, where, "needs an id");
  if (!has_position) r.fail(node, where + " (" + rsu.id + ")", "needs a position");
  if (!has_model) r.fail(node, where + " (" + rsu.id + ")", "needs a lidar_model");
  if (!rsu.calibrated_error_by_range.empty() && !rsu.calibrated_variance)
    r.fail(node, where + ".calibrated_error_by_range", "needs calibrated_variance: the error by range is part of the same calibration");
  for (char c : rsu.id)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_')
      r.fail(node, where + ".id", "'" + rsu.id + "': use letters, digits and _ (it becomes part of a DDS topic name)");
  rsu.coverage_radius = radius.value_or(rsu.lidar.range);
  if (rsu.identity.empty()) rsu.identity = "CN=" + rsu.id;
  return rsu;
}

}  // namespace

RsuRegistry RsuRegistry::parse(const std::string& yaml_text, const std::string& source) {
  const YamlReader r(source);
  const YAML::Node root = r.parse(yaml_text);
  RsuRegistry registry;
  if (!root.IsMap()) r.fail(root, "(top level)", "expected a mapping with covariance_placement and rsus");
  std::set<std::string> ids;
  for (const auto& entry : root) {
    const std::string key = r.key(entry.first);
    if (key == "covariance_placement") {
      registry.placement_ = r.choice(entry.second, key, {"published", "standard_deviation"}) == "published"
                                ? CovariancePlacement::kPublished
                                : CovariancePlacement::kStandardDeviation;
    } else if (key == "map_frame") {
      registry.map_frame_ = r.text(entry.second, key);
      bool plain = !registry.map_frame_.empty() && registry.map_frame_.size() <= kMaxFrameIdBytes;
      for (char c : registry.map_frame_) plain = plain && (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '/' || c == '-' || c == '.');
      if (!plain) r.fail(entry.second, key, "'" + registry.map_frame_ + "': a frame name of 1-256 letters, digits, _ / - .");
    } else if (key == "rsus") {
      if (!entry.second.IsSequence()) r.fail(entry.second, key, "expected a list of roadside units");
      for (std::size_t i = 0; i < entry.second.size(); ++i) {
        RsuInfo rsu = readRsu(r, entry.second[i], i);
        if (!ids.insert(rsu.id).second) r.fail(entry.second[i], "rsus[" + std::to_string(i) + "].id", "'" + rsu.id + "' appears twice");
        registry.rsus_.push_back(std::move(rsu));
      }
    } else {
      r.fail(entry.first, key, "unknown key (covariance_placement, map_frame, rsus)");
    }
  }
  return registry;
}

RsuRegistry RsuRegistry::load(const std::string& path) {
  return parse(YamlReader::readFile(path, "RSU registry"), path);
}

RsuRegistry::RsuRegistry(const std::vector<RsuInfo>& rsus, CovariancePlacement placement, const std::string& map_frame) {
  RsuRegistry probe;
  probe.rsus_ = rsus;
  probe.placement_ = placement;
  probe.map_frame_ = map_frame;
  // Through the file format, so that an entry made in code passes exactly the checks a file does.
  *this = parse(probe.toYaml(), "(RSU registry made in code)");
}

std::string RsuRegistry::toYaml() const {
  auto number = [](double v) {  // the shortest text that reads back to the same double
    char b[40];
    for (int precision = 15; precision <= 17; ++precision) {
      std::snprintf(b, sizeof b, "%.*g", precision, v);
      if (std::strtod(b, nullptr) == v) break;
    }
    return std::string(b);
  };
  std::ostringstream out;
  out << "# Roadside units the vehicle accepts fixes from (coloc RSU registry). Positions are in the map frame.\n"
      << "covariance_placement: " << (placement_ == CovariancePlacement::kPublished ? "published" : "standard_deviation") << "\n"
      << "map_frame: \"" << map_frame_ << "\"\n"
      << "rsus:" << (rsus_.empty() ? " []" : "") << "\n";
  for (const RsuInfo& r : rsus_) {
    out << "  - id: " << r.id << "\n"
        << "    position: [" << number(r.position.x()) << ", " << number(r.position.y()) << "]\n"
        << "    height: " << number(r.height) << "\n";
    if (r.yaw != 0.0) out << "    yaw_deg: " << number(r.yaw * 180.0 / M_PI) << "\n";
    if (r.roll != 0.0) out << "    roll_deg: " << number(r.roll * 180.0 / M_PI) << "\n";
    if (r.pitch != 0.0) out << "    pitch_deg: " << number(r.pitch * 180.0 / M_PI) << "\n";
    out
        << "    lidar_model: " << r.lidar.name << "\n"
        << "    coverage_radius: " << number(r.coverage_radius) << "\n"
        << "    identity: \"" << r.identity << "\"\n";
    if (r.calibrated_variance) out << "    calibrated_variance: " << number(*r.calibrated_variance) << "\n";
    if (!r.calibrated_error_by_range.empty()) {
      out << "    calibrated_error_by_range:  # [range m, sd along the line of sight m, sd across it m(, mean forward m, mean left m)]\n";
      for (const RsuInfo::ErrorAtRange& e : r.calibrated_error_by_range) {
        out << "      - [" << number(e.range) << ", " << number(e.along_sd) << ", " << number(e.across_sd);
        if (e.forward_mean != 0.0 || e.left_mean != 0.0) out << ", " << number(e.forward_mean) << ", " << number(e.left_mean);
        out << "]\n";
      }
    }
    if (r.calibration)
      out << "    calibration: {dx: " << number(r.calibration->dx) << ", dy: " << number(r.calibration->dy)
          << ", dyaw_deg: " << number(r.calibration->dyaw * 180.0 / M_PI) << ", clock_offset_ms: " << number(r.calibration->clock_offset * 1e3)
          << "}\n";
  }
  return out.str();
}

const RsuInfo* RsuRegistry::find(const std::string& id) const {
  for (const RsuInfo& r : rsus_)
    if (r.id == id) return &r;
  return nullptr;
}

double RsuRegistry::variance(const RsuInfo& rsu) const { return rsu.calibrated_variance ? *rsu.calibrated_variance : lidarVariance(rsu); }

namespace {

// The calibration by range at `range`: each figure interpolated between the rows about it (the
// variances as variances), the end rows held beyond them.
RsuInfo::ErrorAtRange errorAtRange(const std::vector<RsuInfo::ErrorAtRange>& table, double range) {
  auto upper = std::upper_bound(table.begin(), table.end(), range, [](double r, const RsuInfo::ErrorAtRange& e) { return r < e.range; });
  const RsuInfo::ErrorAtRange& hi = upper == table.end() ? table.back() : *upper;
  const RsuInfo::ErrorAtRange& lo = upper == table.begin() ? table.front() : *std::prev(upper);
  const double w = hi.range > lo.range ? std::clamp((range - lo.range) / (hi.range - lo.range), 0.0, 1.0) : 0.0;
  auto mix = [w](double a, double b) { return (1.0 - w) * a + w * b; };
  return {range, std::sqrt(mix(lo.along_sd * lo.along_sd, hi.along_sd * hi.along_sd)), std::sqrt(mix(lo.across_sd * lo.across_sd, hi.across_sd * hi.across_sd)),
          mix(lo.forward_mean, hi.forward_mean), mix(lo.left_mean, hi.left_mean)};
}

}  // namespace

Eigen::Matrix2d RsuRegistry::covarianceAt(const RsuInfo& rsu, const Eigen::Vector2d& fix) const {
  const Eigen::Vector2d sight = fix - rsu.position;
  const double range = sight.norm();
  if (!rsu.calibrated_variance || rsu.calibrated_error_by_range.empty() || !(range > 0.0)) return variance(rsu) * Eigen::Matrix2d::Identity();
  const RsuInfo::ErrorAtRange e = errorAtRange(rsu.calibrated_error_by_range, range);
  const Eigen::Vector2d u = sight / range, v(-u.y(), u.x());
  return e.along_sd * e.along_sd * u * u.transpose() + e.across_sd * e.across_sd * v * v.transpose();
}

Eigen::Vector2d RsuRegistry::meanErrorAt(const RsuInfo& rsu, const Eigen::Vector2d& fix, double yaw) const {
  const double range = (fix - rsu.position).norm();
  if (!rsu.calibrated_variance || rsu.calibrated_error_by_range.empty() || !std::isfinite(range) || !std::isfinite(yaw))
    return Eigen::Vector2d::Zero();
  const RsuInfo::ErrorAtRange e = errorAtRange(rsu.calibrated_error_by_range, range);
  const Eigen::Vector2d forward(std::cos(yaw), std::sin(yaw)), left(-forward.y(), forward.x());
  return e.forward_mean * forward + e.left_mean * left;
}

double RsuRegistry::lidarVariance(const RsuInfo& rsu) const {
  return placement_ == CovariancePlacement::kPublished ? rsu.lidar.sigma : rsu.lidar.sigma * rsu.lidar.sigma;
}

}  // namespace coloc::rsu_client
