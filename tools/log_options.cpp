#include "log_options.hpp"

#include <filesystem>

#include "coloc/core/error.hpp"

namespace coloc::tools {

void addLogOptions(CLI::App* cmd, LogOptions& o) {
  cmd->add_option("LOG", o.log, "the recording (.mcap, .db3 or rosbag2 folder)")->required();
  cmd->add_option("--config", o.config, "YAML configuration (see `coloc config`)")->check(CLI::ExistingFile);
  cmd->add_option("--map", o.map, "point-cloud map (PCD file or folder of PCD tiles): PointCloud2 topics then feed NDT");
  cmd->add_option("--rsu-registry", o.registry,
                  "RSU registry (YAML): /rsu/<id>/fix topics of its RSUs pass its checks (default: rsu.registry of the config)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", o.out, "output folder (created)")->capture_default_str();
}

replay::ReplayOptions replayOptions(const LogOptions& o) {
  replay::ReplayOptions options;
  if (!o.config.empty()) options.config = pipeline::loadConfig(o.config);
  options.map = o.map;
  if (!o.registry.empty()) options.registry = rsu_client::RsuRegistry::load(o.registry);
  return options;
}

void createOutputFolder(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error(dir + ": cannot create the output folder: " + ec.message());
}

}  // namespace coloc::tools
