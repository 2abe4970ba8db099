#include "fuse_config.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <set>
#include <type_traits>
#include <sstream>

#include "coloc/core/config_error.hpp"
#include "coloc/fusion/ekf_params.hpp"
#include "coloc/fusion/localizer.hpp"

namespace coloc::tools {

const char* toString(InputRole role) {
  switch (role) {
    case InputRole::kPose: return "pose";
    case InputRole::kTwist: return "twist";
    case InputRole::kGroundTruth: return "ground_truth";
    case InputRole::kScan: return "scan";
    case InputRole::kIgnore: return "ignore";
  }
  return "?";
}

namespace {

const char* toString(ClockMode mode) {
  switch (mode) {
    case ClockMode::kAuto: return "auto";
    case ClockMode::kSame: return "same";
    case ClockMode::kSeparate: return "separate";
  }
  return "?";
}

// Names a node's place in the file for error messages.
class Context {
 public:
  explicit Context(std::string source) : source_(std::move(source)) {}
  [[noreturn]] void fail(const YAML::Node& node, const std::string& key, const std::string& why) const {
    throwConfigError(source_, node.Mark().line, key, why);
  }
  template <typename T>
  T read(const YAML::Node& node, const std::string& key, const char* what) const {
    try {
      return node.as<T>();
    } catch (const YAML::Exception&) {
      fail(node, key, std::string("expected ") + what);
    }
  }
  double readDouble(const YAML::Node& node, const std::string& key) const {
    const double v = read<double>(node, key, "a number");
    if (std::isnan(v)) fail(node, key, "must not be NaN");
    return v;
  }

