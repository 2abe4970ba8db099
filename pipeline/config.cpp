#include "coloc/pipeline/config.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <filesystem>
#include <set>
#include <sstream>
#include <type_traits>

#include "coloc/core/error.hpp"
#include "coloc/core/number_text.hpp"
#include "coloc/core/yaml_reader.hpp"
#include "coloc/fusion/ekf_params.hpp"
#include "coloc/fusion/localizer.hpp"
#include "coloc/io/ros_messages.hpp"

namespace coloc::pipeline {

const char* toString(InputRole role) {
  switch (role) {
    case InputRole::kPose: return "pose";
    case InputRole::kTwist: return "twist";
    case InputRole::kGroundTruth: return "ground_truth";
    case InputRole::kScan: return "scan";
    case InputRole::kRsuFix: return "rsu_fix";
    case InputRole::kStaticTransforms: return "tf_static";
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

std::string yamlNumber(double v) {
  if (v == kInfinity) return ".inf";
  if (v == -kInfinity) return "-.inf";
  return exactNumberText(v);
}

template <typename Vector>
std::string yamlList(const Vector& v) {
  std::string s = "[";
  for (int i = 0; i < static_cast<int>(v.size()); ++i) s += (i ? ", " : "") + yamlNumber(v[i]);
  return s + "]";
}

template <typename T>
std::string show(T v) {
  std::string text;
  if constexpr (std::is_floating_point_v<T>) {
    text = std::isinf(v) ? (v > 0 ? ".inf" : "-.inf") : exactNumberText(v);
    if (text.find_first_of(".eEn") == std::string::npos) text += ".0";
  } else {
    std::ostringstream out;
    out << v;
    text = out.str();
  }
  return text;
}

std::string quoted(const std::string& s) { return s.empty() ? std::string("null") : "\"" + s + "\""; }

void readFusion(const YamlReader& r, const YAML::Node& node, fusion::EkfConfig& config) {
  r.requireMap(node, "fusion");
  for (const auto& entry : node) {
    const std::string key = r.key(entry.first);
    const fusion::EkfParam* param = nullptr;
    for (const auto& p : fusion::ekfParams())
      if (key == p.key) param = &p;
    if (!param) r.fail(entry.first, "fusion." + key, "unknown key (see `coloc config` for the valid ones)");
    const std::string full = "fusion." + key;
    if (const auto* d = std::get_if<double fusion::EkfConfig::*>(&param->field)) {
      config.*(*d) = r.number(entry.second, full);
    } else if (const auto* i = std::get_if<int fusion::EkfConfig::*>(&param->field)) {
      config.*(*i) = static_cast<int>(r.integer(entry.second, full, std::numeric_limits<int>::min(), std::numeric_limits<int>::max()));
    } else {
      config.*std::get<bool fusion::EkfConfig::*>(param->field) = r.flag(entry.second, full);
    }
  }
  try {
    fusion::Localizer probe(config);  // the filter's own range checks, reported against the file
  } catch (const Error& e) {
    r.fail(node, "fusion", e.what());
  }
}

Vector6d readVariances(const YamlReader& r, const YAML::Node& node, const std::string& key) {
  const std::vector<double> v =
      r.numbers(node, key, 6, "6 variances [x, y, z, roll, pitch, yaw] or [vx, vy, vz, wx, wy, wz]; .inf = not measured");
  for (int i = 0; i < 6; ++i)
    if (!(v[i] > 0.0)) r.fail(node[i], key, "variances must be > 0 (.inf for not measured)");
  return Eigen::Map<const Vector6d>(v.data());
}

rsu_client::LinkConfig readLink(const YamlReader& r, const YAML::Node& node, const std::string& where) {
  r.allowKeys(node, where, {"delay", "jitter", "loss", "burst", "p_good_to_bad", "p_bad_to_good", "loss_in_good", "loss_in_bad", "seed"});
  rsu_client::LinkConfig link;
  for (const auto& entry : node) {
    const std::string key = r.key(entry.first);
    const std::string full = where + "." + key;
    const YAML::Node& v = entry.second;
    if (key == "delay") link.delay = r.inRange(v, full, 0.0, 10.0);
    else if (key == "jitter") link.jitter = r.inRange(v, full, 0.0, 10.0);
    else if (key == "loss") link.loss = r.probability(v, full);
    else if (key == "burst") link.burst = r.flag(v, full);
    else if (key == "p_good_to_bad") link.p_good_to_bad = r.probability(v, full);
    else if (key == "p_bad_to_good") link.p_bad_to_good = r.probability(v, full);
    else if (key == "loss_in_good") link.loss_in_good = r.probability(v, full);
    else if (key == "loss_in_bad") link.loss_in_bad = r.probability(v, full);
    else link.seed = static_cast<std::uint64_t>(r.integer(v, full, 0, std::numeric_limits<long long>::max()));
  }
  return link;
}

InputConfig readInput(const YamlReader& r, const std::string& topic, const YAML::Node& node) {
  const std::string where = "inputs." + topic;
  r.allowKeys(node, where, {"role", "source", "covariance_diagonal", "additional_delay", "link"});
  InputConfig input;
  bool has_role = false;
  for (const auto& entry : node) {
    const std::string key = r.key(entry.first);
    const std::string full = where + "." + key;
    if (key == "role") {
      const std::string role = r.choice(entry.second, full, {"pose", "twist", "ground_truth", "scan", "rsu_fix", "tf_static", "ignore"});
      for (InputRole candidate : {InputRole::kPose, InputRole::kTwist, InputRole::kGroundTruth, InputRole::kScan, InputRole::kRsuFix,
                                  InputRole::kStaticTransforms, InputRole::kIgnore})
        if (role == toString(candidate)) input.role = candidate;
      has_role = true;
    } else if (key == "source") {
      input.source = r.text(entry.second, full);
    } else if (key == "covariance_diagonal") {
      input.covariance_diagonal = readVariances(r, entry.second, full);
    } else if (key == "additional_delay") {
      input.additional_delay = r.inRange(entry.second, full, 0.0, 10.0);
    } else {
      input.link = readLink(r, entry.second, full);
    }
  }
  if (!has_role) r.fail(node, where, "needs a role: pose, twist, ground_truth, scan, rsu_fix, tf_static or ignore");
  if (input.source.empty()) input.source = topic;
  return input;
}

// The keys of the plain sections, one row each: reader and writer side by side so that they cannot
// drift apart, and the documentation beside them.
struct Key {
  const char* section;
  const char* key;
  const char* unit;
  const char* meaning;
  std::string (*get)(const Config&);
  void (*set)(const YamlReader&, const YAML::Node&, const std::string&, Config&);
};

using R = YamlReader;
using N = YAML::Node;
using S = std::string;
using C = Config;

const std::vector<Key>& keys() {
  using namespace coloc::ndt;
  static const std::vector<Key> table = {
      // ---- ndt: types here; ranges are ndt's own checks (ndt::validate)
      {"ndt", "backend", "", "pcl (stock pcl::NormalDistributionsTransform) or fast (coloc's aligner on a hashed voxel grid with PCL's voxel statistics)",
       [](const C& c) { return S(c.ndt.source.ndt.backend == NdtBackend::kPcl ? "pcl" : "fast"); },
       [](const R& r, const N& n, const S& k, C& c) { c.ndt.source.ndt.backend = r.choice(n, k, {"pcl", "fast"}) == "pcl" ? NdtBackend::kPcl : NdtBackend::kFast; }},
      {"ndt", "neighborhood", "", "fast backend voxels per point: radius (as PCL), face7 or single",
       [](const C& c) { const auto h = c.ndt.source.ndt.neighborhood; return S(h == Neighborhood::kRadius ? "radius" : h == Neighborhood::kFace7 ? "face7" : "single"); },
       [](const R& r, const N& n, const S& k, C& c) {
         const S v = r.choice(n, k, {"radius", "face7", "single"});
         c.ndt.source.ndt.neighborhood = v == "radius" ? Neighborhood::kRadius : v == "face7" ? Neighborhood::kFace7 : Neighborhood::kSingle; }},
      {"ndt", "resolution", "m", "NDT voxel size of the map", [](const C& c) { return show(c.ndt.source.ndt.resolution); },
       [](const R& r, const N& n, const S& k, C& c) { c.ndt.source.ndt.resolution = r.number(n, k); }},
      {"ndt", "step_size", "m", "first trust-region radius (Autoware's longest step); it grows while steps succeed", [](const C& c) { return show(c.ndt.source.ndt.step_size); },
       [](const R& r, const N& n, const S& k, C& c) { c.ndt.source.ndt.step_size = r.number(n, k); }},
      {"ndt", "transformation_epsilon", "m^2", "stop when the squared translation of a step is below this (PCL's meaning; Autoware's 0.01 is 1e-4 here)",
       [](const C& c) { return show(c.ndt.source.ndt.transformation_epsilon); },
       [](const R& r, const N& n, const S& k, C& c) { c.ndt.source.ndt.transformation_epsilon = r.number(n, k); }},
      {"ndt", "max_iterations", "", "iteration limit; a result that reaches it is rejected", [](const C& c) { return show(c.ndt.source.ndt.max_iterations); },
       [](const R& r, const N& n, const S& k, C& c) { c.ndt.source.ndt.max_iterations = static_cast<int>(r.integer(n, k, -1000000, 1000000)); }},
      {"ndt", "outlier_ratio", "", "share of points the score treats as outliers", [](const C& c) { return show(c.ndt.source.ndt.outlier_ratio); },
       [](const R& r, const N& n, const S& k, C& c) { c.ndt.source.ndt.outlier_ratio = r.number(n, k); }},
      {"ndt", "threads", "", "fast backend threads; 0 = all cores", [](const C& c) { return show(c.ndt.source.ndt.threads); },
       [](const R& r, const N& n, const S& k, C& c) { c.ndt.source.ndt.threads = static_cast<int>(r.integer(n, k, -1000000, 1000000)); }},
      {"ndt", "nvtl_threshold", "", "results with a lower nearest-voxel transformation likelihood are rejected", [](const C& c) { return show(c.ndt.source.ndt.nvtl_threshold); },
       [](const R& r, const N& n, const S& k, C& c) { c.ndt.source.ndt.nvtl_threshold = r.number(n, k); }},
      {"ndt", "max_oscillations", "", "steps reversing direction before a result is rejected", [](const C& c) { return show(c.ndt.source.ndt.max_oscillations); },
       [](const R& r, const N& n, const S& k, C& c) { c.ndt.source.ndt.max_oscillations = static_cast<int>(r.integer(n, k, -1000000, 1000000)); }},
      {"ndt", "covariance", "",
       "fixed (Autoware's matrix), laplace (-H^-1 at the optimum) or multi_ndt_score (Autoware's: the score's spread over poses offset along, across and about the heading); the last two floored at covariance_floor",
       [](const C& c) { return S(covarianceModeName(c.ndt.source.ndt.covariance)); },
       [](const R& r, const N& n, const S& k, C& c) {
         const S mode = r.choice(n, k, {"fixed", "laplace", "multi_ndt_score"});
         for (const CovarianceMode m : {CovarianceMode::kFixed, CovarianceMode::kLaplace, CovarianceMode::kMultiNdtScore})
           if (mode == covarianceModeName(m)) c.ndt.source.ndt.covariance = m; }},
      {"ndt", "score_temperature", "", "multi_ndt_score: softmax temperature on NVTL (an offset pose this much below the optimum weighs 1/e)",
       [](const C& c) { return show(c.ndt.source.ndt.score_temperature); },
       [](const R& r, const N& n, const S& k, C& c) { c.ndt.source.ndt.score_temperature = r.number(n, k); }},
      {"ndt", "score_yaw_offset_deg", "deg", "multi_ndt_score: yaw probes at +-1 and +-2 times this; 0 = x/y only (Autoware)",
       [](const C& c) { return show(c.ndt.source.ndt.score_yaw_offset_deg); },
       [](const R& r, const N& n, const S& k, C& c) { c.ndt.source.ndt.score_yaw_offset_deg = r.number(n, k); }},
      {"ndt", "fixed_covariance", "m^2, rad^2", "variances x, y, z, roll, pitch, yaw of the fixed covariance", [](const C& c) { return yamlList(c.ndt.source.ndt.fixed_covariance); },
       [](const R& r, const N& n, const S& k, C& c) { c.ndt.source.ndt.fixed_covariance = readVariances(r, n, k); }},
      {"ndt", "covariance_floor", "m^2, rad^2", "laplace and multi_ndt_score: each variance (x, y, z, roll, pitch, yaw) at least this", [](const C& c) { return yamlList(c.ndt.source.ndt.covariance_floor); },
       [](const R& r, const N& n, const S& k, C& c) { c.ndt.source.ndt.covariance_floor = readVariances(r, n, k); }},
      {"ndt", "quality_map", "",
       "NDT's mean square error by place, from a drive with a reference (the ndt_quality.yaml coloc fuse writes for a log with ground truth; relative to this file): each NDT pose's x/y variance at least its cell's; null = none",
       [](const C& c) { return quoted(c.ndt.quality_map); },
       [](const R& r, const N& n, const S& k, C& c) { c.ndt.quality_map = n.IsNull() ? S() : r.text(n, k); }},
      {"ndt", "quality_noise_by_direction", "",
       "where the filter's map-matching bias is loose, floor each NDT pose at the quality map's scan-to-scan noise along and across the vehicle (noise_along, noise_across) rather than its figure per axis",
       [](const C& c) { return S(c.ndt.quality_noise_by_direction ? "true" : "false"); },
       [](const R& r, const N& n, const S& k, C& c) { c.ndt.quality_noise_by_direction = r.flag(n, k); }},
      {"ndt", "quality_floor", "",
       "where nothing tells NDT's bias apart, floor each NDT pose at its place's whole error (error), or take it between its place's scan-to-scan noise (along, across, yaw) and its place's error by direction (noise: the bias followed, counted nowhere; also where it is loose)",
       [](const C& c) { return S(c.ndt.quality_floor); },
       [](const R& r, const N& n, const S& k, C& c) { c.ndt.quality_floor = r.choice(n, k, {"error", "noise"}); }},
      {"ndt", "min_range", "m", "scan points closer than this are dropped (the vehicle itself)", [](const C& c) { return show(c.ndt.source.preprocess.min_range); },
       [](const R& r, const N& n, const S& k, C& c) { c.ndt.source.preprocess.min_range = r.number(n, k); }},
      {"ndt", "max_range", "m", "scan points farther than this are dropped", [](const C& c) { return show(c.ndt.source.preprocess.max_range); },
       [](const R& r, const N& n, const S& k, C& c) { c.ndt.source.preprocess.max_range = r.number(n, k); }},
      {"ndt", "deskew", "", "undo the vehicle's motion during the sweep (needs per-point times)", [](const C& c) { return S(c.ndt.source.preprocess.deskew ? "true" : "false"); },
       [](const R& r, const N& n, const S& k, C& c) { c.ndt.source.preprocess.deskew = r.flag(n, k); }},
      {"ndt", "voxel_size", "m", "scan downsampling before NDT; 0 = off", [](const C& c) { return show(c.ndt.source.preprocess.voxel_size); },
       [](const R& r, const N& n, const S& k, C& c) { c.ndt.source.preprocess.voxel_size = r.number(n, k); }},
      {"ndt", "max_points", "", "at most this many scan points reach NDT (a repeatable random subset); 0 = all", [](const C& c) { return show(c.ndt.source.preprocess.max_points); },
       [](const R& r, const N& n, const S& k, C& c) { c.ndt.source.preprocess.max_points = static_cast<std::size_t>(r.integer(n, k, 0, 1LL << 40)); }},
      {"ndt", "lidar_pose", "m, rad",
       "the LiDAR on the vehicle: x, y, z, roll, pitch, yaw; null = from a replayed log's /tf_static (base_frame to the scans' frame) when it has them, else the vehicle's origin",
       [](const C& c) { return c.ndt.lidar_pose_given ? yamlList(c.ndt.source.lidar_pose) : S("null"); },
       [](const R& r, const N& n, const S& k, C& c) {
         c.ndt.lidar_pose_given = !n.IsNull();
         if (n.IsNull()) {
           c.ndt.source.lidar_pose = Vector6d::Zero();
           return;
         }
         const auto v = r.numbers(n, k, 6, "6 numbers [x, y, z, roll, pitch, yaw]");
         c.ndt.source.lidar_pose = Eigen::Map<const Vector6d>(v.data()); }},
      {"ndt", "base_frame", "", "the vehicle's frame in a log's /tf_static: the LiDAR's pose is looked up from it (ndt.lidar_pose null)",
       [](const C& c) { return quoted(c.ndt.base_frame); },
       [](const R& r, const N& n, const S& k, C& c) {
         const S frame = r.text(n, k);
         if (frame.empty()) r.fail(n, k, "must name a frame");
         c.ndt.base_frame = frame; }},
      {"ndt", "map_tile_size", "m", "a single-file map is cut into squares of this size", [](const C& c) { return show(c.ndt.map_tile_size); },
       [](const R& r, const N& n, const S& k, C& c) { c.ndt.map_tile_size = r.positive(n, k); }},
      {"ndt", "map_radius", "m", "map tiles within this of the vehicle make the NDT target", [](const C& c) { return show(c.ndt.source.map.radius); },
       [](const R& r, const N& n, const S& k, C& c) { c.ndt.source.map.radius = r.number(n, k); }},
      {"ndt", "map_update_distance", "m", "travel before the target is rebuilt around the vehicle", [](const C& c) { return show(c.ndt.source.map.update_distance); },
       [](const R& r, const N& n, const S& k, C& c) { c.ndt.source.map.update_distance = r.number(n, k); }},
      // ---- rsu
      {"rsu", "registry", "", "RSU registry file (relative to this file); with it, fixes pass the registry's checks; null = none",
       [](const C& c) { return quoted(c.rsu.registry); },
       [](const R& r, const N& n, const S& k, C& c) { c.rsu.registry = n.IsNull() ? S() : r.text(n, k); }},
      {"rsu", "max_age", "s", "fixes older than this when they arrive are refused (stale)", [](const C& c) { return show(c.rsu.checks.max_age); },
       [](const R& r, const N& n, const S& k, C& c) { c.rsu.checks.max_age = r.inRange(n, k, 0.001, 60.0); }},
      {"rsu", "future_tolerance", "s", "fixes stamped further than this after their arrival are refused (from_future)",
       [](const C& c) { return show(c.rsu.checks.future_tolerance); },
       [](const R& r, const N& n, const S& k, C& c) { c.rsu.checks.future_tolerance = r.inRange(n, k, 0.0, 10.0); }},
      {"rsu", "station_id", "", "this vehicle's station id (its CAM's): only fixes addressed to it are taken; null = none, every addressed fix is another's",
       [](const C& c) { return c.rsu.checks.station_id ? std::to_string(*c.rsu.checks.station_id) : S("null"); },
       [](const R& r, const N& n, const S& k, C& c) {
         if (n.IsNull()) return c.rsu.checks.station_id.reset();
         c.rsu.checks.station_id = static_cast<std::uint32_t>(r.integer(n, k, 0, 4294967295LL)); }},
      {"rsu", "accept_unaddressed", "", "take fixes that name no vehicle (/rsu/<id>/fix): only where the RSU sees one connected vehicle",
       [](const C& c) { return S(c.rsu.checks.accept_unaddressed ? "true" : "false"); },
       [](const R& r, const N& n, const S& k, C& c) { c.rsu.checks.accept_unaddressed = r.flag(n, k); }},
      {"rsu", "smoothing_steps", "ticks", "each fix is applied over this many ticks, each with covariance x steps; 0 = fusion.pose_smoothing_steps",
       [](const C& c) { return show(c.rsu.smoothing_steps); },
       [](const R& r, const N& n, const S& k, C& c) { c.rsu.smoothing_steps = static_cast<int>(r.integer(n, k, 0, 50)); }},
      {"rsu", "vehicle_length", "m", "this vehicle's own length, bumper to bumper: fixes corrected for its CAM's rounding of it (with vehicle_width); 0 = as sent",
       [](const C& c) { return show(c.rsu.vehicle_length); },
       [](const R& r, const N& n, const S& k, C& c) { c.rsu.vehicle_length = r.inRange(n, k, 0.0, 30.0); }},
      {"rsu", "vehicle_width", "m", "this vehicle's own width without mirrors (with vehicle_length); 0 = as sent",
       [](const C& c) { return show(c.rsu.vehicle_width); },
       [](const R& r, const N& n, const S& k, C& c) { c.rsu.vehicle_width = r.inRange(n, k, 0.0, 5.0); }},
      {"rsu", "cam_size_step", "m", "the step the CAM sends length and width in (ETSI EN 302 637-2: 0.1)",
       [](const C& c) { return show(c.rsu.cam_size_step); },
       [](const R& r, const N& n, const S& k, C& c) { c.rsu.cam_size_step = r.inRange(n, k, 0.001, 1.0); }},
      {"rsu", "cam_length", "m", "the length this vehicle's CAMs send, where its V2X stack rounds otherwise than to the nearest cam_size_step; 0 = rounded to the nearest",
       [](const C& c) { return show(c.rsu.cam_length); },
       [](const R& r, const N& n, const S& k, C& c) { c.rsu.cam_length = r.inRange(n, k, 0.0, 102.2); }},
      {"rsu", "cam_width", "m", "the width this vehicle's CAMs send (as cam_length); 0 = rounded to the nearest cam_size_step",
       [](const C& c) { return show(c.rsu.cam_width); },
       [](const R& r, const N& n, const S& k, C& c) { c.rsu.cam_width = r.inRange(n, k, 0.0, 6.1); }},
      // ---- pipeline
      {"pipeline", "initial_pose", "m, rad", "[x, y, z, yaw] to start the filter at the first input (NDT needs a first guess); null = from the first full pose",
       [](const C& c) { return c.pipeline.initial_pose ? yamlList(*c.pipeline.initial_pose) : S("null"); },
       [](const R& r, const N& n, const S& k, C& c) {
         if (n.IsNull()) return c.pipeline.initial_pose.reset();
         const auto v = r.numbers(n, k, 4, "[x, y, z, yaw]");
         for (int i = 0; i < 4; ++i)
           if (!std::isfinite(v[i])) r.fail(n[i], k, "must be finite");
         c.pipeline.initial_pose = Eigen::Vector4d(v[0], v[1], v[2], v[3]); }},
      {"pipeline", "start_check_radii", "m", "a pose given by hand is held against the map at the next scan: NDT also starts from rings of these radii around it; [] = no check",
       [](const C& c) { return yamlList(c.pipeline.start_check_radii); },
       [](const R& r, const N& n, const S& k, C& c) { c.pipeline.start_check_radii = n.IsSequence() && n.size() == 0 ? std::vector<double>{} : r.numberList(n, k, 0.1, 50.0); }},
      {"pipeline", "start_check_margin", "NVTL", "a match that much better (and more than 1 m away) makes the filter degraded until an RSU's fix agrees",
       [](const C& c) { return show(c.pipeline.start_check_margin); },
       [](const R& r, const N& n, const S& k, C& c) { c.pipeline.start_check_margin = r.inRange(n, k, 0.0, 10.0); }},
      {"pipeline", "start_check_interval", "s", "the check is made again this often until an RSU's fix agrees with the filter",
       [](const C& c) { return show(c.pipeline.start_check_interval); },
       [](const R& r, const N& n, const S& k, C& c) { c.pipeline.start_check_interval = r.inRange(n, k, 0.1, 3600.0); }},
      {"pipeline", "start_check_duration", "s", "... for this long after the start (over a whole drive, a better match elsewhere turns up by chance)",
       [](const C& c) { return show(c.pipeline.start_check_duration); },
       [](const R& r, const N& n, const S& k, C& c) { c.pipeline.start_check_duration = r.inRange(n, k, 0.0, 86400.0); }},
      {"pipeline", "speed_scale_estimation", "", "learn the odometry's speed scale (wheel radius error) from NDT's poses and correct twists by it",
       [](const C& c) { return S(c.pipeline.speed_scale_estimation ? "true" : "false"); },
       [](const R& r, const N& n, const S& k, C& c) { c.pipeline.speed_scale_estimation = r.flag(n, k); }},
      {"pipeline", "speed_scale_memory", "m", "travel over which old comparisons of NDT and odometry distance fade to 1/e",
       [](const C& c) { return show(c.pipeline.speed_scale_memory); },
       [](const R& r, const N& n, const S& k, C& c) { c.pipeline.speed_scale_memory = r.inRange(n, k, 10.0, 1e6); }},
      {"pipeline", "speed_scale_min_distance", "m", "odometry travel compared with NDT's before the learned scale is used (one 5 m chord by default)",
       [](const C& c) { return show(c.pipeline.speed_scale_min_distance); },
       [](const R& r, const N& n, const S& k, C& c) { c.pipeline.speed_scale_min_distance = r.inRange(n, k, 5.0, 1e6); }},
      {"pipeline", "speed_scale_uncertainty", "", "add the learned speed scale's doubt to each twist's speed variance ((sd vx)^2; 2 % until the scale is usable)",
       [](const C& c) { return S(c.pipeline.speed_scale_uncertainty ? "true" : "false"); },
       [](const R& r, const N& n, const S& k, C& c) { c.pipeline.speed_scale_uncertainty = r.flag(n, k); }},
      {"pipeline", "travel_check_window", "s", "each NDT pose's chord from the pose this long before is held against the odometry's travel; the disagreement beyond the tolerance is added to its covariance; 0 = off",
       [](const C& c) { return show(c.pipeline.travel_check_window); },
       [](const R& r, const N& n, const S& k, C& c) { c.pipeline.travel_check_window = r.inRange(n, k, 0.0, 2.0); }},
      {"pipeline", "fix_agreement_window", "s", "each NDT pose is held against the roadside fixes of this many seconds around it; their median disagreement beyond the tolerance is added to its covariance; 0 = off",
       [](const C& c) { return show(c.pipeline.fix_agreement_window); },
       [](const R& r, const N& n, const S& k, C& c) { c.pipeline.fix_agreement_window = r.inRange(n, k, 0.0, 10.0); }},
      {"pipeline", "fix_agreement_tolerance", "m", "the disagreement between NDT and the fixes that their noise and the RSU's survey explain",
       [](const C& c) { return show(c.pipeline.fix_agreement_tolerance); },
       [](const R& r, const N& n, const S& k, C& c) { c.pipeline.fix_agreement_tolerance = r.inRange(n, k, 0.0, 10.0); }},
      {"pipeline", "travel_check_turn_tolerance", "rad", "each chord's turn held against the yaw rate's: a disagreement beyond this (and 0.002 rad/s of the chord) is added, whole, to the pose's yaw variance; 0 = off",
       [](const C& c) { return show(c.pipeline.travel_check_turn_tolerance); },
       [](const R& r, const N& n, const S& k, C& c) { c.pipeline.travel_check_turn_tolerance = r.inRange(n, k, 0.0, 1.0); }},
      {"pipeline", "travel_check_tolerance", "m", "the disagreement that NDT's and the odometry's noise explain over one chord",
       [](const C& c) { return show(c.pipeline.travel_check_tolerance); },
       [](const R& r, const N& n, const S& k, C& c) { c.pipeline.travel_check_tolerance = r.inRange(n, k, 0.0, 10.0); }},
      {"pipeline", "travel_check_tolerance_per_metre", "m/m", "... and this much more per metre of the chord (the speed scale's uncertainty)",
       [](const C& c) { return show(c.pipeline.travel_check_tolerance_per_metre); },
       [](const R& r, const N& n, const S& k, C& c) { c.pipeline.travel_check_tolerance_per_metre = r.inRange(n, k, 0.0, 1.0); }},
      {"pipeline", "travel_check_unverified_sd", "m", "an NDT pose with no chord to compare yet (the first window after a start) is taken at no better than this, in x and y",
       [](const C& c) { return show(c.pipeline.travel_check_unverified_sd); },
       [](const R& r, const N& n, const S& k, C& c) { c.pipeline.travel_check_unverified_sd = r.inRange(n, k, 0.0, 100.0); }},
      {"pipeline", "yaw_rate_bias_estimation", "", "learn the odometry's yaw-rate bias (gyro) from NDT's heading changes and remove it from twists",
       [](const C& c) { return S(c.pipeline.yaw_rate_bias_estimation ? "true" : "false"); },
       [](const R& r, const N& n, const S& k, C& c) { c.pipeline.yaw_rate_bias_estimation = r.flag(n, k); }},
      {"pipeline", "yaw_rate_bias_memory", "s", "time over which old comparisons of NDT and odometry heading change fade to 1/e",
       [](const C& c) { return show(c.pipeline.yaw_rate_bias_memory); },
       [](const R& r, const N& n, const S& k, C& c) { c.pipeline.yaw_rate_bias_memory = r.inRange(n, k, 5.0, 1e6); }},
      {"pipeline", "mount_yaw_estimation", "", "learn the LiDAR's mounting yaw (NDT's heading minus the direction of travel) and correct NDT's poses by it",
       [](const C& c) { return S(c.pipeline.mount_yaw_estimation ? "true" : "false"); },
       [](const R& r, const N& n, const S& k, C& c) { c.pipeline.mount_yaw_estimation = r.flag(n, k); }},
      {"pipeline", "mount_yaw_memory", "m", "travel over which old comparisons of NDT's heading and its direction of travel fade to 1/e",
       [](const C& c) { return show(c.pipeline.mount_yaw_memory); },
       [](const R& r, const N& n, const S& k, C& c) { c.pipeline.mount_yaw_memory = r.inRange(n, k, 10.0, 1e6); }},
      // ---- messages
      {"messages", "zero_variance_is_unmeasured", "", "read a 0 variance in a message as +inf, as ROS drivers write 0 for what they do not estimate",
       [](const C& c) { return S(c.messages.zero_variance_is_unmeasured ? "true" : "false"); },
       [](const R& r, const N& n, const S& k, C& c) { c.messages.zero_variance_is_unmeasured = r.flag(n, k); }},
      {"messages", "fallback_pose_variance", "m^2, rad^2", "pose covariance diagonal for messages that carry none (Autoware's NDT value)",
       [](const C& c) { return yamlList(c.messages.fallback_pose_variance); },
       [](const R& r, const N& n, const S& k, C& c) { c.messages.fallback_pose_variance = readVariances(r, n, k); }},
      {"messages", "fallback_twist_variance", "(m/s)^2, (rad/s)^2", "twist covariance diagonal for messages that carry none (Autoware's 0.2 m/s, 0.1 rad/s)",
       [](const C& c) { return yamlList(c.messages.fallback_twist_variance); },
       [](const R& r, const N& n, const S& k, C& c) { c.messages.fallback_twist_variance = readVariances(r, n, k); }},
      // ---- replay
      {"replay", "clock", "", "auto, same or separate: are header stamps and log times on one clock? auto decides from the data",
       [](const C& c) { return S(toString(c.replay.clock)); },
       [](const R& r, const N& n, const S& k, C& c) {
         const S v = r.choice(n, k, {"auto", "same", "separate"});
         c.replay.clock = v == "auto" ? ClockMode::kAuto : v == "same" ? ClockMode::kSame : ClockMode::kSeparate; }},
      {"replay", "ground_truth_max_gap", "s", "ground truth is interpolated to the filter's ticks only across gaps up to this",
       [](const C& c) { return show(c.replay.ground_truth_max_gap); },
       [](const R& r, const N& n, const S& k, C& c) {
         c.replay.ground_truth_max_gap = r.inRange(n, k, 0.0, 10.0);
         if (c.replay.ground_truth_max_gap == 0.0) r.fail(n, k, "must be > 0"); }},
      {"replay", "input_stretch_length", "m", "each pose input beside the fused pose at its stamps: road per stretch when judging where the input is accurate",
       [](const C& c) { return show(c.replay.input_stretch_length); },
       [](const R& r, const N& n, const S& k, C& c) {
         c.replay.input_stretch_length = r.inRange(n, k, 0.0, 1e4);
         if (c.replay.input_stretch_length == 0.0) r.fail(n, k, "must be > 0"); }},
      {"replay", "input_accurate_below", "m", "a stretch where the input's mean planar error is below this counts as one where it is accurate",
       [](const C& c) { return show(c.replay.input_accurate_below); },
       [](const R& r, const N& n, const S& k, C& c) {
         c.replay.input_accurate_below = r.inRange(n, k, 0.0, 1e3);
         if (c.replay.input_accurate_below == 0.0) r.fail(n, k, "must be > 0"); }},
      {"replay", "input_reference", "",
       "an input_error.csv coloc fuse wrote for a reference drive over the same roads (relative to this file): each input also compared where it was accurate on that drive; null = none",
       [](const C& c) { return quoted(c.replay.input_reference); },
       [](const R& r, const N& n, const S& k, C& c) { c.replay.input_reference = n.IsNull() ? S() : r.text(n, k); }},
      // ---- smoother
      {"smoother", "estimate_noise", "", "measure each source's noise on the drive instead of taking the messages' covariances as given",
       [](const C& c) { return S(c.smoother.estimate_noise ? "true" : "false"); },
       [](const R& r, const N& n, const S& k, C& c) { c.smoother.estimate_noise = r.flag(n, k); }},
      {"smoother", "calibrate_odometry", "", "estimate each odometry's speed scale and yaw-rate bias with the trajectory",
       [](const C& c) { return S(c.smoother.calibrate_odometry ? "true" : "false"); },
       [](const R& r, const N& n, const S& k, C& c) { c.smoother.calibrate_odometry = r.flag(n, k); }},
      {"smoother", "odometry_scale_sd", "", "prior standard deviation of the odometry's speed scale around 1",
       [](const C& c) { return show(c.smoother.odometry_scale_sd); },
       [](const R& r, const N& n, const S& k, C& c) { c.smoother.odometry_scale_sd = r.inRange(n, k, 1e-6, 1.0); }},
      {"smoother", "odometry_yaw_rate_bias_sd", "rad/s", "prior standard deviation of the odometry's yaw-rate bias around 0",
       [](const C& c) { return show(c.smoother.odometry_yaw_rate_bias_sd); },
       [](const R& r, const N& n, const S& k, C& c) { c.smoother.odometry_yaw_rate_bias_sd = r.inRange(n, k, 1e-9, 1.0); }},
      {"smoother", "pose_bias", "", "model a slowly varying bias of map-matching poses (NDT): when_calibrating (RSUs), always or never",
       [](const C& c) {
         using P = SmootherSection::PoseBias;
         return S(c.smoother.pose_bias == P::kAlways ? "always" : c.smoother.pose_bias == P::kNever ? "never" : "when_calibrating"); },
       [](const R& r, const N& n, const S& k, C& c) {
         using P = SmootherSection::PoseBias;
         const S v = r.choice(n, k, {"when_calibrating", "always", "never"});
         c.smoother.pose_bias = v == "always" ? P::kAlways : v == "never" ? P::kNever : P::kWhenCalibrating; }},
      {"smoother", "pose_bias_time", "s", "correlation time of that bias",
       [](const C& c) { return show(c.smoother.pose_bias_time); },
       [](const R& r, const N& n, const S& k, C& c) { c.smoother.pose_bias_time = r.inRange(n, k, 0.05, 1e4); }},
      {"smoother", "proc_stddev_position_c", "m/s", "random walk of the position, which the filter's model moves without noise",
       [](const C& c) { return show(c.smoother.proc_stddev_position_c); },
       [](const R& r, const N& n, const S& k, C& c) { c.smoother.proc_stddev_position_c = r.inRange(n, k, 1e-9, 10.0); }},
      {"smoother", "proc_stddev_yaw_bias_c", "rad/s", "random walk of the yaw bias, likewise",
       [](const C& c) { return show(c.smoother.proc_stddev_yaw_bias_c); },
       [](const R& r, const N& n, const S& k, C& c) { c.smoother.proc_stddev_yaw_bias_c = r.inRange(n, k, 1e-12, 1.0); }},
      // ---- live
      {"live", "scan_topic", "", "PointCloud2 scans for NDT", [](const C& c) { return quoted(c.live.scan_topic); },
       [](const R& r, const N& n, const S& k, C& c) { c.live.scan_topic = r.text(n, k); }},
      {"live", "twist_topic", "", "the vehicle's twist", [](const C& c) { return quoted(c.live.twist_topic); },
       [](const R& r, const N& n, const S& k, C& c) { c.live.twist_topic = r.text(n, k); }},
      {"live", "twist_type", "", "its type: geometry_msgs/msg/TwistWithCovarianceStamped, nav_msgs/msg/Odometry or sensor_msgs/msg/Imu",
       [](const C& c) { return quoted(c.live.twist_type); },
       [](const R& r, const N& n, const S& k, C& c) {
         c.live.twist_type = r.choice(n, k, {"geometry_msgs/msg/TwistWithCovarianceStamped", "nav_msgs/msg/Odometry", "sensor_msgs/msg/Imu"}); }},
      {"live", "initial_pose_topic", "", "PoseWithCovarianceStamped that (re)starts the filter, as RViz's 2D Pose Estimate sends it",
       [](const C& c) { return quoted(c.live.initial_pose_topic); },
       [](const R& r, const N& n, const S& k, C& c) { c.live.initial_pose_topic = r.text(n, k); }},
      {"live", "pose_topic", "", "the fused pose out (PoseWithCovarianceStamped), every tick", [](const C& c) { return quoted(c.live.pose_topic); },
       [](const R& r, const N& n, const S& k, C& c) { c.live.pose_topic = r.text(n, k); }},
      {"live", "odometry_topic", "", "the fused pose and twist out (Odometry), every tick", [](const C& c) { return quoted(c.live.odometry_topic); },
       [](const R& r, const N& n, const S& k, C& c) { c.live.odometry_topic = r.text(n, k); }},
      {"live", "frame_id", "", "frame of the fused pose", [](const C& c) { return quoted(c.live.frame_id); },
       [](const R& r, const N& n, const S& k, C& c) { c.live.frame_id = r.text(n, k); }},
      {"live", "child_frame_id", "", "the vehicle's frame (Odometry's child frame)", [](const C& c) { return quoted(c.live.child_frame_id); },
       [](const R& r, const N& n, const S& k, C& c) { c.live.child_frame_id = r.text(n, k); }},
      {"live", "reliable", "", "reliable QoS on the inputs instead of ROS 2 sensor data (best effort)",
       [](const C& c) { return S(c.live.reliable ? "true" : "false"); },
       [](const R& r, const N& n, const S& k, C& c) { c.live.reliable = r.flag(n, k); }},
      {"live", "discover_inputs", "", "also take every topic published on the domain as `coloc fuse` takes a log's, by its type (inputs: names topics in any case)",
       [](const C& c) { return S(c.live.discover_inputs ? "true" : "false"); },
       [](const R& r, const N& n, const S& k, C& c) { c.live.discover_inputs = r.flag(n, k); }},
      {"live", "twist_out_topic", "", "the fused twist out (TwistWithCovarianceStamped); null: none", [](const C& c) { return quoted(c.live.twist_out_topic); },
       [](const R& r, const N& n, const S& k, C& c) { c.live.twist_out_topic = n.IsNull() ? S() : r.text(n, k); }},
      {"live", "biased_pose_topic", "", "the fused pose with the yaw as measured, before the yaw bias (NDT's initial guess in Autoware); null: none",
       [](const C& c) { return quoted(c.live.biased_pose_topic); },
       [](const R& r, const N& n, const S& k, C& c) { c.live.biased_pose_topic = n.IsNull() ? S() : r.text(n, k); }},
      {"live", "pose_stamped_topic", "", "the fused pose out as PoseStamped (what Autoware's monitors watch); null: none",
       [](const C& c) { return quoted(c.live.pose_stamped_topic); },
       [](const R& r, const N& n, const S& k, C& c) { c.live.pose_stamped_topic = n.IsNull() ? S() : r.text(n, k); }},
      {"live", "ndt_pose_topic", "", "NDT's own poses (PoseWithCovarianceStamped), as ndt_scan_matcher publishes them; null: none",
       [](const C& c) { return quoted(c.live.ndt_pose_topic); },
       [](const R& r, const N& n, const S& k, C& c) { c.live.ndt_pose_topic = n.IsNull() ? S() : r.text(n, k); }},
      {"live", "tf", "", "frame_id -> child_frame_id on /tf at every tick", [](const C& c) { return S(c.live.tf ? "true" : "false"); },
       [](const R& r, const N& n, const S& k, C& c) { c.live.tf = r.flag(n, k); }},
      {"live", "diagnostics", "", "/diagnostics (DiagnosticArray) with the filter's, NDT's and the inputs' state", [](const C& c) { return S(c.live.diagnostics ? "true" : "false"); },
       [](const R& r, const N& n, const S& k, C& c) { c.live.diagnostics = r.flag(n, k); }},
      {"live", "diagnostics_frequency", "Hz", "how often /diagnostics goes out", [](const C& c) { return show(c.live.diagnostics_frequency); },
       [](const R& r, const N& n, const S& k, C& c) { c.live.diagnostics_frequency = r.inRange(n, k, 0.1, 100.0); }},
      {"live", "start_activated", "", "outputs flow from the start; false: only once a trigger service activates the node (Autoware)",
       [](const C& c) { return S(c.live.start_activated ? "true" : "false"); },
       [](const R& r, const N& n, const S& k, C& c) { c.live.start_activated = r.flag(n, k); }},
      {"live", "ekf_trigger_service", "", "std_srvs/SetBool service that activates (true) or deactivates the node, where ekf_localizer's is; null: none",
       [](const C& c) { return quoted(c.live.ekf_trigger_service); },
       [](const R& r, const N& n, const S& k, C& c) { c.live.ekf_trigger_service = n.IsNull() ? S() : r.text(n, k); }},
      {"live", "ndt_trigger_service", "", "the same where ndt_scan_matcher's is (both must be on for outputs to flow); null: none",
       [](const C& c) { return quoted(c.live.ndt_trigger_service); },
       [](const R& r, const N& n, const S& k, C& c) { c.live.ndt_trigger_service = n.IsNull() ? S() : r.text(n, k); }},
      {"live", "align_service", "", "NDT's search around a pose (autoware_internal_localization_msgs/srv/PoseWithCovarianceStamped); null: none",
       [](const C& c) { return quoted(c.live.align_service); },
       [](const R& r, const N& n, const S& k, C& c) { c.live.align_service = n.IsNull() ? S() : r.text(n, k); }},
  };
  return table;
}

const char* kSections[] = {"ndt", "rsu", "pipeline", "messages", "replay", "smoother", "live"};

const char* sectionComment(const std::string& section) {
  if (section == "ndt") return "# Scan matching of PointCloud2 scans against the map given with --map.";
  if (section == "rsu") return "# Roadside fixes: the registry of trusted RSUs and the checks every fix passes (live and offline alike).";
  if (section == "pipeline") return "# The vehicle pipeline.";
  if (section == "messages") return "# How messages become measurements.";
  if (section == "replay") return "# Offline replay of recorded logs (coloc fuse).";
  if (section == "smoother") return "# The Ceres smoother of recorded logs (coloc smooth); rate, process noise and gate follow the fusion section.";
  return "# The live localizer's topics (coloc localize): ROS 2 names, DDS adds \"rt\".";
}

void readSection(const YamlReader& r, const std::string& section, const YAML::Node& node, Config& config) {
  r.requireMap(node, section);
  for (const auto& entry : node) {
    const std::string key = r.key(entry.first);
    const Key* found = nullptr;
    for (const Key& k : keys())
      if (section == k.section && key == k.key) found = &k;
    if (!found) r.fail(entry.first, section + "." + key, "unknown key (see `coloc config`)");
    found->set(r, entry.second, section + "." + key, config);
  }
}

}  // namespace

Config parseConfig(const std::string& yaml_text, const std::string& source_name) {
  const YamlReader r(source_name);
  const YAML::Node root = r.parse(yaml_text);
  Config config;
  if (root.IsNull()) return config;
  r.requireMap(root, "(top level)");
  for (const auto& entry : root) {
    const std::string key = r.key(entry.first);
    if (key == "fusion") {
      readFusion(r, entry.second, config.fusion);
    } else if (key == "inputs") {
      if (entry.second.IsNull()) continue;
      r.requireMap(entry.second, "inputs");
      for (const auto& input : entry.second) {
        const std::string topic = r.key(input.first);
        config.inputs[topic] = readInput(r, topic, input.second);
      }
    } else if (std::find(std::begin(kSections), std::end(kSections), key) != std::end(kSections)) {
      if (!entry.second.IsNull()) readSection(r, key, entry.second, config);
      if (key == "ndt") {
        try {
          ndt::validate(config.ndt.source);
        } catch (const Error& e) {
          r.fail(entry.second, "ndt", e.what());
        }
      }
    } else {
      r.fail(entry.first, key, "unknown section (fusion, ndt, rsu, pipeline, messages, inputs, replay, live)");
    }
  }
  std::set<std::string> sources;
  for (const auto& [topic, input] : config.inputs)
    if ((input.role == InputRole::kPose || input.role == InputRole::kTwist || input.role == InputRole::kScan) &&
        !sources.insert(input.source).second)
      throw Error(source_name + ": inputs." + topic + ".source: '" + input.source + "' is used by two inputs");
  return config;
}

Config loadConfig(const std::string& path) {
  Config config = parseConfig(YamlReader::readFile(path, "config file"), path);
  namespace fs = std::filesystem;
  if (!config.rsu.registry.empty() && fs::path(config.rsu.registry).is_relative())
    config.rsu.registry = (fs::path(path).parent_path() / config.rsu.registry).lexically_normal().string();
  if (!config.ndt.quality_map.empty() && fs::path(config.ndt.quality_map).is_relative())
    config.ndt.quality_map = (fs::path(path).parent_path() / config.ndt.quality_map).lexically_normal().string();
  if (!config.replay.input_reference.empty() && fs::path(config.replay.input_reference).is_relative())
    config.replay.input_reference = (fs::path(path).parent_path() / config.replay.input_reference).lexically_normal().string();
  return config;
}

namespace {

// One input as a flow map, every field the reader takes.
std::string inputYaml(const InputConfig& in) {
  std::ostringstream out;
  out << "{role: " << toString(in.role);
  if (!in.source.empty()) out << ", source: \"" << in.source << "\"";  // empty: the topic's name
  if (in.covariance_diagonal) out << ", covariance_diagonal: " << yamlList(*in.covariance_diagonal);
  if (in.additional_delay != 0.0) out << ", additional_delay: " << show(in.additional_delay);
  if (const auto& l = in.link)
    out << ", link: {delay: " << show(l->delay) << ", jitter: " << show(l->jitter) << ", loss: " << show(l->loss)
        << ", burst: " << (l->burst ? "true" : "false") << ", p_good_to_bad: " << show(l->p_good_to_bad) << ", p_bad_to_good: " << show(l->p_bad_to_good)
        << ", loss_in_good: " << show(l->loss_in_good) << ", loss_in_bad: " << show(l->loss_in_bad) << ", seed: " << l->seed << "}";
  return out.str() + "}";
}

}  // namespace

std::string configYaml(const Config& config, const std::string& heading) {
  std::ostringstream out;
  out << heading << "fusion:\n";
  for (const auto& p : fusion::ekfParams()) {
    out << "  # " << p.meaning;
    if (*p.unit) out << " [" << p.unit << "]";
    out << "\n  " << p.key << ": " << fusion::formatValue(p, config.fusion) << "\n";
  }
  for (const char* section : kSections) {
    out << "\n" << sectionComment(section) << "\n" << section << ":\n";
    for (const Key& k : keys()) {
      if (std::string(k.section) != section) continue;
      out << "  # " << k.meaning;
      if (*k.unit) out << " [" << k.unit << "]";
      out << "\n  " << k.key << ": " << k.get(config) << "\n";
    }
    if (std::string(section) == "messages") {
      out << "\n# How log topics feed the filter. Topics not listed here are chosen by message type:\n"
             "# PoseWithCovarianceStamped -> pose (rsu_fix on /rsu/<id>/fix when rsu.registry is set, as Odometry\n"
             "# on /rsu/<id>/addressed_fix);\n"
             "# TwistWithCovarianceStamped, Odometry, Imu -> twist; PointCloud2 -> scan (with --map);\n"
             "# TFMessage on /tf_static -> tf_static (places the LiDAR when ndt.lidar_pose is null);\n"
             "# Odometry or poses on a topic whose name contains \"ground_truth\" -> ground truth; others are listed and skipped.\n"
             "# Example:\n"
             "#   /amcl_pose: {role: pose, source: amcl}\n"
             "#   /odom: {role: twist, covariance_diagonal: [0.01, .inf, .inf, .inf, .inf, 0.0025]}\n"
             "#   /rsu/rsu_a/fix: {role: rsu_fix, link: {delay: 0.03, jitter: 0.005, loss: 0.2, seed: 1}}\n";
      if (config.inputs.empty()) out << "inputs: {}\n";
      else {
        out << "inputs:\n";
        for (const auto& [topic, input] : config.inputs) out << "  \"" << topic << "\": " << inputYaml(input) << "\n";
      }
    }
  }
  return out.str();
}

std::string defaultConfigYaml() {
  const Config defaults;
  return configYaml(defaults,
                    "# coloc configuration: every key with its default. Any key may be left out.\n"
                    "# Generated by `coloc config`; docs/configuration.md documents each key.\n\n");
}

std::string configReferenceMarkdown() {
  const Config defaults;
  std::ostringstream out;
  out << "| key | default | unit | meaning |\n|---|---|---|---|\n";
  for (const auto& p : fusion::ekfParams())
    out << "| `fusion." << p.key << "` | `" << fusion::formatValue(p, defaults.fusion) << "` | " << p.unit << " | "
        << p.meaning << " |\n";
  for (const char* section : kSections) {
    for (const Key& k : keys())
      if (std::string(k.section) == section)
        out << "| `" << k.section << "." << k.key << "` | `" << k.get(defaults) << "` | " << k.unit << " | " << k.meaning << " |\n";
    if (std::string(section) == "messages")
      out << "| `inputs.TOPIC.role` | by type | | `pose`, `twist`, `ground_truth`, `scan` (PointCloud2 for NDT), `rsu_fix` (through the registry's checks) or `ignore` |\n"
             "| `inputs.TOPIC.source` | the topic | | the source's name in the filter and the summary |\n"
             "| `inputs.TOPIC.covariance_diagonal` | from the message | variances | 6 values replacing the message's covariance; `.inf` = not measured (rsu_fix: the registry's variance) |\n"
             "| `inputs.TOPIC.additional_delay` | `0` | s | the data was sensed this long before its stamp |\n"
             "| `inputs.TOPIC.link` | none | | replay the topic through an emulated link: `{delay, jitter, loss, burst, p_good_to_bad, "
             "p_bad_to_good, loss_in_good, loss_in_bad, seed}` (s, probabilities); deterministic |\n";
  }
  return out.str();
}

}  // namespace coloc::pipeline
