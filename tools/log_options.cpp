#include "log_options.hpp"

#include <cstdio>
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
  addRecoverFlag(cmd, o.recover);
}

CLI::Option* addRecoverFlag(CLI::App* cmd, bool& recover) {
  return cmd->add_flag("--recover", recover,
                       "read a recording that was never closed (an MCAP file without its footer, as a crash or power cut leaves "
                       "it) up to where its whole records end, instead of refusing it");
}

std::string describeRecovered(const std::vector<io::RecoveredFile>& recovered) {
  std::string text;
  for (const io::RecoveredFile& r : recovered) {
    const double percent = r.file_bytes ? 100.0 * static_cast<double>(r.read_bytes) / static_cast<double>(r.file_bytes) : 0.0;
    char line[160];
    std::snprintf(line, sizeof line, ": not closed; recovered %llu messages from its first %llu of %llu bytes (%.1f %%); stopped at: ",
                  static_cast<unsigned long long>(r.messages), static_cast<unsigned long long>(r.read_bytes),
                  static_cast<unsigned long long>(r.file_bytes), percent);
    text += "  " + r.file + line + r.reason + "\n";
  }
  return text;
}

replay::ReplayOptions replayOptions(const LogOptions& o) {
  replay::ReplayOptions options;
  if (!o.config.empty()) options.config = pipeline::loadConfig(o.config);
  options.map = o.map;
  options.recover = o.recover;
  if (!o.registry.empty()) options.registry = rsu_client::RsuRegistry::load(o.registry);
  return options;
}

void createOutputFolder(const std::string& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error(dir + ": cannot create the output folder: " + ec.message());
}

}  // namespace coloc::tools
