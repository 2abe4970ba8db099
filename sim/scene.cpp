#include "coloc/sim/scene.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <limits>
#include <random>
#include <sstream>

#include "coloc/core/error.hpp"
#include "coloc/core/yaml_reader.hpp"
#include "coloc/sim/vehicle_body.hpp"

namespace coloc::sim {

namespace {

// The one YAML reader, with the scene's shapes on top; every scenario value must be finite.
class Reader : public YamlReader {
 public:
  using YamlReader::YamlReader;
  double number(const YAML::Node& n, const std::string& key) const { return finite(n, key); }
  Eigen::Vector2d vec2(const YAML::Node& n, const std::string& key) const {
    const auto v = numbers(n, key, 2, "[x, y]");
    if (!std::isfinite(v[0]) || !std::isfinite(v[1])) fail(n, key, "must be finite");
    return {v[0], v[1]};
  }
  Eigen::Vector3d vec3(const YAML::Node& n, const std::string& key) const {
    const auto v = numbers(n, key, 3, "[x, y, z]");
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) fail(n, key, "must be finite");
    return {v[0], v[1], v[2]};
  }
  void keys(const YAML::Node& n, const std::string& where, std::initializer_list<const char*> allowed) const { allowKeys(n, where, allowed); }
};

SceneObject readObject(const Reader& r, const YAML::Node& n, const std::string& where) {
  SceneObject o;
  o.type = r.text(r.require(n, "type", where), where + ".type");
  const auto common = [&](const YAML::Node& node) {
    if (node["in_world"]) o.in_world = r.flag(node["in_world"], where + ".in_world");
    if (node["in_map"]) o.in_map = r.flag(node["in_map"], where + ".in_map");
    if (!o.in_world && !o.in_map) r.fail(node, where, "an object in neither the world nor the map");
  };
  if (o.type == "building") {
    r.keys(n, where, {"type", "center", "size", "yaw", "in_world", "in_map"});
    const Eigen::Vector2d c = r.vec2(r.require(n, "center", where), where + ".center");
    const Eigen::Vector3d s = r.vec3(r.require(n, "size", where), where + ".size");
    if (!(s.minCoeff() > 0.0)) r.fail(n["size"], where + ".size", "each of [length, width, height] must be > 0");
    const double yaw = n["yaw"] ? r.number(n["yaw"], where + ".yaw") : 0.0;
    o.mesh = box(Eigen::Vector3f(static_cast<float>(c.x()), static_cast<float>(c.y()), 0.0f), s.cast<float>(), static_cast<float>(yaw));
  } else if (o.type == "wall") {
    r.keys(n, where, {"type", "from", "to", "height", "thickness", "in_world", "in_map"});
    const Eigen::Vector2d a = r.vec2(r.require(n, "from", where), where + ".from"), b = r.vec2(r.require(n, "to", where), where + ".to");
    if (!((b - a).norm() > 0.0)) r.fail(n["to"], where + ".to", "must differ from `from`: a wall needs a length");
    const double h = r.positive(r.require(n, "height", where), where + ".height");
    const double t = n["thickness"] ? r.positive(n["thickness"], where + ".thickness") : 0.3;
    const Eigen::Vector2d mid = 0.5 * (a + b);
    o.mesh = box(Eigen::Vector3f(static_cast<float>(mid.x()), static_cast<float>(mid.y()), 0.0f),
                 Eigen::Vector3f(static_cast<float>((b - a).norm()), static_cast<float>(t), static_cast<float>(h)),
                 static_cast<float>(std::atan2(b.y() - a.y(), b.x() - a.x())));
  } else if (o.type == "pole") {
    r.keys(n, where, {"type", "at", "radius", "height", "in_world", "in_map"});
    const Eigen::Vector2d p = r.vec2(r.require(n, "at", where), where + ".at");
    o.mesh = cylinder(Eigen::Vector3f(static_cast<float>(p.x()), static_cast<float>(p.y()), 0.0f),
                      static_cast<float>(n["radius"] ? r.positive(n["radius"], where + ".radius") : 0.15),
                      static_cast<float>(r.positive(r.require(n, "height", where), where + ".height")));
  } else if (o.type == "tree") {
    r.keys(n, where, {"type", "at", "height", "crown", "in_world", "in_map"});
    const Eigen::Vector2d p = r.vec2(r.require(n, "at", where), where + ".at");
    const float h = static_cast<float>(r.positive(r.require(n, "height", where), where + ".height"));
    const float crown = static_cast<float>(n["crown"] ? r.positive(n["crown"], where + ".crown") : 2.0);
    const Eigen::Vector3f base(static_cast<float>(p.x()), static_cast<float>(p.y()), 0.0f);
    o.mesh = cylinder(base, 0.2f, 0.5f * h);
    o.mesh.append(cylinder(base + Eigen::Vector3f(0, 0, 0.5f * h), 0.5f * crown, 0.5f * h, 8));
  } else if (o.type == "parked_car") {
    r.keys(n, where, {"type", "at", "yaw", "in_world", "in_map"});
    const Eigen::Vector2d p = r.vec2(r.require(n, "at", where), where + ".at");
    o.mesh = VehicleBody{}.mesh(p.x(), p.y(), n["yaw"] ? r.number(n["yaw"], where + ".yaw") : 0.0);
    o.position = p;
  } else {
    r.fail(n["type"], where + ".type", "unknown object type '" + o.type + "' (building, wall, pole, tree, parked_car)");
  }
  common(n);
  return o;
}

ErrorSources readErrors(const Reader& r, const YAML::Node& n, const ErrorSources& base = {}) {
  r.keys(n, "errors", {"preset", "survey_position_sd", "survey_yaw_sd_deg", "clock_offset_sd_ms", "clock_jitter_sd_ms", "vehicle_body",
                       "range_noise", "range_noise_per_m", "dropout", "dropout_at_max_range", "lidar_mount_yaw_deg",
                       "map_position_sd", "map_yaw_sd_deg", "map_error_length", "cam_size_step", "cam_length_excess", "cam_width_excess", "beam_divergence_mrad", "beam_divergence_vertical_mrad"});
  ErrorSources e = base;
  if (n["preset"]) e = r.choice(n["preset"], "errors.preset", {"real", "ideal"}) == "ideal" ? ErrorSources::ideal() : ErrorSources{};
  if (n["survey_position_sd"]) e.survey_position_sd = r.inRange(n["survey_position_sd"], "errors.survey_position_sd", 0.0, 5.0);
  if (n["survey_yaw_sd_deg"]) e.survey_yaw_sd = r.inRange(n["survey_yaw_sd_deg"], "errors.survey_yaw_sd_deg", 0.0, 10.0) * M_PI / 180.0;
  if (n["clock_offset_sd_ms"]) e.clock_offset_sd = 1e-3 * r.inRange(n["clock_offset_sd_ms"], "errors.clock_offset_sd_ms", 0.0, 1000.0);
  if (n["clock_jitter_sd_ms"]) e.clock_jitter_sd = 1e-3 * r.inRange(n["clock_jitter_sd_ms"], "errors.clock_jitter_sd_ms", 0.0, 100.0);
  if (n["vehicle_body"]) e.detailed_vehicle = r.choice(n["vehicle_body"], "errors.vehicle_body", {"detailed", "boxes"}) == "detailed";
  if (n["range_noise"]) e.range_noise = r.inRange(n["range_noise"], "errors.range_noise", 0.0, 1.0);
  if (n["range_noise_per_m"]) e.range_noise_per_m = r.inRange(n["range_noise_per_m"], "errors.range_noise_per_m", 0.0, 0.1);
  if (n["dropout"]) e.dropout = r.inRange(n["dropout"], "errors.dropout", 0.0, 0.99);
  if (n["dropout_at_max_range"]) e.dropout_at_max_range = r.inRange(n["dropout_at_max_range"], "errors.dropout_at_max_range", 0.0, 1.0);
  if (n["map_position_sd"]) e.map_position_sd = r.inRange(n["map_position_sd"], "errors.map_position_sd", 0.0, 5.0);
  if (n["map_yaw_sd_deg"]) e.map_yaw_sd = r.inRange(n["map_yaw_sd_deg"], "errors.map_yaw_sd_deg", 0.0, 10.0) * M_PI / 180.0;
  if (n["map_error_length"]) {
    e.map_error_length = r.inRange(n["map_error_length"], "errors.map_error_length", 0.0, 1e5);
    if (e.map_error_length == 0.0) r.fail(n["map_error_length"], "errors.map_error_length", "must be > 0");
  }
  if (n["cam_size_step"]) e.cam_size_step = r.inRange(n["cam_size_step"], "errors.cam_size_step", 0.0, 1.0);
  if (n["cam_length_excess"]) e.cam_length_excess = r.inRange(n["cam_length_excess"], "errors.cam_length_excess", 0.0, 1.0);
  if (n["cam_width_excess"]) e.cam_width_excess = r.inRange(n["cam_width_excess"], "errors.cam_width_excess", 0.0, 1.0);
  if (n["beam_divergence_mrad"]) e.beam_divergence = 1e-3 * r.inRange(n["beam_divergence_mrad"], "errors.beam_divergence_mrad", 0.0, 20.0);
  if (n["beam_divergence_vertical_mrad"])
    e.beam_divergence_vertical = 1e-3 * r.inRange(n["beam_divergence_vertical_mrad"], "errors.beam_divergence_vertical_mrad", 0.0, 20.0);
  if (n["lidar_mount_yaw_deg"]) e.lidar_mount_yaw = r.inRange(n["lidar_mount_yaw_deg"], "errors.lidar_mount_yaw_deg", -10.0, 10.0) * M_PI / 180.0;
  return e;
}

TrafficVehicle readTraffic(const Reader& r, const YAML::Node& n, const std::string& where) {
  r.keys(n, where, {"lane_offset", "start", "speed", "direction", "length", "width", "station_id"});
  TrafficVehicle v;
  if (n["lane_offset"]) v.lane_offset = r.inRange(n["lane_offset"], where + ".lane_offset", -50.0, 50.0);
  if (n["start"]) v.start = r.number(n["start"], where + ".start");
  if (n["speed"]) v.speed = r.inRange(n["speed"], where + ".speed", 0.0, 60.0);
  if (n["direction"]) v.oncoming = r.choice(n["direction"], where + ".direction", {"same", "oncoming"}) == "oncoming";
  if (n["length"]) v.body.length = r.inRange(n["length"], where + ".length", 2.5, 20.0);
  if (n["width"]) v.body.width = r.inRange(n["width"], where + ".width", 1.4, 3.0);
  if (n["station_id"]) v.station_id = static_cast<std::uint32_t>(r.integer(n["station_id"], where + ".station_id", 0, 4294967295LL));
  return v;
}

}  // namespace

