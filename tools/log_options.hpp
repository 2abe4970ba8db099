#pragma once
// The options of the commands that replay a recorded log (fuse, smooth): the log, its configuration,
// map and RSU registry, and the output folder.
#include <CLI/CLI.hpp>
#include <string>

#include "coloc/replay/log_replay.hpp"

namespace coloc::tools {

struct LogOptions {
  std::string log, config, map, registry;
  std::string out;  ///< its default is set before addLogOptions
  bool recover = false;
};

void addLogOptions(CLI::App* cmd, LogOptions& o);
/// The replay the options describe (config, map, registry loaded; throws coloc::Error naming a bad file).
replay::ReplayOptions replayOptions(const LogOptions& o);
/// Creates the output folder or throws coloc::Error saying why not.
void createOutputFolder(const std::string& dir);
/// The --recover flag, as every command that reads a log words it.
CLI::Option* addRecoverFlag(CLI::App* cmd, bool& recover);
/// One line per file read up to its cut, indented, for the terminal.
std::string describeRecovered(const std::vector<io::RecoveredFile>& recovered);

}  // namespace coloc::tools
