#include <gtest/gtest.h>

#include "coloc/core/error.hpp"
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
  expectError("objects: []\n", "needs route");
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
