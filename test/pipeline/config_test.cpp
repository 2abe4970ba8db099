#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "coloc/core/error.hpp"
#include "coloc/pipeline/config.hpp"

namespace coloc::pipeline {
namespace {

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void expectError(const std::string& yaml, const std::string& phrase) {
  try {
    parseConfig(yaml, "test.yaml");
    FAIL() << "expected an error containing '" << phrase << "'";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(phrase), std::string::npos) << e.what();
  }
}

TEST(Config, ShippedDefaultFileIsExactlyTheGeneratedDefaults) {
  EXPECT_EQ(readFile(COLOC_SOURCE_DIR "/config/coloc.yaml"), defaultConfigYaml())
      << "regenerate it: coloc config > config/coloc.yaml";
}

TEST(Config, ReadmeCarriesTheGeneratedReferenceTable) {
  EXPECT_NE(readFile(COLOC_SOURCE_DIR "/docs/configuration.md").find(configReferenceMarkdown()), std::string::npos)
      << "regenerate the table of docs/configuration.md: coloc config --markdown";
}

TEST(Config, DefaultYamlParsesBackToTheDefaults) {
  const Config parsed = parseConfig(defaultConfigYaml(), "defaults");
  EXPECT_EQ(parsed.fusion.predict_frequency, 50.0);
  EXPECT_EQ(parsed.fusion.history_steps, 50);
  EXPECT_EQ(parsed.fusion.pose_gate_alpha, 1e-10);
  EXPECT_EQ(parsed.messages.fallback_twist_variance[1], kInfinity);
  EXPECT_TRUE(parsed.inputs.empty());
}

TEST(Config, EmptyTextIsTheDefaultConfiguration) {
  EXPECT_EQ(parseConfig("", "empty").fusion.pose_smoothing_steps, 5);
}

TEST(Config, ReadsInputsWithTheirRolesAndOverrides) {
  const Config c = parseConfig(
      "inputs:\n"
      "  /odom: {role: twist, covariance_diagonal: [0.01, .inf, .inf, .inf, .inf, 0.0025]}\n"
      "  /rsu/fix: {role: pose, source: rsu_a, additional_delay: 0.01}\n"
      "fusion:\n  pose_smoothing_steps: 3\n",
      "test.yaml");
  EXPECT_EQ(c.inputs.at("/odom").role, InputRole::kTwist);
  EXPECT_EQ(c.inputs.at("/odom").source, "/odom");
  EXPECT_EQ((*c.inputs.at("/odom").covariance_diagonal)[5], 0.0025);
  EXPECT_EQ(c.inputs.at("/rsu/fix").source, "rsu_a");
  EXPECT_EQ(c.inputs.at("/rsu/fix").additional_delay, 0.01);
  EXPECT_EQ(c.fusion.pose_smoothing_steps, 3);
}

TEST(Config, ReadsTheNdtSection) {
  const Config c = parseConfig("ndt:\n  backend: pcl\n  resolution: 1.0\n  max_points: 2000\n  covariance: laplace\n"
                                       "  lidar_pose: [1.0, 0, 1.8, 0, 0, 0.1]\n",
                                       "test.yaml");
  EXPECT_EQ(c.ndt.source.ndt.backend, ndt::NdtBackend::kPcl);
  EXPECT_EQ(c.ndt.source.ndt.resolution, 1.0);
  EXPECT_EQ(c.ndt.source.preprocess.max_points, 2000u);
  EXPECT_EQ(c.ndt.source.ndt.covariance, ndt::CovarianceMode::kLaplace);
  EXPECT_EQ(c.ndt.source.lidar_pose[2], 1.8);
  EXPECT_TRUE(c.ndt.lidar_pose_given);
  EXPECT_FALSE(parseConfig("ndt:\n  lidar_pose: null\n", "test.yaml").ndt.lidar_pose_given);
  EXPECT_FALSE(Config().ndt.lidar_pose_given);  // by default a log's /tf_static places the LiDAR
}

TEST(Config, UnknownKeysAreErrorsNamingKeyAndLine) {
  expectError("fusion:\n  history_step: 50\n", "test.yaml:2: fusion.history_step: unknown key");
  expectError("fusoin: {}\n", "fusoin: unknown section");
  expectError("inputs:\n  /odom: {role: twist, sigma: 1}\n", "inputs./odom.sigma: unknown key");
  expectError("replay:\n  clocks: same\n", "replay.clocks: unknown key");
}

TEST(Config, WrongTypesAndRangesAreErrorsNamingTheKey) {
  expectError("fusion:\n  predict_frequency: fast\n", "fusion.predict_frequency: expected a number");
  expectError("fusion:\n  history_steps: 2.5\n", "fusion.history_steps: expected an integer");
  expectError("fusion:\n  predict_frequency: -1\n", "predict_frequency");
  expectError("fusion:\n  pose_gate_alpha: .nan\n", "must not be NaN");
  expectError("inputs:\n  /odom: {role: velocity}\n", "inputs./odom.role: expected one of pose, twist, ground_truth, scan, rsu_fix, tf_static, ignore");
  expectError("inputs:\n  /odom: {source: x}\n", "needs a role");
  expectError("ndt:\n  backend: gpu\n", "ndt.backend: expected one of pcl, fast, got 'gpu'");
  expectError("ndt:\n  resolution: 0\n", "ndt.resolution: must be a finite number > 0");
  expectError("ndt:\n  lidar_pose: [0, 0, 1]\n", "ndt.lidar_pose: expected 6 numbers");
  expectError("ndt:\n  base_frame: \"\"\n", "ndt.base_frame: must name a frame");
  expectError("ndt:\n  voxel_sise: 1.0\n", "ndt.voxel_sise: unknown key");
  expectError("pipeline:\n  initial_pose: [1, 2]\n", "pipeline.initial_pose: expected [x, y, z, yaw]");
  expectError("inputs:\n  /odom: {role: twist, covariance_diagonal: [1, 2]}\n", "expected 6 variances");
  expectError("inputs:\n  /odom: {role: twist, covariance_diagonal: [1, -2, 1, 1, 1, 1]}\n", "must be > 0");
  expectError("replay:\n  clock: sometimes\n", "replay.clock: expected one of auto, same, separate");
  expectError("fusion: [1, 2]\n", "expected a mapping");
  expectError("fusion:\n  a: [\n", "not valid YAML");
}

// Found by fuzzing (config_fuzzer): YAML allows a list or a mapping as a key ("? [a, b]"), and reading
// it as text threw yaml-cpp's own exception past every caller.
TEST(Config, AKeyThatIsAListOrAMappingIsAnErrorNamingItsLine) {
  expectError("? [a, b]\n: 1\n", "test.yaml:1: (a key): a key must be plain text");
  expectError("fusion:\n  ? {a: 1}\n  : 2\n", "test.yaml:2: (a key): a key must be plain text");
  expectError("inputs:\n  ? [/odom]\n  : {role: twist}\n", "a key must be plain text");
  // The fuzzer's own input: the shipped configuration with a complex key in its ndt section.
  const std::string found = readFile(COLOC_SOURCE_DIR "/test/support/fuzz_findings/config_complex_key.bin");
  ASSERT_FALSE(found.empty());
  expectError(found.substr(1), "a key must be plain text");
}

TEST(Config, TwoInputsWithOneSourceNameAreAnError) {
  expectError("inputs:\n  /a: {role: pose, source: x}\n  /b: {role: pose, source: x}\n", "used by two inputs");
}

TEST(Config, MissingFileIsAnErrorNamingIt) {
  try {
    loadConfig("/nonexistent/coloc.yaml");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/coloc.yaml"), std::string::npos);
  }
}

}  // namespace
}  // namespace coloc::pipeline

