// `coloc fuse LOG`: replays a recording through the filter and writes the fused trajectory, a summary
// and plots.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "coloc/core/error.hpp"
#include "commands.hpp"
#include "log_options.hpp"
#include "coloc/replay/log_replay.hpp"
#include "progress.hpp"
#include "report_lines.hpp"
#include "coloc/replay/svg_plot.hpp"

namespace coloc::tools {

namespace {

namespace fs = std::filesystem;
using namespace coloc::replay;

void printSummary(const std::string& log, const ReplayResult& r, const std::string& out_dir, bool map_given) {
  std::printf("coloc fuse %s\n", log.c_str());
  if (!r.recovered.empty()) std::printf("%s", describeRecovered(r.recovered).c_str());
  std::printf("  %llu messages over %.1f s of log; clock: %s", static_cast<unsigned long long>(r.messages_read), r.log_duration,
              r.clock == ClockMode::kSeparate ? "header stamps and log times on different clocks" : "one clock");
  if (r.clock == ClockMode::kSeparate)
    std::printf("\n  (stamp clock runs at %.5f x log time; delays measured from the fitted relation, the shortest about 0)",
                r.clock_fit.rate);
  std::printf("\n\n  %-22s %-44s %-13s %9s %12s\n", "topic", "type", "role", "messages", "delay median");
  for (const TopicUse& t : r.topics) {
    std::printf("  %-22s %-44s %-13s %9llu", t.topic.c_str(), t.type.c_str(), toString(t.role),
                static_cast<unsigned long long>(t.messages));
    if (t.role != InputRole::kIgnore && t.role != InputRole::kStaticTransforms) std::printf(" %9.1f ms", 1e3 * t.delay_median);
    if (!t.note.empty()) std::printf("  (%s)", t.note.c_str());
    if (t.decode_errors) std::printf("  %llu undecodable", static_cast<unsigned long long>(t.decode_errors));
    if (t.fallback_covariance) std::printf("  %llu without covariance: fallback used", static_cast<unsigned long long>(t.fallback_covariance));
    if (t.link_dropped) std::printf("  %llu lost on the emulated link", static_cast<unsigned long long>(t.link_dropped));
    std::printf("\n");
  }
  std::printf("\n  %-22s %8s %8s %7s %7s %7s %7s %8s %7s\n", "source", "received", "applied", "gated", "too_old", "future",
              "invalid", "no_init", "pending");
  for (const auto& s : r.sources) {
    const auto& c = s.counters;
    std::printf("  %-22s %8llu %8llu %7llu %7llu %7llu %7llu %8llu %7llu\n", s.name.c_str(), (unsigned long long)c.received,
                (unsigned long long)c.applied, (unsigned long long)c.gated, (unsigned long long)c.too_old,
                (unsigned long long)c.from_future, (unsigned long long)c.invalid, (unsigned long long)c.not_initialized,
                (unsigned long long)c.pending);
  }
  std::printf("\n  %-22s %8s %13s %15s %10s %10s  (normalized innovation squared at first use: honest covariances\n"
              "  %-22s %8s %13s %15s %10s %10s   give 1 per degree of freedom, 2.5 %% of samples above and below)\n",
              "source", "samples", "NIS per dof", "95 % band", "above", "below", "", "", "", "", "", "");
  for (const auto& s : r.sources) {
    const auto& c = s.counters;
    if (!c.nis_samples) continue;
    const auto band = fusion::nisBand(c.nis_dof);
    const double n = static_cast<double>(c.nis_samples);
    std::printf("  %-22s %8llu %13.3f %7.3f-%-7.3f %9.1f%% %9.1f%%\n", s.name.c_str(), (unsigned long long)c.nis_samples,
                c.nis_sum / static_cast<double>(c.nis_dof), band.first, band.second, 100.0 * c.nis_above / n, 100.0 * c.nis_below / n);
    std::string parts;
    for (std::size_t k = 0; k < c.nis_component_sum.size(); ++k) {
      if (!c.nis_component_samples[k]) continue;
      char buf[96];
      const double n = static_cast<double>(c.nis_component_samples[k]);
      std::snprintf(buf, sizeof buf, "%s%s %.3g (S %.0f %% prediction)", parts.empty() ? "" : ", ",
                    fusion::toString(static_cast<fusion::NisComponent>(k)), c.nis_component_sum[k] / n, 100.0 * c.nis_prediction_share_sum[k] / n);
      parts += buf;
    }
    if (!parts.empty()) std::printf("  %-22s %8s %s\n", "", "", (parts + " (each component alone; the share of its S that is the filter's prediction, not the source's covariance)").c_str());
  }
  for (const auto& [id, c] : r.fixes) std::printf("  %s\n", fixLine(id, r.pipeline_report).c_str());
  std::printf("  localization: %s\n", localizationLine(r.pipeline_report).c_str());
  for (const std::string& line : r.pipeline_report.first_events) std::printf("    %s\n", line.c_str());
  for (const TopicUse& t : r.topics)
    if (!t.first_error.empty()) std::printf("  first decode error: %s\n", t.first_error.c_str());
  if (r.ndt_used) {
    const auto& n = r.ndt;
    std::printf("\n  NDT: %llu scans -> %llu poses; rejected: %llu low score, %llu iteration limit, %llu oscillation, %llu empty, "
                "%llu off the map; %llu before the filter could predict; mean alignment %.1f ms; map rebuilt %zu times\n",
                (unsigned long long)n.scans, (unsigned long long)n.poses, (unsigned long long)n.low_score,
                (unsigned long long)n.max_iterations, (unsigned long long)n.oscillation, (unsigned long long)n.empty_scan,
                (unsigned long long)n.no_map, (unsigned long long)r.scans_without_guess, n.scans ? n.align_ms_total / n.scans : 0.0,
                r.map.builds);
    const Vector6d& l = r.lidar_pose;
    std::printf("  LiDAR on the vehicle: [%.3f, %.3f, %.3f] m, roll %.2f, pitch %.2f, yaw %.2f deg, from %s\n", l[0], l[1], l[2], l[3] * 180.0 / M_PI,
                l[4] * 180.0 / M_PI, l[5] * 180.0 / M_PI, r.lidar_pose_from.c_str());
    std::printf("%s", learnedLines(r.pipeline_report).c_str());
  } else if (map_given) {
    std::printf("\n  the map was not used: no topic of the log is a scan (PointCloud2) for NDT to match\n");
  }
  if (!r.errors.empty()) {
    const ErrorStats s = r.errorStats();
    std::printf("\n  position error vs ground truth (%zu ticks): mean %.4f m, RMSE %.4f m, max %.4f m; bias %+.4f m along, %+.4f m across\n",
                r.errors.size(), s.mean, s.rmse, s.max, s.along_mean, s.across_mean);
    for (const auto& [source, samples] : r.input_errors) {
      const ErrorStats i = errorStats(samples);
      std::printf("  %-22s its own poses (%zu): mean %.4f m, RMSE %.4f m; bias %+.4f m along, %+.4f m across\n", source.c_str(),
                  samples.size(), i.mean, i.rmse, i.along_mean, i.across_mean);
      // The filter's settled estimate beside it where it is accurate: on this drive's stretches, and
      // on the reference drive's places (replay.input_reference), which carry no luck of this drive.
      const auto c = r.input_comparison.find(source);
      if (c == r.input_comparison.end()) continue;
      const InputComparison& k = c->second;
      if (k.accurate_samples > 0)
        std::printf("  %-22s where it is accurate (%zu poses on %.0f m stretches under %.2f m): its own %.4f m, the filter's settled %.4f m (%.3fx)\n", "",
                    k.accurate_samples, k.stretch_length, k.accurate_below, k.accurate_input_mean, k.accurate_settled_mean,
                    k.accurate_settled_mean / k.accurate_input_mean);
      if (k.places_given)
        std::printf("  %-22s where it was accurate on the reference drive (%zu poses): its own %.4f m, the filter's settled %.4f m (%.3fx)\n", "",
                    k.place_samples, k.place_input_mean, k.place_settled_mean, k.place_samples ? k.place_settled_mean / k.place_input_mean : 0.0);
    }
  } else {
    std::printf("\n  no ground truth in the log: no error figures\n");
  }
  std::printf("  fused %zu poses (%.1f s) in %.3f s: %.0fx real time\n", r.fused.size(), toSeconds(r.last_stamp - r.first_stamp),
              r.wall_seconds, r.wall_seconds > 0 ? r.log_duration / r.wall_seconds : 0.0);
  const bool quality = r.input_errors.count(pipeline::kNdtSource) && !r.input_errors.at(pipeline::kNdtSource).empty();
  std::printf("  wrote %s/{fused.tum, summary.json, trajectory.svg%s%s}\n", out_dir.c_str(),
              r.errors.empty() ? "" : ", error.csv, error.svg, input_error.csv, input_error.svg",
              quality ? ", ndt_quality.yaml (NDT's error by place, for ndt.quality_map)" : "");
}

void writePlots(const ReplayResult& r, const std::string& dir, const std::string& log) {
  Plot map;
  map.title = "Trajectory: " + fs::path(log).filename().string();
  map.x_label = "x [m]";
  map.y_label = "y [m]";
  map.equal_aspect = true;
  auto series = [](const std::vector<io::TrajectoryPoint>& points, std::string label, std::string color, bool dots) {
    PlotSeries s{std::move(label), {}, {}, std::move(color), dots};
    for (const auto& p : points) s.x.push_back(p.pose.position.x()), s.y.push_back(p.pose.position.y());
    return s;
  };
  if (!r.ground_truth.empty()) map.series.push_back(series(r.ground_truth, "ground truth", "#333333", false));
  map.series.push_back(series(r.pose_inputs, "pose measurements", "#ff7f0e", true));
  map.series.push_back(series(r.fused, "fused", "#1f77b4", false));
  writeSvg(dir + "/trajectory.svg", map);
  if (r.errors.empty()) return;
  // Plots against time since the first error sample, from zero up.
  const auto overTime = [](std::string title, std::string y_label) {
    Plot p;
    p.title = std::move(title);
    p.x_label = "time since start [s]";
    p.y_label = std::move(y_label);
    p.y_from_zero = true;
    return p;
  };
  Plot error = overTime("Position error against ground truth", "planar error [m]");
  PlotSeries e{"fused", {}, {}, "#1f77b4", false};
  for (const ErrorSample& s : r.errors) e.x.push_back(toSeconds(s.stamp - r.errors.front().stamp)), e.y.push_back(s.error);
  error.series.push_back(e);
  writeSvg(dir + "/error.svg", error);
  if (r.input_errors.empty()) return;
  // Each pose input's error beside the deviation it claimed: where it said it did not know, and where
  // it was wrong while sure.
  Plot inputs = overTime("Pose inputs against ground truth, and the deviation each claimed", "planar error, claimed 1-sigma [m]");
  const auto claimed = r.claimedCovariances();
  for (const auto& [source, samples] : r.input_errors) {
    PlotSeries err{source + ": error", {}, {}, "", true}, sd{source + ": claimed", {}, {}, "", false};
    for (const ErrorSample& s : samples) {
      const double t = toSeconds(s.stamp - r.errors.front().stamp);
      err.x.push_back(t), err.y.push_back(s.error);
      if (const auto c = claimed.find({source, s.stamp}); c != claimed.end()) {
        const Eigen::Vector2d d = alongAcrossDeviation(c->second, s.truth_heading);
        if (d.allFinite()) sd.x.push_back(t), sd.y.push_back(d.norm());
      }
    }
    inputs.series.push_back(err);
    if (!sd.x.empty()) inputs.series.push_back(sd);
  }
  writeSvg(dir + "/input_error.svg", inputs);
}

}  // namespace

void addFuseCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("fuse", "Fuse a recorded ROS 2 log (.mcap, .db3 or rosbag2 folder) and write the trajectory");
  static LogOptions o{"", "", "", "", "coloc_out"};
  addLogOptions(cmd, o);
  cmd->callback([] {
    const std::string& log = o.log;
    const std::string& out_dir = o.out;
    ReplayOptions options = replayOptions(o);
    ProgressBar progress("fusing");
    options.progress = [&](double f) { progress.update(f); };
    const ReplayResult result = replayLog(log, options);
    progress.finish();
    createOutputFolder(out_dir);
    // The header names no file, so the same data in another storage format gives the same bytes.
    io::writeTumTrajectory(out_dir + "/fused.tum", result.fused,
                           "coloc fused trajectory\nt x y z qx qy qz qw (t: header-stamp clock, s)");
    std::ofstream(out_dir + "/summary.json") << result.summaryJson(log);
    nlohmann::ordered_json timing = {{"replay_wall_s", result.wall_seconds},
                                     {"speed_x_realtime", result.wall_seconds > 0 ? result.log_duration / result.wall_seconds : 0.0}};
    std::ofstream(out_dir + "/timing.json") << timing.dump(2) << "\n";
    if (!result.errors.empty()) result.writeErrorCsv(out_dir + "/error.csv");
    if (!result.input_errors.empty()) result.writeInputErrorCsv(out_dir + "/input_error.csv");
    // NDT's error by place, for later drives on the same roads (ndt.quality_map): a log with ground truth.
    if (const auto ndt = result.input_errors.find(pipeline::kNdtSource); ndt != result.input_errors.end() && !ndt->second.empty())
      std::ofstream(out_dir + "/ndt_quality.yaml") << replay::ndtQualityMap(ndt->second).toYaml();
    writePlots(result, out_dir, log);
    printSummary(log, result, out_dir, !options.map.empty());
  });
}

}  // namespace coloc::tools
