#pragma once
// A digital-twin scenario from YAML: the world's objects as meshes (ground, buildings, walls, poles,
// trees, parked cars), which of them the survey map has (a map can be older than the world), the ego
// vehicle's route and speed, other traffic, the roadside units, and the error sources of the road.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "coloc/core/yaml_reader.hpp"
#include "coloc/sim/error_sources.hpp"
#include "coloc/sim/mesh.hpp"
#include "coloc/sim/traffic.hpp"
#include "coloc/sim/vehicle_motion.hpp"

namespace coloc::sim {

struct SceneObject {
  std::string type;       ///< building, wall, pole, tree, parked_car
  TriangleMesh mesh;
  Eigen::Vector2d position = Eigen::Vector2d::Zero();  ///< centre in plan (a parked car's, for ground truth)
  bool in_world = true;   ///< false: removed since the survey (the map still has it)
  bool in_map = true;     ///< false: added since the survey (the map lacks it)
};

struct ScenarioRsu {
  std::string id;
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  double height = 2.0;
  double yaw = 0.0;
  /// The LiDAR's tilt (roll_deg, pitch_deg in the file; rad here): about its x axis, then its y axis
  /// (pitch > 0: its forward axis down towards the road), before the yaw. Poles' LiDARs are tilted.
  double roll = 0.0, pitch = 0.0;
  std::string lidar_model = "VLP-16";
  /// The surveyed pose minus the true pose (dx, dy [m], dyaw [rad]): the RSU computes its fixes from
  /// its surveyed pose, so they are off by it; the vehicle's registry lists the surveyed position.
  Eigen::Vector3d survey_error = Eigen::Vector3d::Zero();
  double clock_offset = 0.0;  ///< s, the RSU's clock minus the vehicle's: its fixes are stamped on it
  /// Whether the scenario states them; if not, they are drawn from the scenario's error sources.
  bool survey_error_given = false, clock_offset_given = false;
};

struct Scenario {
  std::string name;
  std::uint64_t seed = 1;
  Eigen::Vector2d ground_min = Eigen::Vector2d(-50, -50), ground_max = Eigen::Vector2d(50, 50);
  std::vector<SceneObject> objects;
  Eigen::Vector2d route_start = Eigen::Vector2d::Zero();
  double route_heading = 0.0;
  std::vector<RoutePiece> route;
  SpeedProfile speed;
  std::string vehicle_lidar = "VLP-32C";
  double vehicle_lidar_height = 1.9;  ///< m above the road
  OdometryNoise odometry;             ///< the wheel odometry's noise, scale error and yaw-rate bias
  /// The ego's station id, as its CAM carries it: the RSUs address its fixes to it.
  std::uint32_t vehicle_station_id = 1001;
  std::vector<ScenarioRsu> rsus;
  std::vector<TrafficVehicle> traffic;
  ErrorSources errors;  ///< realistic by default

  /// The meshes of the world (ground first) or of the world as surveyed.
  std::vector<TriangleMesh> worldMeshes() const;
  std::vector<TriangleMesh> mapMeshes() const;
};

/// Sets the error sources and draws what the RSUs do not state (survey error, clock offset) from them
/// and the seed: one draw per RSU, the same for every drive of the scenario.
void setErrorSources(Scenario& scenario, const ErrorSources& errors);

/// An `errors:` section (a scenario's, or an experiment's for every site) on top of `base`: `preset`
/// first, then each key given. Throws coloc::Error naming the reader's file, the line and the key.
ErrorSources readErrorSources(const YamlReader& reader, const YAML::Node& node, const ErrorSources& base);

/// Throws coloc::Error naming the file, line and key for unknown keys, unknown object types or LiDAR
/// models, and values out of range.
Scenario loadScenario(const std::string& path);
Scenario parseScenario(const std::string& yaml_text, const std::string& source_name);

}  // namespace coloc::sim
