// `coloc localize`: the vehicle pipeline live over DDS, with a status line per second; on SIGINT or
// SIGTERM it stops cleanly and writes fused.tum and summary.json as `coloc fuse` does.
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>

#include "coloc/core/error.hpp"
#include "coloc/io/trajectory_file.hpp"
#include "coloc/live/live_localizer.hpp"
#include "commands.hpp"
#include "number_checks.hpp"
#include "dds_options.hpp"
#include "report_lines.hpp"
#include "teardown_watchdog.hpp"

namespace coloc::tools {

namespace {

std::atomic<bool> g_stop{false};
extern "C" void requestStop(int) { g_stop = true; }

// Fixes applied by the filter, over every RSU.
std::uint64_t applied(const pipeline::PipelineReport& r) {
  std::uint64_t n = 0;
  for (const auto& [id, c] : r.filter_of_fixes) n += c.applied;
  return n;
}

void printStatus(const live::LiveStatus& s, double elapsed) {
  std::printf("[%6.1f s] ", elapsed);
  if (s.estimate) {
    const auto& e = *s.estimate;
    std::printf("%s t=%s x=%.3f y=%.3f yaw=%.2f deg sd=%.3f m v=%.2f m/s", fusion::toString(s.report.state), formatSeconds(e.stamp).c_str(),
                e.pose.position.x(), e.pose.position.y(), rollPitchYaw(e.pose.orientation)[2] * 180.0 / M_PI,
                std::sqrt(std::max(0.0, e.pose_covariance(0, 0) + e.pose_covariance(1, 1))), e.linear_velocity.x());
    if (s.report.state != fusion::LocalizationState::kLocalized && !s.report.state_reason.empty())
      std::printf(" (%s)", s.report.state_reason.c_str());
  } else {
    std::printf("initialising (%s)", s.report.state_reason.empty() ? "waiting for an initial pose, a pose source or an RSU fix"
                                                                    : s.report.state_reason.c_str());
  }
  std::printf(" | published %llu", (unsigned long long)s.published);
  if (s.report.ndt_used) {
    // Scans NDT never matched: replaced by a newer one while it was busy, or with no guess to start from.
    std::printf(" | ndt %llu poses of %llu scans", (unsigned long long)s.report.ndt.poses, (unsigned long long)s.report.ndt.scans);
    if (s.report.scans_superseded) std::printf(", %llu skipped (busy)", (unsigned long long)s.report.scans_superseded);
    if (s.report.scans_without_guess) std::printf(", %llu before a guess", (unsigned long long)s.report.scans_without_guess);
  }
  // What the transport lost, and the inputs that fell silent (more than 1 s since their last message).
  std::uint64_t lost = 0;
  for (const auto& t : s.topics) lost += t.sequence_gaps + t.rejected;
  if (lost) {
    std::printf(" | LOST");
    for (const auto& t : s.topics)
      if (t.sequence_gaps + t.rejected) std::printf(" %s %llu", t.topic.c_str(), (unsigned long long)(t.sequence_gaps + t.rejected));
  }
  for (const auto& t : s.topics)
    if (t.last_arrival != 0 && s.clock > t.last_arrival && toSeconds(s.clock - t.last_arrival) > 1.0 && t.topic != "/clock")
      std::printf(" | %s silent %.1f s", t.topic.c_str(), toSeconds(s.clock - t.last_arrival));
  if (!s.report.fixes.empty()) {
    std::uint64_t received = 0, refused = 0;
    for (const auto& [id, c] : s.report.fixes) received += c.received, refused += c.received - c.passed_checks;
    std::uint64_t gated = 0, waiting = 0;
    for (const auto& [id, c] : s.report.filter_of_fixes) gated += c.gated, waiting += c.not_initialized;
    std::printf(" | fixes %llu received, %llu refused, %llu gated, %llu before start, %llu applied", (unsigned long long)received,
                (unsigned long long)refused, (unsigned long long)gated, (unsigned long long)waiting, (unsigned long long)applied(s.report));
  }
  if (s.report.recoveries || s.report.clock_resets)
    std::printf(" | recoveries %llu, clock resets %llu", (unsigned long long)s.report.recoveries, (unsigned long long)s.report.clock_resets);
  std::printf(" | rejected %llu | writers %d", (unsigned long long)s.report.rejections, s.matched_writers);
  if (!s.trajectory_error.empty()) std::printf(" | fused.tum stopped: %s", s.trajectory_error.c_str());
  std::printf("\n");
  std::fflush(stdout);
}

}  // namespace

void addLocalizeCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("localize", "Localize live over DDS: scans, twist and RSU fixes in, the fused pose out (ROS 2 names and QoS)");
  static std::string map, config_path, registry, out_dir = "coloc_live";
  static bool sim_time = false;
  static double duration = 0.0, idle = 0.0;
  static DdsOptions dds;
  cmd->add_option("--map", map, "point-cloud map (PCD file or folder of PCD tiles) for NDT; without it, no scan is subscribed to");
  static bool discover = false;
  cmd->add_flag("--discover-inputs", discover, "take every topic on the domain by its type, as `coloc fuse` takes a log's (live.discover_inputs)");
  cmd->add_option("--config", config_path, "YAML configuration (see `coloc config`; topics in its live: section)")->check(CLI::ExistingFile);
  cmd->add_option("--rsu-registry", registry, "RSU registry (YAML): whose fixes to subscribe to and accept (default: rsu.registry of the config)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", out_dir, "where fused.tum and summary.json go when it stops")->capture_default_str();
  cmd->add_flag("--use-sim-time", sim_time, "run on the time received on /clock (as a ROS 2 node with use_sim_time, for `coloc play`)");
  cmd->add_option("--duration", duration, "stop after this many seconds (0 = until SIGINT or SIGTERM)")->check(finiteNumber(0.0));
  cmd->add_option("--idle-exit", idle, "stop once no input arrived for this many seconds, after the first (0 = never)")->check(finiteNumber(0.0));
  cmd->add_option("--name", dds.name, "DDS participant name (and security file prefix)");
  addDdsOptions(cmd, dds);
  cmd->callback([] {
    live::LiveOptions options;
    if (!config_path.empty()) options.config = pipeline::loadConfig(config_path);
    if (!registry.empty()) options.registry = rsu_client::RsuRegistry::load(registry);
    if (dds.reliable) options.config.live.reliable = true;
    if (discover) options.config.live.discover_inputs = true;
    options.map = map;
    options.use_sim_time = sim_time;
    options.dds = ddsConfig(dds, "coloc_localizer");
    // Starts, recoveries, state changes and clock resets, as they happen.
    std::error_code ec;
    std::filesystem::create_directories(out_dir, ec);
    if (ec) throw Error(out_dir + ": cannot create the output folder: " + ec.message());
    options.trajectory_file = out_dir + "/fused.tum";
    options.on_event = [](const std::string& line) {
      std::printf("event: %s\n", line.c_str());
      std::fflush(stdout);
    };
    printSecurity(options.dds);
    std::signal(SIGINT, requestStop);
    std::signal(SIGTERM, requestStop);

    TeardownWatchdog watchdog("localize");
    watchdog.arm(1);  // a participant that fails to come up is deleted at once
    live::LiveLocalizer localizer(options);
    watchdog.disarm();
    const TeardownWatchdog::ArmOnExit arm_on_exit(watchdog);
    std::printf("localizing: scans %s, twist %s (%s), initial pose %s; out %s and %s; domain %d, %s%s\n", options.config.live.scan_topic.c_str(),
                options.config.live.twist_topic.c_str(), options.config.live.twist_type.c_str(), options.config.live.initial_pose_topic.c_str(),
                options.config.live.pose_topic.c_str(), options.config.live.odometry_topic.c_str(), options.dds.domain,
                options.dds.loopback_only ? "loopback only" : "every interface", sim_time ? "; time from /clock" : "");
    std::fflush(stdout);

    const auto start = std::chrono::steady_clock::now();
    auto last_status = start;
    auto last_input = start;
    std::uint64_t inputs_seen = 0;
    while (!g_stop.load()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      const auto now = std::chrono::steady_clock::now();
      const double elapsed = std::chrono::duration<double>(now - start).count();
      const live::LiveStatus s = localizer.status();
      std::uint64_t inputs = 0;
      for (const auto& t : s.topics) inputs += t.received;
      if (inputs != inputs_seen) inputs_seen = inputs, last_input = now;
      if (now - last_status >= std::chrono::seconds(1)) {
        last_status = now;
        printStatus(s, elapsed);
      }
      if (duration > 0.0 && elapsed >= duration) break;
      if (idle > 0.0 && inputs_seen > 0 && std::chrono::duration<double>(now - last_input).count() >= idle) break;
    }
    localizer.stop();
    std::ofstream(out_dir + "/summary.json") << localizer.summaryJson();
    const live::LiveStatus s = localizer.status();
    std::printf("stopped%s: %llu estimates written to %s/fused.tum; summary.json beside it\n", g_stop.load() ? " on a signal" : "",
                (unsigned long long)s.trajectory_points, out_dir.c_str());
    if (!s.trajectory_error.empty()) std::printf("  fused.tum stopped early: %s\n", s.trajectory_error.c_str());
    for (const auto& t : s.topics)
      std::printf("  %-48s %8llu messages %6llu undecodable %6llu lost (%llu gaps, %llu rejected)  longest gap %.2f s%s%s\n", t.topic.c_str(),
                  (unsigned long long)t.received, (unsigned long long)t.undecodable, (unsigned long long)(t.sequence_gaps + t.rejected),
                  (unsigned long long)t.sequence_gaps, (unsigned long long)t.rejected, t.longest_gap, t.first_error.empty() ? "" : "  first: ",
                  t.first_error.c_str());
    for (const auto& t : s.topics)
      if (t.from_before_clock_jump)
        std::printf("  %s: %llu sent before /clock went back and arriving after, dropped\n", t.topic.c_str(), (unsigned long long)t.from_before_clock_jump);
    if (s.report.ndt_used) std::printf("%s", learnedLines(s.report).c_str());
    for (const auto& [id, c] : s.report.fixes) std::printf("  %s\n", fixLine(id, s.report).c_str());
    std::printf("  localization: %s\n", localizationLine(s.report).c_str());
    for (const auto& line : s.report.first_rejections) std::printf("  rejected: %s\n", line.c_str());
    std::fflush(stdout);
  });
}

}  // namespace coloc::tools
