// `coloc experiment [FILE] [--quick] [--trials N] [--out DIR]`: the paper's experiment on the digital
// twin, end to end (see experiment.hpp), with its tables and figures (see experiment_report.hpp).
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "commands.hpp"
#include "number_checks.hpp"
#include "coloc/twin/experiment.hpp"
#include "coloc/twin/experiment_report.hpp"

namespace coloc::tools {

using namespace coloc::twin;

void addExperimentCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("experiment",
                                 "The paper's experiment on the digital twin: NDT only against NDT + roadside fusion with a VLP-16 and a "
                                 "VLP-32C, at the built-in sites (A-E: where NDT is good, and where it falls short by geometry and by the map's age) or your own, over trials and a network grid; tables and figures");
  static std::string file, out_dir = "results/experiment";
  static int trials = 0, jobs = 0;
  static bool quick = false, sweeps = false, no_network = false, recordings = false;
  cmd->add_option("FILE", file, "experiment YAML overriding the defaults (keys: see experiment_config.hpp or docs/experiment.md)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", out_dir, "results folder")->capture_default_str();
  cmd->add_option("--trials", trials, "trials per site (default 10)")->check(wholeNumber(1, 1000));
  cmd->add_flag("--quick", quick, "a first look: Table I on every site, one trial, the network grid's corners (0 / 30 ms, 0 / 20 %), no RSU calibration study; a FILE's keys override these");
  cmd->add_flag("--sweeps", sweeps, "also sweep the RSU covariance, the RSU height and the speed");
  cmd->add_flag("--no-network", no_network, "skip the network grid (Tables II and III)");
  cmd->add_flag("--recordings", recordings, "keep each drive's rosbag2 log under OUT/recordings/ (a few hundred MB per drive)");
  cmd->add_option("--jobs", jobs, "replays run side by side (default 2)")->check(wholeNumber(1, 64));
  cmd->callback([app = &app] {
    const ExperimentConfig defaults = quick ? quickExperiment() : ExperimentConfig{};
    ExperimentConfig config = file.empty() ? defaults : loadExperimentConfig(file, defaults);
    if (trials > 0) config.trials = trials;
    if (jobs > 0) config.jobs = jobs;
    if (sweeps) config.sweeps = true;
    if (no_network) config.network = false;
    if (recordings) config.recordings = true;
    std::filesystem::create_directories(out_dir);
    std::string command_line = "coloc experiment";
    for (const std::string& a : app->get_subcommand("experiment")->remaining()) command_line += " " + a;
    if (!file.empty()) command_line += " " + file;
    if (quick) command_line += " --quick";
    if (trials > 0) command_line += " --trials " + std::to_string(trials);
    if (sweeps) command_line += " --sweeps";
    if (no_network) command_line += " --no-network";
    if (recordings) command_line += " --recordings";
    std::printf("coloc experiment: %zu site(s), %d trial(s), roadside LiDARs", config.sites.size(), config.trials);
    for (const std::string& l : config.lidars) std::printf(" %s", l.c_str());
    std::printf(config.network ? ", network grid %zux%zu" : ", no network grid", config.delays.size(), config.losses.size());
    std::printf("%s -> %s\n", config.sweeps ? ", sweeps" : "", out_dir.c_str());
    std::fflush(stdout);
    // Progress: a line per drive and its replays, with the time left at the pace so far. Not after the
    // first drive: it carries the site's map survey and runs alone, where the later ones overlap, so its
    // pace said twice the time left (about 86 s of a quick run's remaining 46). The later estimates still
    // run high (1.4-2x on a quick run): the noise calibration drives, the heaviest, come early.
    const auto start = std::chrono::steady_clock::now();
    double done = 0.0;
    int lines = 0;
    ExperimentProgress progress;
    progress.fraction = [&](double f) { done = f; };
    progress.step = [&](const std::string& line) {
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::printf("  %s [%.0f s]", line.c_str(), elapsed);
      if (++lines > 1 && done > 0.0 && done < 1.0) std::printf(" (about %.0f s left)", elapsed * (1.0 - done) / done);
      std::printf("\n");
      std::fflush(stdout);
    };
    const ExperimentResults results = runExperiment(config, out_dir, progress);
    const std::string table = writeExperimentReport(results, out_dir, command_line);
    std::printf("\nTable I: error within coverage (NDT only against NDT + RSU fusion)\n\n%s\n", table.c_str());
    for (const std::string& note : results.notes) std::printf("note: %s\n", note.c_str());
    std::printf("finished in %.0f s; tables, figures and CSVs in %s/ (README.md puts them together)\n", results.timing.total, out_dir.c_str());
  });
}

}  // namespace coloc::tools
