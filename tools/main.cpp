// coloc: cooperative localization with roadside LiDAR -- the command-line tool.
#include <cstdio>
#include <exception>

#include "commands.hpp"
#include "coloc/core/error.hpp"

int main(int argc, char** argv) {
  CLI::App app{"coloc: cooperative vehicle localization with LiDAR-equipped roadside units"};
  app.require_subcommand(1);
  coloc::tools::addFuseCommand(app);
  coloc::tools::addConvertCommand(app);
  coloc::tools::addConfigCommand(app);
  coloc::tools::addAlignCommand(app);
  coloc::tools::addRsuListenCommand(app);
  coloc::tools::addRsuPublishCommand(app);
  coloc::tools::addRsuNodeCommand(app);
  coloc::tools::addSimulateCommand(app);
  coloc::tools::addExperimentCommand(app);
  coloc::tools::addLocalizeCommand(app);
  coloc::tools::addPlayCommand(app);
  coloc::tools::addSmoothCommand(app);
  coloc::tools::addInitializeCommand(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const coloc::Error& e) {
    std::fprintf(stderr, "coloc: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "coloc: unexpected error: %s\n", e.what());
    return 2;
  }
  return 0;
}