 private:
  std::string source_;
};

void requireMap(const Context& ctx, const YAML::Node& node, const std::string& key) {
  if (!node.IsMap()) ctx.fail(node, key, "expected a mapping of keys to values");
}

void readFusion(const Context& ctx, const YAML::Node& node, fusion::EkfConfig& config) {
  requireMap(ctx, node, "fusion");
  for (const auto& entry : node) {
    const std::string key = entry.first.as<std::string>();
    const fusion::EkfParam* param = nullptr;
    for (const auto& p : fusion::ekfParams())
      if (key == p.key) param = &p;
    if (!param) ctx.fail(entry.first, "fusion." + key, "unknown key (see `coloc config` for the valid ones)");
    const std::string full = "fusion." + key;
    if (const auto* d = std::get_if<double fusion::EkfConfig::*>(&param->field)) {
      config.*(*d) = ctx.readDouble(entry.second, full);
    } else if (const auto* i = std::get_if<int fusion::EkfConfig::*>(&param->field)) {
      config.*(*i) = ctx.read<int>(entry.second, full, "an integer");
    } else {
      config.*std::get<bool fusion::EkfConfig::*>(param->field) = ctx.read<bool>(entry.second, full, "true or false");
    }
  }
  try {
    fusion::Localizer probe(config);  // the filter's own range checks, reported against the file
  } catch (const Error& e) {
    ctx.fail(node, "fusion", e.what());
  }
}

Vector6d readVariances(const Context& ctx, const YAML::Node& node, const std::string& key) {
  if (!node.IsSequence() || node.size() != 6)
    ctx.fail(node, key, "expected 6 variances [x, y, z, roll, pitch, yaw] or [vx, vy, vz, wx, wy, wz]; .inf = not measured");
  Vector6d v;
  for (int i = 0; i < 6; ++i) {
    v[i] = ctx.readDouble(node[i], key);
    if (!(v[i] > 0.0)) ctx.fail(node[i], key, "variances must be > 0 (.inf for not measured)");
  }
  return v;
}

rsu_client::LinkConfig readLink(const Context& ctx, const YAML::Node& node, const std::string& where) {
  requireMap(ctx, node, where);
  rsu_client::LinkConfig link;
  auto probability = [&](const YAML::Node& n, const std::string& key) {
    const double v = ctx.readDouble(n, key);
    if (!(v >= 0.0 && v <= 1.0)) ctx.fail(n, key, "must be a probability in [0, 1]");
    return v;
  };
  for (const auto& entry : node) {
    const std::string key = entry.first.as<std::string>();
    const std::string full = where + "." + key;
    if (key == "delay" || key == "jitter") {
      const double v = ctx.readDouble(entry.second, full);
      if (!(v >= 0.0 && v < 10.0)) ctx.fail(entry.second, full, "must be in [0, 10) s");
      (key == "delay" ? link.delay : link.jitter) = v;
    } else if (key == "loss") {
      link.loss = probability(entry.second, full);
    } else if (key == "burst") {
      link.burst = ctx.read<bool>(entry.second, full, "true or false");
    } else if (key == "p_good_to_bad") {
      link.p_good_to_bad = probability(entry.second, full);
    } else if (key == "p_bad_to_good") {
      link.p_bad_to_good = probability(entry.second, full);
    } else if (key == "loss_in_good") {
      link.loss_in_good = probability(entry.second, full);
    } else if (key == "loss_in_bad") {
      link.loss_in_bad = probability(entry.second, full);
    } else if (key == "seed") {
      link.seed = ctx.read<std::uint64_t>(entry.second, full, "a non-negative integer");
    } else {
      ctx.fail(entry.first, full, "unknown key (delay, jitter, loss, burst, p_good_to_bad, p_bad_to_good, loss_in_good, loss_in_bad, seed)");
    }
  }
  return link;
}

InputConfig readInput(const Context& ctx, const std::string& topic, const YAML::Node& node) {
  const std::string where = "inputs." + topic;
  requireMap(ctx, node, where);
  InputConfig input;
  bool has_role = false;
  for (const auto& entry : node) {
    const std::string key = entry.first.as<std::string>();
    const std::string full = where + "." + key;
    if (key == "role") {
      const std::string role = ctx.read<std::string>(entry.second, full, "a string");
      if (role == "pose") input.role = InputRole::kPose;
      else if (role == "twist") input.role = InputRole::kTwist;
      else if (role == "ground_truth") input.role = InputRole::kGroundTruth;
      else if (role == "scan") input.role = InputRole::kScan;
      else if (role == "ignore") input.role = InputRole::kIgnore;
      else ctx.fail(entry.second, full, "expected pose, twist, ground_truth, scan or ignore, got '" + role + "'");
      has_role = true;
    } else if (key == "source") {
      input.source = ctx.read<std::string>(entry.second, full, "a string");
    } else if (key == "covariance_diagonal") {
      input.covariance_diagonal = readVariances(ctx, entry.second, full);
    } else if (key == "additional_delay") {
      input.additional_delay = ctx.readDouble(entry.second, full);
      if (!(input.additional_delay >= 0.0 && input.additional_delay < 10.0)) ctx.fail(entry.second, full, "must be in [0, 10) s");
    } else if (key == "link") {
      input.link = readLink(ctx, entry.second, full);
    } else {
      ctx.fail(entry.first, full, "unknown key (role, source, covariance_diagonal, additional_delay, link)");
    }
  }
  if (!has_role) ctx.fail(node, where, "needs a role: pose, twist, ground_truth, scan or ignore");
  if (input.source.empty()) input.source = topic;
  return input;
}

void readReplay(const Context& ctx, const YAML::Node& node, ReplayConfig& replay) {
  requireMap(ctx, node, "replay");
  for (const auto& entry : node) {
    const std::string key = entry.first.as<std::string>();
    const std::string full = "replay." + key;
    if (key == "clock") {
      const std::string mode = ctx.read<std::string>(entry.second, full, "a string");
      if (mode == "auto") replay.clock = ClockMode::kAuto;
      else if (mode == "same") replay.clock = ClockMode::kSame;
      else if (mode == "separate") replay.clock = ClockMode::kSeparate;
      else ctx.fail(entry.second, full, "expected auto, same or separate, got '" + mode + "'");
    } else if (key == "zero_variance_is_unmeasured") {
      replay.zero_variance_is_unmeasured = ctx.read<bool>(entry.second, full, "true or false");
    } else if (key == "fallback_pose_variance") {
      replay.fallback_pose_variance = readVariances(ctx, entry.second, full);
    } else if (key == "fallback_twist_variance") {
      replay.fallback_twist_variance = readVariances(ctx, entry.second, full);
    } else if (key == "initial_pose") {
      if (entry.second.IsNull()) continue;
      if (!entry.second.IsSequence() || entry.second.size() != 4) ctx.fail(entry.second, full, "expected [x, y, z, yaw]");
      Eigen::Vector4d v;
      for (int i = 0; i < 4; ++i) v[i] = ctx.readDouble(entry.second[i], full);
      replay.initial_pose = v;
    } else if (key == "ground_truth_max_gap") {
      replay.ground_truth_max_gap = ctx.readDouble(entry.second, full);
      if (!(replay.ground_truth_max_gap > 0.0 && replay.ground_truth_max_gap <= 10.0))
        ctx.fail(entry.second, full, "must be in (0, 10] s");
    } else {
      ctx.fail(entry.first, full, "unknown key (see `coloc config`)");
    }
  }
}

std::string yamlNumber(double v) {
  if (v == kInfinity) return ".inf";
  std::ostringstream out;
  out << v;
  return out.str();
}

std::string yamlList(const Vector6d& v) {
  std::string s = "[";
  for (int i = 0; i < 6; ++i) s += (i ? ", " : "") + yamlNumber(v[i]);
  return s + "]";
}

struct ReplayKey {
  const char* key;
  const char* unit;
  const char* meaning;
  std::string (*value)(const ReplayConfig&);
};

const std::vector<ReplayKey>& replayKeys() {
  static const std::vector<ReplayKey> keys = {
      {"clock", "", "auto, same or separate: are header stamps and log times on one clock? auto decides from the data",
       [](const ReplayConfig& r) { return std::string(toString(r.clock)); }},
      {"zero_variance_is_unmeasured", "", "read a 0 variance in a message as +inf, as ROS drivers write 0 for what they do not estimate",
       [](const ReplayConfig& r) { return std::string(r.zero_variance_is_unmeasured ? "true" : "false"); }},
      {"fallback_pose_variance", "m^2, rad^2", "pose covariance diagonal for messages that carry none (Autoware's NDT value)",
       [](const ReplayConfig& r) { return yamlList(r.fallback_pose_variance); }},
      {"fallback_twist_variance", "(m/s)^2, (rad/s)^2", "twist covariance diagonal for messages that carry none (Autoware's 0.2 m/s, 0.1 rad/s)",
       [](const ReplayConfig& r) { return yamlList(r.fallback_twist_variance); }},
      {"ground_truth_max_gap", "s", "ground truth is interpolated to the filter's ticks only across gaps up to this",
       [](const ReplayConfig& r) { return yamlNumber(r.ground_truth_max_gap); }},
      {"initial_pose", "m, rad", "[x, y, z, yaw] to start the filter at the first message (NDT needs a first guess); null = from the first full pose",
       [](const ReplayConfig& r) {
         if (!r.initial_pose) return std::string("null");
         std::string t = "[";
         for (int i = 0; i < 4; ++i) t += (i ? ", " : "") + yamlNumber((*r.initial_pose)[i]);
         return t + "]"; }},
  };
  return keys;
}

// The `ndt:` section, one row per key: reader and writer side by side so they cannot drift apart.
struct NdtKey {
  const char* key;
  const char* unit;
  const char* meaning;
  std::string (*get)(const NdtSection&);
  void (*set)(const Context&, const YAML::Node&, const std::string&, NdtSection&);
};

template <typename T>
std::string show(T v) {
  std::ostringstream out;
  out << v;
  std::string text = out.str();
  if constexpr (std::is_floating_point_v<T>)
    if (text.find_first_of(".eEn") == std::string::npos) text += ".0";
  return text;
}

double positive(const Context& ctx, const YAML::Node& n, const std::string& key) {
  const double v = ctx.readDouble(n, key);
  if (!(v > 0.0) || !std::isfinite(v)) ctx.fail(n, key, "must be a finite number > 0");
  return v;
}

std::string choice(const Context& ctx, const YAML::Node& n, const std::string& key, std::initializer_list<const char*> options) {
  const std::string v = ctx.read<std::string>(n, key, "a string");
  std::string list;
  for (const char* o : options) {
    if (v == o) return v;
    list += std::string(list.empty() ? "" : ", ") + o;
  }
  ctx.fail(n, key, "expected one of " + list + ", got '" + v + "'");
}

const std::vector<NdtKey>& ndtKeys() {
  using S = NdtSection;
  using namespace coloc::ndt;
  static const std::vector<NdtKey> keys = {
      {"backend", "", "pcl (stock pcl::NormalDistributionsTransform) or fast (coloc's aligner on PCL's voxel grid)",
       [](const S& s) { return std::string(s.source.ndt.backend == NdtBackend::kPcl ? "pcl" : "fast"); },
       [](const Context& c, const YAML::Node& n, const std::string& k, S& s) {
         s.source.ndt.backend = choice(c, n, k, {"pcl", "fast"}) == "pcl" ? NdtBackend::kPcl : NdtBackend::kFast; }},
      {"neighborhood", "", "fast backend voxels per point: radius (as PCL), face7 or single",
       [](const S& s) { return std::string(s.source.ndt.neighborhood == Neighborhood::kRadius ? "radius" : s.source.ndt.neighborhood == Neighborhood::kFace7 ? "face7" : "single"); },
       [](const Context& c, const YAML::Node& n, const std::string& k, S& s) {
         const std::string v = choice(c, n, k, {"radius", "face7", "single"});
         s.source.ndt.neighborhood = v == "radius" ? Neighborhood::kRadius : v == "face7" ? Neighborhood::kFace7 : Neighborhood::kSingle; }},
      {"resolution", "m", "NDT voxel size of the map", [](const S& s) { return show(s.source.ndt.resolution); },
       [](const Context& c, const YAML::Node& n, const std::string& k, S& s) { s.source.ndt.resolution = positive(c, n, k); }},
      {"step_size", "m", "longest Newton step", [](const S& s) { return show(s.source.ndt.step_size); },
       [](const Context& c, const YAML::Node& n, const std::string& k, S& s) { s.source.ndt.step_size = positive(c, n, k); }},
      {"transformation_epsilon", "m^2", "stop when the squared translation of a step is below this (PCL's meaning; Autoware's 0.01 is 1e-4 here)",
       [](const S& s) { return show(s.source.ndt.transformation_epsilon); },
       [](const Context& c, const YAML::Node& n, const std::string& k, S& s) { s.source.ndt.transformation_epsilon = positive(c, n, k); }},
      {"max_iterations", "", "iteration limit; a result that reaches it is rejected", [](const S& s) { return show(s.source.ndt.max_iterations); },
       [](const Context& c, const YAML::Node& n, const std::string& k, S& s) {
         s.source.ndt.max_iterations = c.read<int>(n, k, "an integer");
         if (s.source.ndt.max_iterations < 1) c.fail(n, k, "must be >= 1"); }},
      {"outlier_ratio", "", "share of points the score treats as outliers", [](const S& s) { return show(s.source.ndt.outlier_ratio); },
       [](const Context& c, const YAML::Node& n, const std::string& k, S& s) {
         s.source.ndt.outlier_ratio = c.readDouble(n, k);
         if (!(s.source.ndt.outlier_ratio > 0.0 && s.source.ndt.outlier_ratio < 1.0)) c.fail(n, k, "must be in (0, 1)"); }},
      {"threads", "", "fast backend threads; 0 = all cores", [](const S& s) { return show(s.source.ndt.threads); },
       [](const Context& c, const YAML::Node& n, const std::string& k, S& s) {
         s.source.ndt.threads = c.read<int>(n, k, "an integer");
         if (s.source.ndt.threads < 0) c.fail(n, k, "must be >= 0"); }},
      {"nvtl_threshold", "", "results with a lower nearest-voxel transformation likelihood are rejected", [](const S& s) { return show(s.source.ndt.nvtl_threshold); },
       [](const Context& c, const YAML::Node& n, const std::string& k, S& s) { s.source.ndt.nvtl_threshold = c.readDouble(n, k); }},
      {"max_oscillations", "", "steps reversing direction before a result is rejected", [](const S& s) { return show(s.source.ndt.max_oscillations); },
       [](const Context& c, const YAML::Node& n, const std::string& k, S& s) { s.source.ndt.max_oscillations = c.read<int>(n, k, "an integer"); }},
      {"covariance", "", "fixed (Autoware's matrix) or laplace (-H^-1 at the optimum, floored at the fixed one)",
       [](const S& s) { return std::string(s.source.ndt.covariance == CovarianceMode::kFixed ? "fixed" : "laplace"); },
       [](const Context& c, const YAML::Node& n, const std::string& k, S& s) {
         s.source.ndt.covariance = choice(c, n, k, {"fixed", "laplace"}) == "fixed" ? CovarianceMode::kFixed : CovarianceMode::kLaplace; }},
      {"fixed_covariance", "m^2, rad^2", "variances x, y, z, roll, pitch, yaw of the fixed covariance", [](const S& s) { return yamlList(s.source.ndt.fixed_covariance); },
       [](const Context& c, const YAML::Node& n, const std::string& k, S& s) { s.source.ndt.fixed_covariance = readVariances(c, n, k); }},
      {"min_range", "m", "scan points closer than this are dropped (the vehicle itself)", [](const S& s) { return show(s.source.preprocess.min_range); },
       [](const Context& c, const YAML::Node& n, const std::string& k, S& s) { s.source.preprocess.min_range = c.readDouble(n, k); }},
      {"max_range", "m", "scan points farther than this are dropped", [](const S& s) { return show(s.source.preprocess.max_range); },
       [](const Context& c, const YAML::Node& n, const std::string& k, S& s) { s.source.preprocess.max_range = positive(c, n, k); }},
      {"deskew", "", "undo the vehicle's motion during the sweep (needs per-point times)", [](const S& s) { return std::string(s.source.preprocess.deskew ? "true" : "false"); },
       [](const Context& c, const YAML::Node& n, const std::string& k, S& s) { s.source.preprocess.deskew = c.read<bool>(n, k, "true or false"); }},
      {"voxel_size", "m", "scan downsampling before NDT; 0 = off", [](const S& s) { return show(s.source.preprocess.voxel_size); },
       [](const Context& c, const YAML::Node& n, const std::string& k, S& s) { s.source.preprocess.voxel_size = c.readDouble(n, k); }},
      {"max_points", "", "at most this many scan points reach NDT (a repeatable random subset); 0 = all", [](const S& s) { return show(s.source.preprocess.max_points); },
       [](const Context& c, const YAML::Node& n, const std::string& k, S& s) { s.source.preprocess.max_points = c.read<std::size_t>(n, k, "an integer >= 0"); }},
      {"lidar_pose", "m, rad", "the LiDAR on the vehicle: x, y, z, roll, pitch, yaw", [](const S& s) {
         std::string t = "[";
         for (int i = 0; i < 6; ++i) t += (i ? ", " : "") + yamlNumber(s.source.lidar_pose[i]);
         return t + "]"; },
       [](const Context& c, const YAML::Node& n, const std::string& k, S& s) {
         if (!n.IsSequence() || n.size() != 6) c.fail(n, k, "expected 6 numbers [x, y, z, roll, pitch, yaw]");
         for (int i = 0; i < 6; ++i) s.source.lidar_pose[i] = c.readDouble(n[i], k); }},
      {"map_tile_size", "m", "a single-file map is cut into squares of this size", [](const S& s) { return show(s.map_tile_size); },
       [](const Context& c, const YAML::Node& n, const std::string& k, S& s) { s.map_tile_size = positive(c, n, k); }},
      {"map_radius", "m", "map tiles within this of the vehicle make the NDT target", [](const S& s) { return show(s.source.map.radius); },
       [](const Context& c, const YAML::Node& n, const std::string& k, S& s) { s.source.map.radius = positive(c, n, k); }},
      {"map_update_distance", "m", "travel before the target is rebuilt around the vehicle", [](const S& s) { return show(s.source.map.update_distance); },
       [](const Context& c, const YAML::Node& n, const std::string& k, S& s) { s.source.map.update_distance = positive(c, n, k); }},
  };
  return keys;
}

void readNdt(const Context& ctx, const YAML::Node& node, NdtSection& ndt) {
  requireMap(ctx, node, "ndt");
  for (const auto& entry : node) {
    const std::string key = entry.first.as<std::string>();
    const NdtKey* found = nullptr;
    for (const NdtKey& k : ndtKeys())
      if (key == k.key) found = &k;
    if (!found) ctx.fail(entry.first, "ndt." + key, "unknown key (see `coloc config`)");
    found->set(ctx, entry.second, "ndt." + key, ndt);
  }
}

}  // namespace

FuseConfig parseFuseConfig(const std::string& yaml_text, const std::string& source_name) {
  const Context ctx(source_name);
  YAML::Node root;
  try {
    root = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw Error(source_name + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg);
  }
  FuseConfig config;
  if (root.IsNull()) return config;
  requireMap(ctx, root, "(top level)");
  for (const auto& entry : root) {
    const std::string key = entry.first.as<std::string>();
    if (key == "fusion") {
      readFusion(ctx, entry.second, config.fusion);
    } else if (key == "inputs") {
      if (entry.second.IsNull()) continue;
      requireMap(ctx, entry.second, "inputs");
      for (const auto& input : entry.second) {
        const std::string topic = input.first.as<std::string>();
        config.inputs[topic] = readInput(ctx, topic, input.second);
      }
    } else if (key == "replay") {
      readReplay(ctx, entry.second, config.replay);
    } else if (key == "ndt") {
      readNdt(ctx, entry.second, config.ndt);
    } else {
      ctx.fail(entry.first, key, "unknown section (fusion, ndt, inputs, replay)");
    }
  }
  std::set<std::string> sources;
  for (const auto& [topic, input] : config.inputs)
    if ((input.role == InputRole::kPose || input.role == InputRole::kTwist || input.role == InputRole::kScan) &&
        !sources.insert(input.source).second)
      throw Error(source_name + ": inputs." + topic + ".source: '" + input.source + "' is used by two inputs");
  return config;
}

FuseConfig loadFuseConfig(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open the config file");
  std::stringstream text;
  text << in.rdbuf();
  return parseFuseConfig(text.str(), path);
}

std::string defaultConfigYaml() {
  const FuseConfig defaults;
  std::ostringstream out;
  out << "# coloc configuration: every key with its default. Any key may be left out.\n"
         "# Generated by `coloc config`; the README's table documents each key.\n\n"
         "fusion:\n";
  for (const auto& p : fusion::ekfParams()) {
    out << "  # " << p.meaning;
    if (*p.unit) out << " [" << p.unit << "]";
    out << "\n  " << p.key << ": " << fusion::formatValue(p, defaults.fusion) << "\n";
  }
  out << "\n# Scan matching of a PointCloud2 topic against the map given with `coloc fuse --map`.\nndt:\n";
  for (const auto& k : ndtKeys()) {
    out << "  # " << k.meaning;
    if (*k.unit) out << " [" << k.unit << "]";
    out << "\n  " << k.key << ": " << k.get(defaults.ndt) << "\n";
  }
  out << "\n# How log topics feed the filter. Topics not listed here are chosen by message type:\n"
         "# PoseWithCovarianceStamped -> pose; TwistWithCovarianceStamped, Odometry, Imu -> twist;\n"
         "# Odometry on a topic whose name contains \"ground_truth\" -> ground truth; others are listed and skipped.\n"
         "# Example:\n"
         "#   /amcl_pose: {role: pose, source: amcl}\n"
         "#   /odom: {role: twist, covariance_diagonal: [0.01, .inf, .inf, .inf, .inf, 0.0025]}\n"
         "#   /rsu/rsu_a/fix: {role: pose, link: {delay: 0.03, jitter: 0.005, loss: 0.2, seed: 1}}\n"
         "inputs: {}\n\nreplay:\n";
  for (const auto& k : replayKeys()) {
    out << "  # " << k.meaning;
    if (*k.unit) out << " [" << k.unit << "]";
    out << "\n  " << k.key << ": " << k.value(defaults.replay) << "\n";
  }
  return out.str();
}

std::string configReferenceMarkdown() {
  const FuseConfig defaults;
  std::ostringstream out;
  out << "| key | default | unit | meaning |\n|---|---|---|---|\n";
  for (const auto& p : fusion::ekfParams())
    out << "| `fusion." << p.key << "` | `" << fusion::formatValue(p, defaults.fusion) << "` | " << p.unit << " | "
        << p.meaning << " |\n";
  for (const auto& k : ndtKeys())
    out << "| `ndt." << k.key << "` | `" << k.get(defaults.ndt) << "` | " << k.unit << " | " << k.meaning << " |\n";
  out << "| `inputs.TOPIC.role` | by type | | `pose`, `twist`, `ground_truth`, `scan` (PointCloud2 for NDT) or `ignore` |\n"
         "| `inputs.TOPIC.source` | the topic | | the source's name in the filter and the summary |\n"
         "| `inputs.TOPIC.covariance_diagonal` | from the message | variances | 6 values replacing the message's covariance; `.inf` = not measured |\n"
         "| `inputs.TOPIC.additional_delay` | `0` | s | the data was sensed this long before its stamp |\n"
         "| `inputs.TOPIC.link` | none | | replay the topic through an emulated link: `{delay, jitter, loss, burst, p_good_to_bad, "
         "p_bad_to_good, loss_in_good, loss_in_bad, seed}` (s, probabilities); deterministic |\n";
  for (const auto& k : replayKeys())
    out << "| `replay." << k.key << "` | `" << k.value(defaults.replay) << "` | " << k.unit << " | " << k.meaning << " |\n";
  return out.str();
}

}  // namespace coloc::tools
