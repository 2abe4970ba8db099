// `coloc simulate SCENARIO --out DIR`: drives the digital twin and records what the vehicle would have
// recorded, as a rosbag2 log that `coloc fuse` replays and ROS 2 plays (see twin_recording.hpp).
#include <cstdio>
#include <filesystem>

#include "coloc/sim/scene.hpp"
#include "commands.hpp"
#include "number_checks.hpp"
#include "progress.hpp"
#include "coloc/twin/twin_recording.hpp"

namespace coloc::tools {

using namespace coloc::twin;

void addSimulateCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("simulate", "Drive the digital twin through a scenario and record a rosbag2 log");
  static std::string scenario_path, out_dir = "sim_out";
  static TwinRecordingOptions options;
  cmd->add_option("SCENARIO", scenario_path, "scenario YAML (see config/scenarios/)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--out", out_dir,
                  "output folder: log/, map/, fuse.yaml, rsu_fixes.csv, rsu_frames.csv, rsu_fix_error.svg, rsu_perception.csv, rsu_perception.svg")
      ->capture_default_str();
  cmd->add_option("--delay", options.link.delay, "V2I delay of the fixes, s")->check(finiteNumber(0.0, 10.0))->capture_default_str();
  cmd->add_option("--jitter", options.link.jitter, "V2I delay jitter, s")->check(finiteNumber(0.0, 10.0))->capture_default_str();
  cmd->add_option("--loss", options.link.loss, "V2I loss probability")->check(finiteNumber(0.0, 1.0))->capture_default_str();
  cmd->add_option("--rsu-processing", options.rsu_processing,
                  "time the RSU takes from the end of its sweep to sending the fix, s (simulated, so runs repeat; "
                  "the measured time is in rsu_fixes.csv)")
      ->check(finiteNumber(0.0, 10.0))
      ->capture_default_str();
  cmd->add_flag("--compare-ideal", options.ideal_comparison,
               "also image every RSU frame in the ideal twin (no error sources) and fix it: ideal_error_m in rsu_frames.csv, beside "
               "the real fixes in rsu_fix_error.svg");
  cmd->add_flag("--rsu-frames", options.record_rsu_frames,
                "also record what each RSU's own node takes in (coloc rsu-node): its LiDAR frames on /rsu/<id>/points and the "
                "connected vehicles' CAMs on /v2x/cam");
  static std::string rsu_background = "learned";
  cmd->add_option("--rsu-background", rsu_background,
                  "how each RSU gets its background: learned from frames of the busy street before the drive, as on site, or "
                  "surveyed, the empty street as the map has it (no real RSU has one)")
      ->check(CLI::IsMember({"learned", "surveyed"}))
      ->capture_default_str();
  static bool ideal = false;
  cmd->add_flag("--ideal", ideal, "drive the ideal twin: the scenario without its error sources (errors: preset ideal)");
  cmd->callback([] {
    sim::Scenario scenario = sim::loadScenario(scenario_path);
    if (ideal) sim::setErrorSources(scenario, sim::ErrorSources::ideal());
    options.out_dir = out_dir;
    if (rsu_background == "surveyed") options.rsu_commissioning_frames = 0;
    ProgressBar progress("simulating");
    options.progress = [&](double f) { progress.update(f); };
    const TwinRecordingSummary s = recordTwin(scenario, options);
    progress.finish();
    std::printf("simulated %s: %.1f s of driving in %.1f s (%.1fx real time)\n", scenario.name.c_str(), s.drive_seconds, s.wall_seconds,
                s.drive_seconds / s.wall_seconds);
    std::printf("  %llu roof scans, %llu RSU fixes recorded (%llu lost on the link); %.1f M rays cast at %.2f M rays/s\n",
                (unsigned long long)s.scans, (unsigned long long)s.fixes, (unsigned long long)s.fixes_lost, s.rays * 1e-6,
                s.rays / std::max(s.ray_casting_seconds, 1e-9) * 1e-6);
    if (s.connected_fixes)
      std::printf("  %llu fixes sent to the other connected vehicles (addressed to them, on the same topics: the ego's log has them)\n",
                  (unsigned long long)s.connected_fixes);
    std::printf("  time: survey map %.1f s, ray casting %.1f s, LiDAR noise and dropouts %.1f s, roadside perception %.2f s, the rest %.1f s\n",
                s.map_seconds, s.ray_casting_seconds, s.lidar_seconds, s.perception_seconds,
                s.wall_seconds - s.map_seconds - s.ray_casting_seconds - s.lidar_seconds - s.perception_seconds);
    // A scenario's RSU the route never brings within coverage is most likely a mistake in the scenario.
    for (const sim::ScenarioRsu& r : scenario.rsus)
      if (s.rsu_frames.count(r.id) == 0)
        std::printf("  note: %s (%s) never had the vehicle within its coverage: no frame, no fix\n", r.id.c_str(), r.lidar_model.c_str());
    // What is there to see: the plots exist only when an RSU sent something to plot.
    std::string wrote;
    for (const char* name : {"log/", "map/", "fuse.yaml", "rsu.yaml", "rsu_fixes.csv", "rsu_frames.csv", "rsu_fix_error.svg", "rsu_perception.csv",
                             "rsu_perception.svg"})
      if (std::filesystem::exists(out_dir + "/" + name)) wrote += (wrote.empty() ? "" : ", ") + std::string(name);
    std::printf("  wrote %s/{%s}\n", out_dir.c_str(), wrote.c_str());
  });
}

}  // namespace coloc::tools
