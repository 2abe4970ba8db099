// `coloc play LOG`: a recorded log over DDS at its recorded pace, as `ros2 bag play` does, without ROS.
#include <atomic>
#include <csignal>
#include <cstdio>

#include "coloc/core/error.hpp"
#include "coloc/live/log_player.hpp"
#include "commands.hpp"
#include "number_checks.hpp"
#include "dds_options.hpp"
#include "log_options.hpp"
#include "progress.hpp"
#include "teardown_watchdog.hpp"

namespace coloc::tools {

namespace {

std::atomic<bool> g_stop_play{false};
extern "C" void requestPlayStop(int) { g_stop_play = true; }

}  // namespace

void addPlayCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("play", "Publish a recorded log (.mcap, .db3 or rosbag2 folder) over DDS with ROS 2 names, types and QoS");
  static std::string log;
  static live::PlayOptions options;
  static bool no_clock = false;
  static DdsOptions dds;
  cmd->add_option("LOG", log, "the recording")->required();
  cmd->add_option("--rate", options.rate, "playback speed: 2 = twice as fast as recorded")->check(finiteNumber(0.0, 1000.0, true))->capture_default_str();
  cmd->add_option("--topics", options.topics, "play only these topics");
  cmd->add_flag("--loop", options.loop, "start again at the end, until interrupted");
  cmd->add_option("--passes", options.passes, "with --loop: stop after this many passes (0 = until interrupted)")
      ->check(wholeNumber(0, 1000000))->capture_default_str();
  cmd->add_flag("--no-clock", no_clock, "do not publish the log's time on /clock");
  cmd->add_option("--clock-frequency", options.clock_frequency, "Hz of /clock between messages")->check(finiteNumber(1.0, 10000.0))->capture_default_str();
  cmd->add_option("--delay", options.delay, "seconds to wait before the first message, for discovery")->check(finiteNumber(0.0, 3600.0))->capture_default_str();
  static std::vector<std::string> remaps;
  cmd->add_option("--remap", remaps, "publish a topic under another name: FROM:=TO (repeatable), as ros2 bag play --remap");
  addRecoverFlag(cmd, options.recover);
  cmd->add_option("--name", dds.name, "DDS participant name (and security file prefix)");
  addDdsOptions(cmd, dds);
  cmd->callback([] {
    options.publish_clock = !no_clock;
    for (const std::string& r : remaps) {
      const auto at = r.find(":=");
      if (at == std::string::npos || at == 0) throw Error("--remap '" + r + "': expected FROM:=TO");
      options.remap[r.substr(0, at)] = r.substr(at + 2);
    }
    options.dds = ddsConfig(dds, "coloc_player");
    printSecurity(options.dds);
    std::signal(SIGINT, requestPlayStop);
    std::signal(SIGTERM, requestPlayStop);
    options.stop_requested = [] { return g_stop_play.load(); };
    ProgressBar progress("playing");
    options.progress = [&](double f) { progress.update(f); };
    TeardownWatchdog watchdog("play");
    const TeardownWatchdog::ArmOnExit arm_on_exit(watchdog);
    const live::PlayReport r = live::playLog(log, options);
    progress.finish();
    std::uint64_t total = 0;
    for (const auto& [topic, n] : r.published) total += n;
    std::printf("played %llu messages of %.1f s of log in %.1f s%s (latest %.1f ms behind its time)%s\n", (unsigned long long)total,
                r.log_seconds, r.wall_seconds, r.loops > 1 ? (", " + std::to_string(r.loops) + " passes").c_str() : "", r.max_lag_ms,
                r.stopped ? ", stopped on a signal" : "");
    std::printf("%s", describeRecovered(r.recovered).c_str());
    for (const auto& [topic, n] : r.published) std::printf("  %-40s %llu\n", topic.c_str(), (unsigned long long)n);
    if (r.failed) std::printf("  %llu writes refused by DDS\n", (unsigned long long)r.failed);
  });
}

}  // namespace coloc::tools
