#include "coloc/replay/log_smoother.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>
#include <nlohmann/json.hpp>

#include "coloc/core/error.hpp"
#include "error_json.hpp"
#include "recovered_json.hpp"
#include "coloc/rsu_client/dds_transport.hpp"

namespace coloc::replay {

smoother::SmootherOptions smootherOptionsFor(const pipeline::Config& config, bool calibrating_rsus) {
  const fusion::EkfConfig& filter = config.fusion;
  const pipeline::SmootherSection& c = config.smoother;
  smoother::SmootherOptions o;
  o.rate = filter.predict_frequency;
  o.proc_stddev_yaw_c = std::max(filter.proc_stddev_yaw_c, smoother::SmootherOptions::kLeastProcessNoise);
  o.proc_stddev_vx_c = std::max(filter.proc_stddev_vx_c, smoother::SmootherOptions::kLeastProcessNoise);
  o.proc_stddev_wz_c = std::max(filter.proc_stddev_wz_c, smoother::SmootherOptions::kLeastProcessNoise);
  o.initial_yaw_bias_variance = filter.initial_yaw_bias_variance;
  o.robust = filter.pose_gate_alpha > 0.0;
  if (o.robust) o.gate_alpha = filter.pose_gate_alpha;
  o.estimate_noise = c.estimate_noise;
  o.calibrate_odometry = c.calibrate_odometry;
  o.odometry_scale_sd = c.odometry_scale_sd;
  o.odometry_yaw_rate_bias_sd = c.odometry_yaw_rate_bias_sd;
  using PoseBias = pipeline::SmootherSection::PoseBias;
  o.pose_bias = c.pose_bias == PoseBias::kAlways || (c.pose_bias == PoseBias::kWhenCalibrating && calibrating_rsus);
  o.pose_bias_time = c.pose_bias_time;
  o.proc_stddev_position_c = c.proc_stddev_position_c;
  o.proc_stddev_yaw_bias_c = c.proc_stddev_yaw_bias_c;
  return o;
}

namespace {

io::TrajectoryPoint pointOf(const smoother::SmoothedState& st) {
  io::TrajectoryPoint p;
  p.stamp = st.stamp;
  p.pose.position = {st.state[0], st.state[1], 0.0};
  p.pose.orientation = quaternionFromRollPitchYaw(0.0, 0.0, st.state[2] + st.state[3]);  // heading, as the filter gives it
  return p;
}

// The filter's errors at exactly the stamps the smoother produced, so that the two compare like for like.
void matchFilterErrors(SmoothResult& r) {
  std::size_t i = 0;
  for (const ErrorSample& e : r.errors) {
    while (i < r.filter.errors.size() && r.filter.errors[i].stamp < e.stamp) ++i;
    if (i < r.filter.errors.size() && r.filter.errors[i].stamp == e.stamp) r.filter_errors_matched.push_back(r.filter.errors[i]);
  }
}

// Windows of `window` seconds every `window_step`, each from the filter's state at its start.
void smoothFixedLag(const SmoothOptions& options, SmoothResult& result) {
  const ReplayResult& f = result.filter;
  FixedLagReport report;
  report.window = options.window;
  report.step = options.window_step;
  const Duration window = fromSeconds(options.window), step = fromSeconds(std::max(options.window_step, 1e-3));
  smoother::SmootherOptions o = options.smoother;
  o.covariances = false;  // a vehicle running behind the filter wants the states, now
  // A window of a second or two is too short to measure the sources' noise in, or their biases and
  // the odometry's calibration: it takes the inputs as the filter does.
  o.estimate_noise = false;
  o.calibrate_odometry = false;  // the filter's twists, scaled as it scaled them
  o.pose_bias = false;
  const Stamp first = f.fused_states.front().first, last = f.fused_states.back().first;
  std::size_t start_index = 0;
  for (Stamp end = first + window; end <= last; end += step) {
    const Stamp begin = end - window;
    while (start_index + 1 < f.fused_states.size() && f.fused_states[start_index].first < begin) ++start_index;
    smoother::Smoother s(o);
    for (std::size_t i = start_index; i < f.fused_states.size() && f.fused_states[i].first <= end; ++i) s.addGuess(f.fused_states[i].first, f.fused_states[i].second);
    s.addPrior(f.fused_states[start_index].first, f.fused_states[start_index].second, f.fused_state_covariances[start_index]);
    for (const auto& [source, pose] : f.filter_poses)
      if (pose.stamp >= begin && pose.stamp <= end) s.addPose(source, pose);
    for (const auto& [source, twist] : f.filter_twists)
      if (twist.stamp >= begin && twist.stamp <= end) s.addTwist(source, twist);
    const auto t0 = std::chrono::steady_clock::now();
    const smoother::SmootherResult r = s.solve(f.fused_states[start_index].first, end);
    if (!r.summary.usable())
      throw Error("smooth: the window ending at " + formatSeconds(end) + " s: the solver found no solution (" + r.summary.report + ")");
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ++report.windows;
    report.mean_solve_seconds += seconds;
    report.max_solve_seconds = std::max(report.max_solve_seconds, seconds);
    result.summary = r.summary;  // the last window's account
    for (const smoother::SmoothedState& st : r.states)
      if (st.stamp > end - step || result.smoothed.empty()) {
        if (!result.smoothed.empty() && st.stamp <= result.smoothed.back().stamp) continue;
        result.states.push_back(st);
        result.smoothed.push_back(pointOf(st));
      }
  }
  if (report.windows) report.mean_solve_seconds /= report.windows;
  result.fixed_lag = report;
}

}  // namespace

SmoothResult smoothLog(const std::string& log_path, SmoothOptions options) {
  if (options.window > 0.0 && options.calibrate_rsus)
    throw Error("smooth: RSU calibration takes the whole drive at once; it does not run in a fixed-lag window");
  if (options.window < 0.0 || !std::isfinite(options.window)) throw Error("smooth: the window must be a finite number of seconds >= 0");
  if (options.window > 0.0 && !(std::isfinite(options.window_step) && options.window_step > 0.0))
    throw Error("smooth: the window step must be a finite number of seconds > 0");
  options.replay.keep_filter_inputs = true;
  // Calibrating, the log is replayed twice (below): each replay is half of the progress.
  const bool two_replays = options.calibrate_rsus && options.window <= 0.0;
  const std::function<void(double)> progress = options.replay.progress;
  if (two_replays && progress) options.replay.progress = [&](double f) { progress(0.5 * f); };
  SmoothResult result;
  result.filter = replayLog(log_path, options.replay);
  if (result.filter.fused_states.size() < 2) throw Error(log_path + ": the filter gave fewer than two estimates: nothing to smooth");
  std::optional<rsu_client::RsuRegistry> registry = options.replay.registry;
  if (!registry && !options.replay.config.rsu.registry.empty()) registry = rsu_client::RsuRegistry::load(options.replay.config.rsu.registry);
  if (registry) result.registry = *registry;
  std::set<std::string> fix_sources;
  if (registry)
    for (const rsu_client::RsuInfo& rsu : registry->rsus()) fix_sources.insert(rsu_client::fixTopic(rsu.id));
  for (const auto& [topic, input] : options.replay.config.inputs)
    if (input.role == pipeline::InputRole::kRsuFix) fix_sources.insert(topic);
  // Calibrating an RSU, its fixes must not have steered the anchor: NDT starts from the filter's
  // prediction, and a filter that followed a miscalibrated RSU drags NDT with it (on site B's open
  // stretch 0.56 m on average, and the RSU then came out 0.39 m off). The anchor (guesses, NDT's poses,
  // twists) comes from a replay without the fixes; the fixes themselves from the replay with them.
  std::optional<ReplayResult> anchor;
  if (two_replays) {
    ReplayOptions without = options.replay;
    if (progress) without.progress = [&](double f) { progress(0.5 + 0.5 * f); };
    for (const std::string& topic : fix_sources) without.config.inputs[topic].role = pipeline::InputRole::kIgnore;
    anchor = replayLog(log_path, without);
    if (anchor->fused_states.size() < 2) throw Error(log_path + ": the filter without the fixes gave fewer than two estimates: nothing to calibrate against");
  }
  const ReplayResult& f = anchor ? *anchor : result.filter;
  const auto start = std::chrono::steady_clock::now();
  if (options.window > 0.0) {
    smoothFixedLag(options, result);
    result.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    result.errors = evaluate(result.smoothed, f.ground_truth, fromSeconds(options.replay.config.replay.ground_truth_max_gap));
    matchFilterErrors(result);
    return result;
  }
  smoother::Smoother s(options.smoother);
  for (const auto& [stamp, state] : f.fused_states) s.addGuess(stamp, state);
  // A configured initial pose is information the filter started from: the smoother starts from it too,
  // as the filter's first state and covariance.
  if (options.replay.config.pipeline.initial_pose && !f.fused_state_covariances.empty())
    s.addPrior(f.fused_states.front().first, f.fused_states.front().second, f.fused_state_covariances.front());
  for (const auto& [source, pose] : f.filter_poses) s.addPose(source, pose);
  if (anchor)
    for (const auto& [source, pose] : result.filter.filter_poses)
      if (fix_sources.count(source)) s.addPose(source, pose);
  // With the odometry's calibration estimated, the twists as the log has them: the filter's were
  // scaled by what NDT had taught so far, a scale that changes along the drive.
  for (const auto& [source, twist] : options.smoother.calibrate_odometry ? f.received_twists : f.filter_twists) s.addTwist(source, twist);
  // Every pose source but the RSUs' fixes is map matching of some kind, whose error is a slow bias.
  for (const auto& [source, pose] : f.filter_poses)
    if (!fix_sources.count(source)) s.setPoseBias(source);
  if (options.calibrate_rsus) {
    if (!registry) throw Error("smooth: --calibrate-rsus needs an RSU registry (rsu.registry or --rsu-registry)");
    for (const rsu_client::RsuInfo& rsu : registry->rsus()) s.calibrateRsu(rsu_client::fixTopic(rsu.id), rsu.position);
  }
  const smoother::SmootherResult r = s.solve(f.fused_states.front().first, f.fused_states.back().first);
  if (!r.summary.usable()) throw Error("smooth: " + log_path + ": the solver found no solution (" + r.summary.report + ")");
  result.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.summary = r.summary;
  result.odometry = r.odometry;
  if (registry)
    for (std::size_t i = 0; i < r.calibrations.size() && i < registry->rsus().size(); ++i) result.calibrations[registry->rsus()[i].id] = r.calibrations[i];
  result.states = r.states;
  for (const smoother::SmoothedState& st : r.states) result.smoothed.push_back(pointOf(st));
  result.errors = evaluate(result.smoothed, f.ground_truth, fromSeconds(options.replay.config.replay.ground_truth_max_gap));
  matchFilterErrors(result);
  return result;
}

rsu_client::RsuRegistry SmoothResult::calibratedRegistry() const {
  std::vector<rsu_client::RsuInfo> rsus = registry.rsus();
  for (rsu_client::RsuInfo& rsu : rsus) {
    const auto found = calibrations.find(rsu.id);
    if (found == calibrations.end() || !found->second.observable) continue;
    // The fixes were already corrected by the old calibration: the new one is what remained.
    const smoother::RsuCalibration& c = found->second;
    rsu_client::RsuCalibrationEntry e = rsu.calibration.value_or(rsu_client::RsuCalibrationEntry{});
    const Eigen::Vector2d old_d(e.dx, e.dy);
    // Correcting by e, then by c, is correcting by d = c + R(-c.dyaw) e, dyaw = c.dyaw + e.dyaw.
    const Eigen::Vector2d d = Eigen::Vector2d(c.dx, c.dy) + Eigen::Rotation2Dd(-c.dyaw) * old_d;
    e.dx = d.x();
    e.dy = d.y();
    e.dyaw += c.dyaw;
    e.clock_offset += c.clock_offset;
    rsu.calibration = e;
  }
  return rsu_client::RsuRegistry(rsus, registry.placement());
}

std::string SmoothResult::summaryJson(const std::string& log) const {
  nlohmann::ordered_json j;
  j["log"] = log;
  if (!filter.recovered.empty()) j["recovered"] = recoveredJson(filter.recovered);
  j["smoothed"] = {{"file", "smoothed.tum"}, {"states", smoothed.size()}};
  j["position_error"] = errorJson(errors, "error.csv");
  j["filter_position_error"] = errorJson(filter_errors_matched, "error.csv");
  if (fixed_lag)
    j["fixed_lag"] = {{"window_s", fixed_lag->window}, {"step_s", fixed_lag->step}, {"windows", fixed_lag->windows}};
  if (!odometry.empty()) {
    auto& odo = j["odometry_calibration"] = nlohmann::ordered_json::object();
    for (const smoother::OdometryCalibration& o : odometry)
      odo[o.source] = {{"speed_scale", o.speed_scale}, {"sd_speed_scale", o.sd_speed_scale}, {"yaw_rate_bias_rad_s", o.yaw_rate_bias},
                       {"sd_yaw_rate_bias_rad_s", o.sd_yaw_rate_bias}};
  }
  if (!summary.noise.empty()) {
    auto& noise = j["noise_scale"] = nlohmann::ordered_json::object();  // measured sd / the covariances' sd
    for (const smoother::NoiseScale& n : summary.noise) noise[n.source] = n.scale;
  }
  if (summary.pose_bias_sd) j["pose_bias_sd_m"] = *summary.pose_bias_sd;
  auto& down = j["down_weighted"] = nlohmann::ordered_json::array();
  for (const smoother::DownWeighted& d : summary.down_weighted)
    down.push_back({{"source", d.source}, {"stamp", formatSeconds(d.stamp)}, {"mahalanobis", d.mahalanobis}, {"weight", d.weight}});
  if (!calibrations.empty()) {
    auto& cal = j["rsu_calibration"] = nlohmann::ordered_json::object();
    for (const auto& [id, c] : calibrations) {
      nlohmann::ordered_json o = {{"dx_m", c.dx},
                                  {"dy_m", c.dy},
                                  {"dyaw_deg", c.dyaw * 180.0 / M_PI},
                                  {"clock_offset_ms", c.clock_offset * 1e3},
                                  {"sd_dx_m", c.sd_dx},
                                  {"sd_dy_m", c.sd_dy},
                                  {"sd_dyaw_deg", c.sd_dyaw * 180.0 / M_PI},
                                  {"sd_clock_offset_ms", c.sd_clock_offset * 1e3},
                                  {"observable", c.observable},
                                  {"clock_observable", c.clock_observable},
                                  {"fixes", c.fixes}};
      if (!c.note.empty()) o["note"] = c.note;
      cal[id] = o;
    }
  }
  // The solver's own account; its time is a run time, so it stays out of this file (see timing).
  j["solver"] = {{"termination", summary.termination},
                 {"iterations", summary.iterations},
                 {"initial_cost", summary.initial_cost},
                 {"final_cost", summary.final_cost},
                 {"states", summary.states},
                 {"pose_residuals", summary.pose_residuals},
                 {"twist_residuals", summary.twist_residuals}};
  return j.dump(2) + "\n";
}

}  // namespace coloc::replay
