#include <gtest/gtest.h>

#include "coloc/core/error.hpp"
#include <cmath>

#include "coloc/sim/scene.hpp"
#include "coloc/sim/survey_map.hpp"

namespace coloc::sim {
namespace {

void expectError(const std::string& yaml, const std::string& phrase) {
  try {
    parseScenario(yaml, "s.yaml");
    FAIL() << "expected an error containing '" << phrase << "'";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(phrase), std::string::npos) << e.what();
  }
}

const char* kRoute = "route: {start: [0, 0], pieces: [{length: 50}]}\n";

TEST(Scenario, ShippedSiteALoadsWithAMapThatDiffersFromTheWorld) {
  const Scenario s = loadScenario(COLOC_SOURCE_DIR "/config/scenarios/site_a.yaml");
  EXPECT_EQ(s.name, "site_a");
  EXPECT_EQ(s.rsus.size(), 1u);
  EXPECT_EQ(s.worldMeshes().size(), s.mapMeshes().size() + 1);  // the car parked since the survey
}

TEST(Scenario, ErrorsNameTheKeyAndLine) {
  expectError(std::string("objects:\n  - {type: fountain, at: [0, 0]}\n") + kRoute, "s.yaml:2: objects[0].type: unknown object type 'fountain'");
  expectError(std::string("objects:\n  - {type: pole, at: [0, 0], height: 5, colour: red}\n") + kRoute, "objects[0].colour: unknown key");
  expectError(std::string("objects:\n  - {type: wall, from: [0, 0], to: [1, 0], height: -2}\n") + kRoute, "objects[0].height: must be a finite number > 0");
  expectError("route: {start: [0, 0], pieces: []}\n", "expected a list of {length, curvature}");
  expectError(std::string(kRoute) + "vehicle: {lidar: HDL-64}\n", "unknown LiDAR model 'HDL-64'");
  expectError(std::string(kRoute) + "weather: rain\n", "weather: unknown key");
  expectError(std::string("objects:\n  - {type: building, center: [0, 9], size: [10, -8, 5]}\n") + kRoute,
              "s.yaml:2: objects[0].size: each of [length, width, height] must be > 0");
  expectError(std::string("objects:\n  - {type: wall, from: [3, 4], to: [3, 4], height: 2}\n") + kRoute,
              "objects[0].to: must differ from `from`");
  expectError("route: {start: [0, 0], pieces: [{length: 20, curvature: 10}]}\n", "route.pieces[0].curvature: must be within +-0.25 1/m");
  expectError("objects: []\n", "needs route");
  expectError(std::string(kRoute) + "errors: {cam_width_excess: -0.1}\n", "errors.cam_width_excess");
}

TEST(Scenario, ACamBoxLargerThanTheBodyIsReadPerSide) {
  const Scenario s = parseScenario(std::string(kRoute) + "errors: {cam_length_excess: 0.15, cam_width_excess: 0.4}\n", "s.yaml");
  EXPECT_DOUBLE_EQ(s.errors.cam_length_excess, 0.15);
  EXPECT_DOUBLE_EQ(s.errors.cam_width_excess, 0.4);
  EXPECT_DOUBLE_EQ(parseScenario(kRoute, "s.yaml").errors.cam_width_excess, 0.0) << "the body's size by default";
}

TEST(Scenario, RsusCarryTheirSurveyErrorAndClockOffsetInTheScenariosUnits) {
  const Scenario s = parseScenario(std::string(kRoute) +
                                       "rsus:\n  - {id: a, position: [10, 5], lidar_model: VLP-16, survey_error: [0.15, -0.05, 0.5], "
                                       "clock_offset_ms: 20}\n",
                                   "s.yaml");
  ASSERT_EQ(s.rsus.size(), 1u);
  EXPECT_DOUBLE_EQ(s.rsus[0].survey_error.x(), 0.15);
  EXPECT_DOUBLE_EQ(s.rsus[0].survey_error.y(), -0.05);
  EXPECT_NEAR(s.rsus[0].survey_error.z(), 0.5 * M_PI / 180.0, 1e-15);  // degrees in the file, radians inside
  EXPECT_DOUBLE_EQ(s.rsus[0].clock_offset, 0.020);                       // ms in the file, seconds inside
  expectError(std::string(kRoute) + "rsus:\n  - {id: a, position: [10, 5], survey_error: [0.1, 0.1]}\n",
              "rsus[0].survey_error: expected [dx, dy, dyaw_deg]");
  expectError(std::string(kRoute) + "odometry: {}\nrsus: []\n", "odometry: unknown key");
}

TEST(Scenario, UnstatedRsuSurveyAndClockErrorsAreDrawnOncePerInstallationFromTheErrorSources) {
  const std::string rsus = "rsus:\n  - {id: a, position: [10, 5]}\n  - {id: b, position: [40, 5], survey_error: [0.1, 0, 0], clock_offset_ms: 3}\n";
  const Scenario s = parseScenario(std::string(kRoute) + "seed: 4\n" + rsus, "s.yaml");
  // Drawn for a, as stated for b; the same draw on every parse (one installation, one survey).
  EXPECT_GT(s.rsus[0].survey_error.head<2>().norm(), 0.0);
  EXPECT_LT(s.rsus[0].survey_error.head<2>().norm(), 5 * s.errors.survey_position_sd);
  EXPECT_LT(std::abs(s.rsus[0].survey_error.z()), 5 * s.errors.survey_yaw_sd);
  EXPECT_LT(std::abs(s.rsus[0].clock_offset), 5 * s.errors.clock_offset_sd);
  EXPECT_EQ(parseScenario(std::string(kRoute) + "seed: 4\n" + rsus, "s.yaml").rsus[0].survey_error, s.rsus[0].survey_error);
  EXPECT_NE(parseScenario(std::string(kRoute) + "seed: 5\n" + rsus, "s.yaml").rsus[0].survey_error, s.rsus[0].survey_error);
  EXPECT_EQ(s.rsus[1].survey_error, Eigen::Vector3d(0.1, 0, 0));
  EXPECT_DOUBLE_EQ(s.rsus[1].clock_offset, 0.003);
  // The ideal twin: nothing drawn, what is stated kept.
  Scenario ideal = s;
  setErrorSources(ideal, ErrorSources::ideal());
  EXPECT_EQ(ideal.rsus[0].survey_error, Eigen::Vector3d::Zero());
  EXPECT_EQ(ideal.rsus[0].clock_offset, 0.0);
  EXPECT_EQ(ideal.rsus[1].survey_error, Eigen::Vector3d(0.1, 0, 0));
  EXPECT_FALSE(ideal.errors.detailed_vehicle);
  EXPECT_EQ(ideal.errors.lidar_mount_yaw, 0.0);
  EXPECT_GT(s.errors.lidar_mount_yaw, 0.0);  // a real car's LiDAR is mounted a little off its calibration
  // The errors section, in the file's units, and its mistakes.
  const Scenario e = parseScenario(std::string(kRoute) + "errors: {preset: ideal, survey_yaw_sd_deg: 0.5, clock_offset_sd_ms: 10, dropout: 0.1}\n", "s.yaml");
  EXPECT_NEAR(e.errors.survey_yaw_sd, 0.5 * M_PI / 180.0, 1e-15);
  EXPECT_DOUBLE_EQ(e.errors.clock_offset_sd, 0.010);
  EXPECT_DOUBLE_EQ(e.errors.dropout, 0.1);
  EXPECT_EQ(e.errors.survey_position_sd, 0.0);
  EXPECT_NEAR(parseScenario(std::string(kRoute) + "errors: {lidar_mount_yaw_deg: -0.5}\n", "s.yaml").errors.lidar_mount_yaw, -0.5 * M_PI / 180.0, 1e-15);
  expectError(std::string(kRoute) + "errors: {lidar_mount_yaw_deg: 20}\n", "errors.lidar_mount_yaw_deg");
  // Every LiDAR's footprint: Velodyne's 3 mrad unless stated, none in the ideal twin.
  EXPECT_DOUBLE_EQ(s.errors.beam_divergence, 3e-3);
  EXPECT_EQ(ideal.errors.beam_divergence, 0.0);
  EXPECT_DOUBLE_EQ(parseScenario(std::string(kRoute) + "errors: {beam_divergence_mrad: 1.5}\n", "s.yaml").errors.beam_divergence, 1.5e-3);
  expectError(std::string(kRoute) + "errors: {beam_divergence_mrad: -1}\n", "errors.beam_divergence_mrad: must be in [0, 20]");
  expectError(std::string(kRoute) + "errors: {beam_divergence_mrad: .nan}\n", "errors.beam_divergence_mrad: must not be NaN");
  EXPECT_DOUBLE_EQ(parseScenario(std::string(kRoute) + "errors: {beam_divergence_vertical_mrad: 0.7}\n", "s.yaml").errors.beam_divergence_vertical, 0.7e-3);
  expectError(std::string(kRoute) + "errors: {beam_divergence_vertical_mrad: 25}\n", "errors.beam_divergence_vertical_mrad: must be in [0, 20]");
  expectError(std::string(kRoute) + "errors: {fog: 1}\n", "errors.fog: unknown key");
  expectError(std::string(kRoute) + "errors: {dropout: 1.5}\n", "errors.dropout");
  expectError(std::string(kRoute) + "errors: {vehicle_body: blob}\n", "errors.vehicle_body: expected one of detailed, boxes");
}

TEST(Traffic, VehiclesFollowTheRouteInTheirLaneAndLeaveItAtItsEnds) {
  const Scenario s = parseScenario(std::string(kRoute) +
                                       "traffic:\n  - {lane_offset: 3.5, start: 10, speed: 5}\n  - {lane_offset: 7, start: 40, speed: 10, direction: oncoming}\n",
                                   "s.yaml");
  ASSERT_EQ(s.traffic.size(), 2u);
  const Route route(s.route_start, s.route_heading, s.route);
  const auto same = trafficPose(route, s.traffic[0], 2.0), oncoming = trafficPose(route, s.traffic[1], 2.0);
  ASSERT_TRUE(same && oncoming);
  EXPECT_NEAR(same->x(), 20.0, 1e-9);
  EXPECT_NEAR(same->y(), 3.5, 1e-9);  // to the left of the route
  EXPECT_NEAR(same->z(), 0.0, 1e-9);
  EXPECT_NEAR(oncoming->x(), 20.0, 1e-9);
  EXPECT_NEAR(std::abs(oncoming->z()), M_PI, 1e-9);  // facing the other way
  EXPECT_FALSE(trafficPose(route, s.traffic[0], 9.0));  // past the route's 50 m
  EXPECT_FALSE(trafficPose(route, s.traffic[1], 4.5));
  expectError(std::string(kRoute) + "traffic:\n  - {direction: sideways}\n", "traffic[0].direction: expected one of same, oncoming");
  expectError(std::string(kRoute) + "traffic: {speed: 3}\n", "traffic: expected a list");
}

TEST(SurveyMap, SamplesTheSurveyedSurfacesWithinNoise) {
  const Scenario s = parseScenario(
      "ground: {min: [-30, -30], max: [60, 30]}\n"
      "objects:\n  - {type: wall, from: [-10, 8], to: [50, 8], height: 3, thickness: 0.4}\n"
      "  - {type: pole, at: [20, -5], height: 4, in_map: false}\n"
      "route: {start: [0, 0], pieces: [{length: 40}]}\n",
      "s.yaml");
  SurveyConfig config;
  config.spacing = 10.0;
  const ndt::PointCloud map = surveyMap(s, config);
  ASSERT_GT(map.size(), 1000u);
  int wall = 0, pole = 0;
  for (const auto& p : map.points) {
    if (p.z() > 0.3 && std::abs(p.y() - 7.8f) < 0.1f) ++wall;  // the wall's face towards the road
    if (p.z() > 0.3 && (p.head<2>() - Eigen::Vector2f(20, -5)).norm() < 0.5f) ++pole;
  }
  EXPECT_GT(wall, 500);
  EXPECT_EQ(pole, 0);  // not in the map: built after the survey
}

}  // namespace
}  // namespace coloc::sim
