// `coloc config`: prints the default configuration (YAML) or the reference table (Markdown), or checks
// a configuration file.
#include <cstdio>

#include "commands.hpp"
#include "coloc/pipeline/config.hpp"

namespace coloc::tools {

void addConfigCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("config", "Print the default configuration, its reference table, or check a file");
  static bool markdown = false;
  static std::string check;
  cmd->add_flag("--markdown", markdown, "print the reference table of docs/configuration.md instead of YAML");
  cmd->add_option("--check", check, "validate this YAML file and exit")->check(CLI::ExistingFile);
  cmd->callback([] {
    if (!check.empty()) {
      pipeline::loadConfig(check);
      std::printf("%s: valid\n", check.c_str());
      return;
    }
    std::fputs((markdown ? pipeline::configReferenceMarkdown() : pipeline::defaultConfigYaml()).c_str(), stdout);
  });
}

}  // namespace coloc::tools