ErrorSources readErrorSources(const YamlReader& reader, const YAML::Node& node, const ErrorSources& base) {
  return readErrors(Reader(reader.source()), node, base);
}

void setErrorSources(Scenario& s, const ErrorSources& errors) {
  s.errors = errors;
  for (std::size_t i = 0; i < s.rsus.size(); ++i) {
    ScenarioRsu& rsu = s.rsus[i];
    // One stream per RSU, from the seed and its place in the list: adding an RSU changes no other's draw.
    std::mt19937_64 rng(s.seed * 1000003ULL + 7919ULL * (i + 1));
    std::normal_distribution<double> unit(0.0, 1.0);
    const double dx = unit(rng), dy = unit(rng), dyaw = unit(rng), dt = unit(rng);
    if (!rsu.survey_error_given)
      rsu.survey_error = Eigen::Vector3d(errors.survey_position_sd * dx, errors.survey_position_sd * dy, errors.survey_yaw_sd * dyaw);
    if (!rsu.clock_offset_given) rsu.clock_offset = errors.clock_offset_sd * dt;
  }
}

Scenario parseScenario(const std::string& yaml_text, const std::string& source) {
  const Reader r(source);
  const YAML::Node root = r.parse(yaml_text);
  r.keys(root, "(top level)", {"name", "seed", "ground", "objects", "route", "vehicle", "rsus", "traffic", "errors"});
  Scenario s;
  s.name = root["name"] ? r.text(root["name"], "name") : "scenario";
  if (root["seed"]) s.seed = static_cast<std::uint64_t>(r.integer(root["seed"], "seed", 0, std::numeric_limits<long long>::max()));
  if (root["ground"]) {
    r.keys(root["ground"], "ground", {"min", "max"});
    s.ground_min = r.vec2(r.require(root["ground"], "min", "ground"), "ground.min");
    s.ground_max = r.vec2(r.require(root["ground"], "max", "ground"), "ground.max");
    if ((s.ground_max.array() <= s.ground_min.array()).any()) r.fail(root["ground"], "ground", "max must exceed min");
  }
  if (root["objects"]) {
    if (!root["objects"].IsSequence()) r.fail(root["objects"], "objects", "expected a list");
    for (std::size_t i = 0; i < root["objects"].size(); ++i)
      s.objects.push_back(readObject(r, root["objects"][i], "objects[" + std::to_string(i) + "]"));
  }
  const YAML::Node route = r.require(root, "route", "(top level)");
  r.keys(route, "route", {"start", "heading", "pieces", "speed", "acceleration"});
  s.route_start = r.vec2(r.require(route, "start", "route"), "route.start");
  s.route_heading = route["heading"] ? r.number(route["heading"], "route.heading") : 0.0;
  const YAML::Node pieces = r.require(route, "pieces", "route");
  if (!pieces.IsSequence() || pieces.size() == 0) r.fail(pieces, "route.pieces", "expected a list of {length, curvature}");
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    const std::string where = "route.pieces[" + std::to_string(i) + "]";
    r.keys(pieces[i], where, {"length", "curvature"});
    // A car turns on no less than about 4 m (its turning circle's radius at the rear axle is 4-6 m).
    constexpr double kMaxCurvature = 0.25;  // 1/m
    const double curvature = pieces[i]["curvature"] ? r.number(pieces[i]["curvature"], where + ".curvature") : 0.0;
    if (std::abs(curvature) > kMaxCurvature)
      r.fail(pieces[i]["curvature"], where + ".curvature", "must be within +-0.25 1/m (a radius of 4 m or more: a car's tightest turn)");
    s.route.push_back({r.positive(r.require(pieces[i], "length", where), where + ".length"), curvature});
  }
  if (route["speed"]) s.speed.cruise = r.positive(route["speed"], "route.speed");
  if (route["acceleration"]) s.speed.acceleration = r.positive(route["acceleration"], "route.acceleration");
  if (root["vehicle"]) {
    r.keys(root["vehicle"], "vehicle", {"lidar", "lidar_height", "odometry", "station_id"});
    if (root["vehicle"]["station_id"])
      s.vehicle_station_id = static_cast<std::uint32_t>(r.integer(root["vehicle"]["station_id"], "vehicle.station_id", 0, 4294967295LL));
    if (root["vehicle"]["lidar"]) s.vehicle_lidar = r.text(root["vehicle"]["lidar"], "vehicle.lidar");
    if (s.vehicle_lidar != "VLP-16" && s.vehicle_lidar != "VLP-32C")
      r.fail(root["vehicle"]["lidar"], "vehicle.lidar", "unknown LiDAR model '" + s.vehicle_lidar + "' (VLP-16, VLP-32C)");
    if (root["vehicle"]["lidar_height"]) s.vehicle_lidar_height = r.positive(root["vehicle"]["lidar_height"], "vehicle.lidar_height");
    if (const YAML::Node o = root["vehicle"]["odometry"]) {
      r.keys(o, "vehicle.odometry", {"speed_sigma", "speed_scale", "yaw_rate_sigma", "yaw_rate_bias"});
      if (o["speed_sigma"]) s.odometry.speed_sigma = r.inRange(o["speed_sigma"], "vehicle.odometry.speed_sigma", 0.0, 10.0);
      if (o["speed_scale"]) s.odometry.speed_scale = r.inRange(o["speed_scale"], "vehicle.odometry.speed_scale", 0.5, 1.5);
      if (o["yaw_rate_sigma"]) s.odometry.yaw_rate_sigma = r.inRange(o["yaw_rate_sigma"], "vehicle.odometry.yaw_rate_sigma", 0.0, 1.0);
      if (o["yaw_rate_bias"]) s.odometry.yaw_rate_bias = r.inRange(o["yaw_rate_bias"], "vehicle.odometry.yaw_rate_bias", -1.0, 1.0);
    }
  }
  if (root["rsus"]) {
    for (std::size_t i = 0; i < root["rsus"].size(); ++i) {
      const YAML::Node n = root["rsus"][i];
      const std::string where = "rsus[" + std::to_string(i) + "]";
      r.keys(n, where, {"id", "position", "height", "yaw", "roll_deg", "pitch_deg", "lidar_model", "survey_error", "clock_offset_ms"});
      ScenarioRsu rsu;
      rsu.id = r.text(r.require(n, "id", where), where + ".id");
      rsu.position = r.vec2(r.require(n, "position", where), where + ".position");
      if (n["height"]) rsu.height = r.positive(n["height"], where + ".height");
      if (n["yaw"]) rsu.yaw = r.number(n["yaw"], where + ".yaw");
      if (n["roll_deg"]) rsu.roll = r.inRange(n["roll_deg"], where + ".roll_deg", -45.0, 45.0) * M_PI / 180.0;
      if (n["pitch_deg"]) rsu.pitch = r.inRange(n["pitch_deg"], where + ".pitch_deg", -45.0, 45.0) * M_PI / 180.0;
      if (n["survey_error"]) {
        const auto v = r.numbers(n["survey_error"], where + ".survey_error", 3, "[dx, dy, dyaw_deg]");
        const Eigen::Vector3d e(v[0], v[1], v[2]);
        if (e.head<2>().norm() > 10.0 || std::abs(e.z()) > 30.0)
          r.fail(n["survey_error"], where + ".survey_error", "expected [dx, dy, dyaw_deg] within 10 m and 30 deg");
        rsu.survey_error = Eigen::Vector3d(e.x(), e.y(), e.z() * M_PI / 180.0);
        rsu.survey_error_given = true;
      }
      if (n["clock_offset_ms"]) {
        rsu.clock_offset = 1e-3 * r.inRange(n["clock_offset_ms"], where + ".clock_offset_ms", -1000.0, 1000.0);
        rsu.clock_offset_given = true;
      }
      if (n["lidar_model"]) rsu.lidar_model = r.text(n["lidar_model"], where + ".lidar_model");
      if (rsu.lidar_model != "VLP-16" && rsu.lidar_model != "VLP-32C" && rsu.lidar_model != "OS1-64")
        r.fail(n["lidar_model"], where + ".lidar_model", "unknown LiDAR model '" + rsu.lidar_model + "' (VLP-16, VLP-32C, OS1-64)");
      s.rsus.push_back(rsu);
    }
  }
  if (const YAML::Node t = root["traffic"]) {
    if (!t.IsSequence()) r.fail(t, "traffic", "expected a list of {lane_offset, start, speed, direction, length, width, station_id}");
    for (std::size_t i = 0; i < t.size(); ++i) {
      s.traffic.push_back(readTraffic(r, t[i], "traffic[" + std::to_string(i) + "]"));
      if (s.traffic.back().station_id && *s.traffic.back().station_id == s.vehicle_station_id)
        r.fail(t[i]["station_id"], "traffic[" + std::to_string(i) + "].station_id", "is the ego vehicle's (vehicle.station_id)");
    }
  }
  Route(s.route_start, s.route_heading, s.route);  // validates the pieces
  setErrorSources(s, root["errors"] ? readErrors(r, root["errors"]) : ErrorSources{});
  return s;
}

Scenario loadScenario(const std::string& path) {
  return parseScenario(YamlReader::readFile(path, "scenario"), path);
}

std::vector<TriangleMesh> Scenario::worldMeshes() const {
  std::vector<TriangleMesh> out = {groundRectangle(ground_min.cast<float>(), ground_max.cast<float>())};
  for (const SceneObject& o : objects)
    if (o.in_world) out.push_back(o.mesh);
  return out;
}

std::vector<TriangleMesh> Scenario::mapMeshes() const {
  std::vector<TriangleMesh> out = {groundRectangle(ground_min.cast<float>(), ground_max.cast<float>())};
  for (const SceneObject& o : objects)
    if (o.in_map) out.push_back(o.mesh);
  return out;
}

}  // namespace coloc::sim
