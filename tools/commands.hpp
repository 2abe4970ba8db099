#pragma once
// The subcommands of `coloc`, each registered on the CLI11 app by its own file.
#include <CLI/CLI.hpp>

namespace coloc::tools {

void addFuseCommand(CLI::App& app);
void addConvertCommand(CLI::App& app);
void addConfigCommand(CLI::App& app);
void addAlignCommand(CLI::App& app);
void addRsuListenCommand(CLI::App& app);
void addRsuPublishCommand(CLI::App& app);
void addRsuNodeCommand(CLI::App& app);
void addSimulateCommand(CLI::App& app);
void addExperimentCommand(CLI::App& app);
void addLocalizeCommand(CLI::App& app);
void addPlayCommand(CLI::App& app);
void addSmoothCommand(CLI::App& app);
void addInitializeCommand(CLI::App& app);

}  // namespace coloc::tools