namespace coloc::pipeline {
namespace {

// What the experiment writes beside a recorded drive must replay exactly what it ran.
TEST(Config, AnyConfigurationWrittenOutReadsBackToTheBit) {
  Config c;
  c.fusion.pose_gate_recovery = 3;
  c.ndt.source.ndt.covariance = ndt::CovarianceMode::kMultiNdtScore;
  c.ndt.source.ndt.fixed_covariance << 0.000776543210987, 0.000776543210987, 0.0225, 0.000625, 0.000625, kInfinity;
  c.ndt.source.ndt.score_temperature = 1.0 / 3.0;
  c.ndt.source.lidar_pose << 0.0, 0.0, 1.9, 0.0, 0.0, 0.0;
  c.ndt.lidar_pose_given = true;
  c.ndt.base_frame = "base_footprint";
  c.pipeline.initial_pose = Eigen::Vector4d(0.1, -1.75, 0.0, 0.1234567890123);
  InputConfig fix;
  fix.role = InputRole::kRsuFix;
  fix.source = "/rsu/rsu_a/fix";
  rsu_client::LinkConfig link;
  link.delay = 0.03;
  link.loss = 0.2;
  link.seed = 7919ULL * 3 + 301;
  fix.link = link;
  c.inputs["/rsu/rsu_a/fix"] = fix;
  InputConfig twist;
  twist.role = InputRole::kTwist;
  twist.source = "odometry";
  twist.covariance_diagonal = (Vector6d() << 0.0024681357913, kInfinity, kInfinity, kInfinity, kInfinity, 2.9e-5).finished();
  twist.additional_delay = 0.015;
  c.inputs["/vehicle/twist"] = twist;

  const std::string text = configYaml(c, "# written by a test\n");
  const Config back = parseConfig(text, "written.yaml");
  EXPECT_EQ(configYaml(back, "# written by a test\n"), text);
  EXPECT_EQ(back.ndt.source.ndt.fixed_covariance, c.ndt.source.ndt.fixed_covariance);  // to the bit
  EXPECT_EQ(back.ndt.source.ndt.score_temperature, 1.0 / 3.0);
  EXPECT_EQ(back.ndt.source.ndt.covariance, ndt::CovarianceMode::kMultiNdtScore);
  EXPECT_EQ(*back.pipeline.initial_pose, *c.pipeline.initial_pose);
  EXPECT_TRUE(back.ndt.lidar_pose_given);
  EXPECT_EQ(back.ndt.source.lidar_pose, c.ndt.source.lidar_pose);
  EXPECT_EQ(back.ndt.base_frame, "base_footprint");
  ASSERT_EQ(back.inputs.size(), 2u);
  const InputConfig& f = back.inputs.at("/rsu/rsu_a/fix");
  EXPECT_EQ(f.role, InputRole::kRsuFix);
  ASSERT_TRUE(f.link.has_value());
  EXPECT_EQ(f.link->delay, 0.03);
  EXPECT_EQ(f.link->loss, 0.2);
  EXPECT_EQ(f.link->seed, link.seed);
  const InputConfig& t = back.inputs.at("/vehicle/twist");
  EXPECT_EQ(t.source, "odometry");
  EXPECT_EQ(*t.covariance_diagonal, *twist.covariance_diagonal);
  EXPECT_EQ(t.additional_delay, 0.015);
}

}  // namespace
}  // namespace coloc::pipeline
