#include <gtest/gtest.h>

#include <cmath>

#include "coloc/core/error.hpp"
#include "coloc/rsu_client/rsu_registry.hpp"

namespace coloc::rsu_client {
namespace {

void expectError(const std::string& yaml, const std::string& phrase) {
  try {
    RsuRegistry::parse(yaml, "rsu.yaml");
    FAIL() << "expected an error containing '" << phrase << "'";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(phrase), std::string::npos) << e.what();
  }
}

TEST(RsuRegistry, ShippedRegistryLoadsWithThePublishedSigmas) {
  const RsuRegistry r = RsuRegistry::load(COLOC_SOURCE_DIR "/config/rsu.yaml");
  ASSERT_EQ(r.rsus().size(), 2u);
  const RsuInfo* a = r.find("rsu_a");
  ASSERT_NE(a, nullptr);
  EXPECT_EQ(a->lidar.name, "VLP-16");
  EXPECT_EQ(a->coverage_radius, 30.0);  // the model's effective range
  EXPECT_EQ(r.variance(*a), 0.01486);   // the paper's placement: sigma on the diagonal
  EXPECT_EQ(r.variance(*r.find("rsu_b")), 0.00681);
  EXPECT_EQ(r.find("rsu_b")->coverage_radius, 50.0);
}

TEST(RsuRegistry, StandardDeviationPlacementSquaresTheSigma) {
  const RsuRegistry r = RsuRegistry::parse(
      "covariance_placement: standard_deviation\nrsus:\n  - {id: a, position: [0, 0], lidar_model: VLP-32C}\n", "rsu.yaml");
  EXPECT_DOUBLE_EQ(r.variance(*r.find("a")), 0.00681 * 0.00681);
}

TEST(RsuRegistry, CalibratedVarianceOverridesTheModelsFigureWhateverThePlacement) {
  for (const char* placement : {"published", "standard_deviation"}) {
    const RsuRegistry r = RsuRegistry::parse(std::string("covariance_placement: ") + placement +
                                                 "\nrsus:\n  - {id: a, position: [0, 0], lidar_model: VLP-16, calibrated_variance: 0.0016}\n"
                                                 "  - {id: b, position: [9, 0], lidar_model: VLP-16}\n",
                                             "rsu.yaml");
    EXPECT_DOUBLE_EQ(r.variance(*r.find("a")), 0.0016) << placement;
    EXPECT_DOUBLE_EQ(r.variance(*r.find("b")), placement[0] == 'p' ? 0.01486 : 0.01486 * 0.01486) << placement;
  }
}

TEST(RsuRegistry, ACalibrationByRangeSurvivesTheFileFormat) {
  const RsuRegistry r = RsuRegistry::parse(
      "rsus:\n  - {id: a, position: [0, 0], lidar_model: VLP-32C, calibrated_variance: 0.0001,\n"
      "     calibrated_error_by_range: [[5.5, 0.012, 0.02], [31.25, 0.011, 0.05, 0.002, -0.013]]}\n", "rsu.yaml");
  const RsuRegistry again = RsuRegistry::parse(r.toYaml(), "again");
  const auto& table = again.find("a")->calibrated_error_by_range;
  ASSERT_EQ(table.size(), 2u);
  EXPECT_EQ(table[1].range, 31.25);
  EXPECT_EQ(table[1].along_sd, 0.011);
  EXPECT_EQ(table[1].across_sd, 0.05);
  EXPECT_EQ(table[0].left_mean, 0.0);  // a row of three: no mean
  EXPECT_EQ(table[1].forward_mean, 0.002);
  EXPECT_EQ(table[1].left_mean, -0.013);
  // 40 m along the diagonal, beyond the last row: 0.05^2 across the line of sight, 0.011^2 along it.
  const Eigen::Matrix2d c = again.covarianceAt(*again.find("a"), Eigen::Vector2d(40.0, 40.0) / std::sqrt(2.0));
  EXPECT_NEAR(c(0, 0), (0.011 * 0.011 + 0.05 * 0.05) / 2.0, 1e-12);
  EXPECT_NEAR(c(0, 1), (0.011 * 0.011 - 0.05 * 0.05) / 2.0, 1e-12);
  // An RSU without one: its calibrated variance on each axis, wherever the fix.
  const RsuRegistry flat = RsuRegistry::parse("rsus:\n  - {id: b, position: [0, 0], lidar_model: VLP-16, calibrated_variance: 0.0002}\n", "x");
  const Eigen::Matrix2d f = flat.covarianceAt(*flat.find("b"), Eigen::Vector2d(30, 7));
  EXPECT_EQ(f(0, 0), 0.0002);
  EXPECT_EQ(f(1, 1), 0.0002);
  EXPECT_EQ(f(0, 1), 0.0);
}

// The mean error of a calibration by range is in the vehicle's frame: a fix 40 m east of the RSU of a
// vehicle heading north is off by the row's forward mean northwards and its left mean westwards,
// heading south the other way round; interpolated in range like the spreads, and nothing without a
// table or without a heading.
TEST(RsuRegistry, TheMeanErrorByRangeIsInTheVehiclesFrame) {
  const RsuRegistry r = RsuRegistry::parse(
      "rsus:\n  - {id: a, position: [100, 0], lidar_model: VLP-16, coverage_radius: 50, calibrated_variance: 0.0004,\n"
      "     calibrated_error_by_range: [[10, 0.01, 0.01, 0.0, 0.0], [40, 0.01, 0.02, 0.004, -0.03]]}\n", "rsu.yaml");
  const RsuInfo& a = *r.find("a");
  Eigen::Vector2d m = r.meanErrorAt(a, Eigen::Vector2d(140, 0), M_PI / 2.0);  // heading north: left is west
  EXPECT_NEAR(m.x(), 0.03, 1e-12);
  EXPECT_NEAR(m.y(), 0.004, 1e-12);
  m = r.meanErrorAt(a, Eigen::Vector2d(140, 0), -M_PI / 2.0);  // heading south: left is east
  EXPECT_NEAR(m.x(), -0.03, 1e-12);
  EXPECT_NEAR(m.y(), -0.004, 1e-12);
  m = r.meanErrorAt(a, Eigen::Vector2d(100, 25), 0.0);  // 25 m, halfway; heading east: left is north
  EXPECT_NEAR(m.x(), 0.002, 1e-12);
  EXPECT_NEAR(m.y(), -0.015, 1e-12);
  EXPECT_EQ(r.meanErrorAt(a, Eigen::Vector2d(140, 0), std::nan("")), Eigen::Vector2d::Zero());
  const RsuRegistry flat = RsuRegistry::parse("rsus:\n  - {id: b, position: [0, 0], lidar_model: VLP-16, calibrated_variance: 0.0002}\n", "x");
  EXPECT_EQ(flat.meanErrorAt(*flat.find("b"), Eigen::Vector2d(20, 0), 0.0), Eigen::Vector2d::Zero());
}

TEST(RsuRegistry, ConfigErrorsNameTheKeyAndLine) {
  expectError("rsus:\n  - {id: a, position: [0, 0], lidar_model: HDL-64}\n", "unknown LiDAR model 'HDL-64'");
  expectError("rsus:\n  - {id: a, position: [0, 0], lidar_model: VLP-16}\n  - {id: a, position: [1, 0], lidar_model: VLP-16}\n",
              "'a' appears twice");
  expectError("rsus:\n  - {id: a, position: [0, 0], lidar_model: VLP-16, colour: red}\n", "rsus[0].colour: unknown key");
  expectError("rsus:\n  - {id: a, lidar_model: VLP-16}\n", "needs a position");
  expectError("rsus:\n  - {id: a, position: [0], lidar_model: VLP-16}\n", "expected [x, y]");
  expectError("rsus:\n  - {id: a, position: [0, 0], lidar_model: VLP-16, coverage_radius: -3}\n", "rsus[0].coverage_radius: must be a finite number > 0");
  expectError("rsus:\n  - {id: a/b, position: [0, 0], lidar_model: VLP-16}\n", "DDS topic");
  expectError("covariance_placement: guessed\n", "covariance_placement: expected one of published, standard_deviation");
  expectError("rsus:\n  - {id: a, position: [0, 0], lidar_model: VLP-16, calibrated_variance: 0}\n",
              "rsus[0].calibrated_variance: must be a finite number > 0");
  expectError("rsus:\n  - {id: a, position: [0, 0], lidar_model: VLP-16, calibrated_variance: .nan}\n", "rsus[0].calibrated_variance: must not be NaN");
  expectError("rsus:\n  - {id: a, position: [0, 0], lidar_model: VLP-16, calibrated_error_by_range: [[5, 0.01, 0.01]]}\n",
              "rsus[0].calibrated_error_by_range: needs calibrated_variance");
  expectError("rsus:\n  - {id: a, position: [0, 0], lidar_model: VLP-16, calibrated_variance: 0.01, calibrated_error_by_range: [[5, -0.01, 0.01]]}\n",
              "rsus[0].calibrated_error_by_range[0]: each standard deviation must be within (0, 10] m");
  expectError("rsus:\n  - {id: a, position: [0, 0], lidar_model: VLP-16, calibrated_variance: 0.01, calibrated_error_by_range: [[5, .nan, 0.01]]}\n",
              "rsus[0].calibrated_error_by_range[0]:");
  expectError("rsus:\n  - {id: a, position: [0, 0], lidar_model: VLP-16, calibrated_variance: 0.01,\n"
              "     calibrated_error_by_range: [[15, 0.01, 0.01], [15, 0.02, 0.02]]}\n",
              "rsus[0].calibrated_error_by_range[1]: the ranges must increase");
  expectError("rsus:\n  - {id: a, position: [0, 0], lidar_model: VLP-16, calibrated_variance: 0.01, calibrated_error_by_range: [[5, 0.01]]}\n",
              "rsus[0].calibrated_error_by_range[0]");
  expectError("rsus:\n  - {id: a, position: [0, 0], lidar_model: VLP-16, calibrated_variance: 0.01, calibrated_error_by_range: [[5, 0.01, 0.01, .inf, 0]]}\n",
              "rsus[0].calibrated_error_by_range[0]: each mean error must be within 10 m of 0");
  expectError("rsus:\n  - {id: a, position: [0, 0], lidar_model: VLP-16, calibrated_variance: 0.01, calibrated_error_by_range: []}\n",
              "rsus[0].calibrated_error_by_range: expected a list");
  expectError("rsu:\n  - {}\n", "rsu: unknown key");
  expectError("? [rsus]\n: []\n", "a key must be plain text");  // found by fuzzing the configs
  expectError("rsus:\n  - {id: a, position: [0, 0], lidar_model: VLP-16, calibration: {? [dx] : 1}}\n", "a key must be plain text");
  expectError("map_frame: \"\"\n", "map_frame: '': a frame name");
  expectError("map_frame: \"a b\"\n", "map_frame: 'a b': a frame name");
}

TEST(RsuRegistry, MapFrameDefaultsToMapAndSurvivesTheFileFormat) {
  EXPECT_EQ(RsuRegistry::parse("rsus: []\n", "test").mapFrame(), "map");
  const RsuRegistry r = RsuRegistry::parse("map_frame: world/utm_54\nrsus: []\n", "test");
  EXPECT_EQ(r.mapFrame(), "world/utm_54");
  EXPECT_EQ(RsuRegistry::parse(r.toYaml(), "again").mapFrame(), "world/utm_54");
}

}  // namespace
}  // namespace coloc::rsu_client
