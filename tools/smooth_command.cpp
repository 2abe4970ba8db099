// `coloc smooth LOG`: the log through the filter, then every measurement at once through the Ceres
// smoother; writes the smoothed trajectory, a summary and the error of both along the route.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "coloc/core/error.hpp"
#include "coloc/replay/log_smoother.hpp"
#include "coloc/replay/svg_plot.hpp"
#include "commands.hpp"
#include "number_checks.hpp"
#include "log_options.hpp"
#include "progress.hpp"

namespace coloc::tools {

namespace {

using namespace coloc::replay;

void writeErrorPlot(const SmoothResult& r, const std::string& path) {
  Plot plot;
  plot.title = "Position error against ground truth: filter and smoother";
  plot.x_label = "time since start [s]";
  plot.y_label = "planar error [m]";
  plot.y_from_zero = true;
  auto series = [](const std::vector<ErrorSample>& errors, std::string label, std::string color, Stamp origin) {
    PlotSeries s{std::move(label), {}, {}, std::move(color), false};
    for (const ErrorSample& e : errors) s.x.push_back(toSeconds(e.stamp - origin)), s.y.push_back(e.error);
    return s;
  };
  const Stamp origin = r.filter.errors.empty() ? 0 : r.filter.errors.front().stamp;
  plot.series.push_back(series(r.filter_errors_matched, "filter", "#ff7f0e", origin));
  plot.series.push_back(series(r.errors, "smoother", "#1f77b4", origin));
  writeSvg(path, plot);
}

}  // namespace

void addSmoothCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("smooth", "Smooth a recorded log with every measurement at once (Ceres), beside the filter");
  static LogOptions o{"", "", "", "", "coloc_smooth"};
  addLogOptions(cmd, o);
  static bool calibrate = false;
  static double window = 0.0, window_step = 0.5;
  cmd->add_option("--window", window, "fixed-lag mode: a window of this many seconds behind the filter (0 = the whole log at once)")
      ->check(finiteNumber(0.0))
      ->capture_default_str();
  cmd->add_option("--window-step", window_step, "how far the window moves each time, s")->check(finiteNumber(0.0, std::numeric_limits<double>::infinity(), true))->capture_default_str();
  cmd->add_flag("--calibrate-rsus", calibrate,
                "estimate each RSU's survey and clock offsets with the trajectory; writes rsu_calibrated.yaml for the next drives");
  cmd->callback([] {
    const std::string& log = o.log;
    const std::string& out_dir = o.out;
    SmoothOptions options;
    options.replay = replayOptions(o);
    options.smoother = smootherOptionsFor(options.replay.config, calibrate);
    options.calibrate_rsus = calibrate;
    options.window = window;
    options.window_step = window_step;
    ProgressBar progress("filtering");
    options.replay.progress = [&](double f) { progress.update(f); };
    const SmoothResult r = smoothLog(log, options);
    progress.finish();
    createOutputFolder(out_dir);
    io::writeTumTrajectory(out_dir + "/smoothed.tum", r.smoothed, "coloc smoothed trajectory\nt x y z qx qy qz qw (t: header-stamp clock, s)");
    std::ofstream(out_dir + "/summary.json") << r.summaryJson(log);
    {
      // Every state with its marginal position uncertainty (empty where the drive does not determine it).
      std::ofstream states(out_dir + "/smoothed.csv");
      states << "stamp_s,x,y,yaw,yaw_bias,vx,wz,sd_x_m,sd_y_m,cov_xy_m2\n";
      char line[400];
      for (const smoother::SmoothedState& st : r.states) {
        std::snprintf(line, sizeof line, "%s,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,", formatSeconds(st.stamp).c_str(), st.state[0], st.state[1],
                      st.state[2], st.state[3], st.state[4], st.state[5]);
        states << line;
        if (st.position_covariance) {
          const Eigen::Matrix2d& c = *st.position_covariance;
          std::snprintf(line, sizeof line, "%.6g,%.6g,%.6g\n", std::sqrt(std::max(0.0, c(0, 0))), std::sqrt(std::max(0.0, c(1, 1))), c(0, 1));
          states << line;
        } else {
          states << ",,\n";
        }
      }
    }
    nlohmann::ordered_json timing = {{"replay_wall_s", r.filter.wall_seconds}, {"smoother_wall_s", r.wall_seconds},
                                     {"solver_s", r.summary.seconds}};
    if (r.fixed_lag) {
      timing["fixed_lag_mean_solve_s"] = r.fixed_lag->mean_solve_seconds;
      timing["fixed_lag_max_solve_s"] = r.fixed_lag->max_solve_seconds;
    }
    std::ofstream(out_dir + "/timing.json") << timing.dump(2) << "\n";
    if (!r.errors.empty()) {
      std::ofstream csv(out_dir + "/error.csv");
      csv << "stamp_s,estimator,error_m,along_m,across_m\n";
      for (const ErrorSample& e : r.filter_errors_matched) csv << formatSeconds(e.stamp) << ",filter," << e.error << "," << e.along << "," << e.across << "\n";
      for (const ErrorSample& e : r.errors) csv << formatSeconds(e.stamp) << ",smoother," << e.error << "," << e.along << "," << e.across << "\n";
      writeErrorPlot(r, out_dir + "/error.svg");
    }
    std::printf("coloc smooth %s\n", log.c_str());
    if (!r.filter.recovered.empty()) std::printf("%s", describeRecovered(r.filter.recovered).c_str());
    std::printf("  %d states, %d pose and %d twist residuals; Ceres: %s\n", r.summary.states,
                r.summary.pose_residuals, r.summary.twist_residuals, r.summary.report.c_str());
    std::printf("  smoothed %.1f s of log in %.2f s (solver %.2f s); %zu measurements down-weighted by the robust loss\n",
                toSeconds(r.smoothed.back().stamp - r.smoothed.front().stamp), r.wall_seconds, r.summary.seconds,
                r.summary.down_weighted.size());
    if (r.fixed_lag)
      std::printf("  fixed lag: %d windows of %.1f s every %.2f s; each solved in %.1f ms on average, %.1f ms at most (the latency it adds)\n",
                  r.fixed_lag->windows, r.fixed_lag->window, r.fixed_lag->step, 1e3 * r.fixed_lag->mean_solve_seconds,
                  1e3 * r.fixed_lag->max_solve_seconds);
    for (const auto& o : r.odometry)
      std::printf("  odometry %s: speed scale %.5f (sd %.5f), yaw-rate bias %+.5f rad/s (sd %.5f)\n", o.source.c_str(), o.speed_scale, o.sd_speed_scale,
                  o.yaw_rate_bias, o.sd_yaw_rate_bias);
    if (!r.summary.noise.empty()) {
      std::printf("  noise measured on the drive (standard deviation / the messages' own):");
      for (const auto& n : r.summary.noise) std::printf(" %s %.3g", n.source.c_str(), n.scale);
      std::printf("\n");
    }
    if (r.summary.pose_bias_sd) std::printf("  NDT's slowly varying bias, as measured where fixes show it: %.1f cm\n", 100 * *r.summary.pose_bias_sd);
    for (std::size_t i = 0; i < r.summary.down_weighted.size() && i < 5; ++i) {
      const auto& d = r.summary.down_weighted[i];
      std::printf("    %s stamped %s: %.1f sigma, weight %.3f\n", d.source.c_str(), formatSeconds(d.stamp).c_str(), d.mahalanobis, d.weight);
    }
    for (const auto& [id, c] : r.calibrations) {
      if (c.observable && c.clock_observable)
        std::printf("  RSU %s calibration: survey %+.4f m, %+.4f m, %+.3f deg; clock %+.2f ms (sd %.4f m, %.4f m, %.3f deg, %.2f ms)\n",
                    id.c_str(), c.dx, c.dy, c.dyaw * 180.0 / M_PI, c.clock_offset * 1e3, c.sd_dx, c.sd_dy, c.sd_dyaw * 180.0 / M_PI,
                    c.sd_clock_offset * 1e3);
      else if (c.observable)
        std::printf("  RSU %s calibration: survey %+.4f m, %+.4f m, %+.3f deg (sd %.4f m, %.4f m, %.3f deg); %s\n", id.c_str(), c.dx, c.dy,
                    c.dyaw * 180.0 / M_PI, c.sd_dx, c.sd_dy, c.sd_dyaw * 180.0 / M_PI, c.note.c_str());
      else
        std::printf("  RSU %s calibration: not determined (%s)\n", id.c_str(), c.note.c_str());
    }
    if (calibrate) {
      std::ofstream(out_dir + "/rsu_calibrated.yaml") << r.calibratedRegistry().toYaml();
      std::printf("  wrote %s/rsu_calibrated.yaml: the registry with the calibrations found, for the next drives\n", out_dir.c_str());
    }
    if (!r.errors.empty()) {
      const ErrorStats f = errorStats(r.filter_errors_matched), s = errorStats(r.errors);
      std::printf("  position error vs ground truth: filter mean %.4f m (RMSE %.4f), smoother mean %.4f m (RMSE %.4f): %.2fx\n", f.mean,
                  f.rmse, s.mean, s.rmse, f.mean > 0 ? s.mean / f.mean : 0.0);
    } else {
      std::printf("  no ground truth in the log: no error figures\n");
    }
    std::printf("  wrote %s/{smoothed.tum, smoothed.csv, summary.json, timing.json%s}\n", out_dir.c_str(), r.errors.empty() ? "" : ", error.csv, error.svg");
  });
}

}  // namespace coloc::tools
