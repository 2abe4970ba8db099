// `coloc align TARGET SOURCE`: one NDT alignment, printed as JSON.
#include <Eigen/Geometry>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "coloc/ndt/aligner.hpp"
#include "coloc/ndt/ndt_pose_source.hpp"
#include "coloc/ndt/pcd_file.hpp"
#include "coloc/ndt/preprocess.hpp"
#include "commands.hpp"
#include "number_checks.hpp"

namespace coloc::tools {

void addAlignCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("align", "Align SOURCE to TARGET (PCD files) with NDT and print the result as JSON");
  // Defaults are ndt's own (ndt::NdtConfig), so that `coloc align` and the pipeline match alike.
  static const ndt::NdtConfig d;
  static std::string target_path, source_path, backend = d.backend == ndt::NdtBackend::kPcl ? "pcl" : "fast",
                                               neighborhood = d.neighborhood == ndt::Neighborhood::kRadius  ? "radius"
                                                              : d.neighborhood == ndt::Neighborhood::kFace7 ? "face7"
                                                                                                            : "single",
                                               covariance = ndt::covarianceModeName(d.covariance);
  static std::vector<double> init;
  static double resolution = d.resolution, step = d.step_size, epsilon = d.transformation_epsilon, source_voxel = 0.1,
                nvtl_threshold = d.nvtl_threshold;
  static int iterations = d.max_iterations, threads = d.threads;
  cmd->add_option("TARGET", target_path, "map / target cloud (.pcd)")->required()->check(CLI::ExistingFile);
  cmd->add_option("SOURCE", source_path, "scan / source cloud (.pcd)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--init", init, "initial guess x y z yaw (m, m, m, rad)")->expected(4);
  cmd->add_option("--backend", backend, "pcl (stock PCL NDT) or fast")->check(CLI::IsMember({"pcl", "fast"}))->capture_default_str();
  cmd->add_option("--neighborhood", neighborhood, "fast backend: radius, face7 or single")
      ->check(CLI::IsMember({"radius", "face7", "single"}))->capture_default_str();
  cmd->add_option("--resolution", resolution, "target voxel size, m")->capture_default_str();
  cmd->add_option("--step-size", step, "first trust-region radius (Autoware's longest step), m")->capture_default_str();
  cmd->add_option("--epsilon", epsilon, "stop when the squared step translation is below this, m^2")->capture_default_str();
  cmd->add_option("--max-iterations", iterations, "iteration limit")->capture_default_str();
  cmd->add_option("--source-voxel", source_voxel, "voxel size the source is downsampled with, m (0 = none)")->check(finiteNumber(0.0))->capture_default_str();
  cmd->add_option("--nvtl-threshold", nvtl_threshold, "quality gate on the result")->capture_default_str();
  cmd->add_option("--covariance", covariance, "fixed, laplace or multi_ndt_score")
      ->check(CLI::IsMember({"fixed", "laplace", "multi_ndt_score"}))->capture_default_str();
  cmd->add_option("--threads", threads, "fast backend threads (0 = all cores)")->capture_default_str();
  cmd->callback([] {
    ndt::NdtConfig config;
    config.backend = backend == "pcl" ? ndt::NdtBackend::kPcl : ndt::NdtBackend::kFast;
    config.neighborhood = neighborhood == "face7" ? ndt::Neighborhood::kFace7
                          : neighborhood == "single" ? ndt::Neighborhood::kSingle : ndt::Neighborhood::kRadius;
    config.resolution = resolution;
    config.step_size = step;
    config.transformation_epsilon = epsilon;
    config.max_iterations = iterations;
    config.nvtl_threshold = nvtl_threshold;
    for (const auto mode : {ndt::CovarianceMode::kFixed, ndt::CovarianceMode::kLaplace, ndt::CovarianceMode::kMultiNdtScore})
      if (covariance == ndt::covarianceModeName(mode)) config.covariance = mode;
    config.threads = threads;
    ndt::NdtPoseSourceConfig check;
    check.ndt = config;
    ndt::validate(check);  // the same ranges, the same words as the config file
    const ndt::PointCloud target_cloud = ndt::loadPcd(target_path);
    const ndt::PointCloud source_cloud = ndt::voxelDownsample(ndt::loadPcd(source_path), source_voxel);
    const ndt::NdtTarget target(target_cloud, config);
    Eigen::Matrix4d guess = Eigen::Matrix4d::Identity();
    if (!init.empty()) {
      guess.topLeftCorner<3, 3>() = Eigen::AngleAxisd(init[3], Eigen::Vector3d::UnitZ()).toRotationMatrix();
      guess.topRightCorner<3, 1>() = Eigen::Vector3d(init[0], init[1], init[2]);
    }
    const ndt::AlignResult r = ndt::align(target, source_cloud, guess, config);
    nlohmann::ordered_json j;
    j["backend"] = backend;
    j["accepted"] = r.accepted();
    j["rejection"] = ndt::toString(r.rejection);
    if (!r.detail.empty()) j["detail"] = r.detail;
    auto& rows = j["transform"] = nlohmann::json::array();
    for (int i = 0; i < 4; ++i) rows.push_back({r.transform(i, 0), r.transform(i, 1), r.transform(i, 2), r.transform(i, 3)});
    const Eigen::Vector3d t = r.transform.topRightCorner<3, 1>();
    const Eigen::Matrix3d R = r.transform.topLeftCorner<3, 3>();
    j["translation"] = {t.x(), t.y(), t.z()};
    j["yaw_deg"] = std::atan2(R(1, 0), R(0, 0)) * 180.0 / M_PI;
    j["iterations"] = r.iterations;
    j["transform_probability"] = r.transform_probability;
    j["nvtl"] = r.nvtl;
    j["elapsed_ms"] = r.elapsed_ms;
    j["source_points"] = source_cloud.size();
    j["target_voxels"] = target.voxelCount();
    auto& cov = j["covariance_diagonal"] = nlohmann::json::array();
    for (int i = 0; i < 6; ++i) cov.push_back(r.covariance(i, i));
    std::printf("%s\n", j.dump(2).c_str());
  });
}

}  // namespace coloc::tools
