#include "coloc/twin/experiment.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <exception>
#include <filesystem>
#include <fstream>
#include <future>
#include <map>
#include <mutex>
#include <optional>
#include <thread>

#include "coloc/core/error.hpp"
#include "coloc/rsu_client/rsu_registry.hpp"
#include "coloc/sim/scene.hpp"
#include "coloc/sim/vehicle_motion.hpp"
#include "coloc/pipeline/cam_size_correction.hpp"
#include "coloc/pipeline/config.hpp"
#include "coloc/replay/accurate_places.hpp"
#include "coloc/replay/log_replay.hpp"
#include "coloc/replay/log_smoother.hpp"
#include "coloc/rsu_client/dds_transport.hpp"
#include "coloc/rsu_client/fix_error_model.hpp"
#include "coloc/twin/twin_recording.hpp"

namespace coloc::twin {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Lower-case letters and digits, runs of anything else as `separator` (none by default):
// "VLP-32C" -> "vlp32c", a suffix for the RSU id, hence the topic; with '_', a file name of a label.
std::string slug(const std::string& text, const char* separator = "") {
  std::string s;
  bool gap = false;
  for (char c : text) {
    if (!std::isalnum(static_cast<unsigned char>(c))) {
      gap = !s.empty();
      continue;
    }
    if (gap) s += separator;
    gap = false;
    s += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return s;
}

std::string rsuIdFor(const sim::ScenarioRsu& rsu, const std::string& lidar) { return rsu.id + "_" + slug(lidar); }

// The site's RSU a mounted sensor stands at: its id without the LiDAR's suffix.
std::string siteRsuId(const sim::ScenarioRsu& mounted) {
  const std::string suffix = "_" + slug(mounted.lidar_model);
  const std::string& id = mounted.id;
  return id.size() > suffix.size() && id.compare(id.size() - suffix.size(), suffix.size(), suffix) == 0 ? id.substr(0, id.size() - suffix.size()) : id;
}

// How the report names a mounted sensor: "SITE LIDAR", and the RSU's id when the site has several.
std::string reportKey(const sim::Scenario& scenario, const sim::ScenarioRsu& mounted) {
  const auto same_model = std::count_if(scenario.rsus.begin(), scenario.rsus.end(),
                                        [&](const sim::ScenarioRsu& r) { return r.lidar_model == mounted.lidar_model; });
  std::string key = scenario.name + " " + mounted.lidar_model;
  if (same_model > 1) key += " (" + siteRsuId(mounted) + ")";
  return key;
}

// The site's scenario with every compared LiDAR model mounted at each of its RSUs (one virtual sensor
// each: they do not disturb one another, so one drive serves all).
sim::Scenario siteScenario(const std::string& site, const ExperimentConfig& config) {
  sim::Scenario s = sim::parseScenario(scenarioText(site), site);
  if (config.ideal_twin) sim::setErrorSources(s, sim::ErrorSources::ideal());
  if (!config.errors.empty()) {
    const YamlReader r("experiment errors");
    sim::setErrorSources(s, sim::readErrorSources(r, r.parse(config.errors), s.errors));
  }
  const std::vector<std::string>& lidars = config.lidars;
  std::vector<sim::ScenarioRsu> rsus;
  for (const sim::ScenarioRsu& r : s.rsus)
    for (const std::string& lidar : lidars) {
      sim::ScenarioRsu copy = r;
      copy.id = rsuIdFor(r, lidar);
      copy.lidar_model = lidar;
      rsus.push_back(copy);
    }
  s.rsus = rsus;
  return s;
}

SiteInfo siteInfo(const sim::Scenario& s) {
  SiteInfo info;
  info.name = s.name;
  info.cruise_speed = s.speed.cruise;
  const sim::Drive drive(sim::Route(s.route_start, s.route_heading, s.route), s.speed);
  // Sample the path finely and find where each RSU is nearest.
  std::vector<std::pair<double, Eigen::Vector2d>> path;
  double along = 0.0;
  Eigen::Vector2d last = drive.at(0.0).position;
  for (double t = 0.0; t <= drive.duration(); t += 0.01) {
    const Eigen::Vector2d p = drive.at(t).position;
    along += (p - last).norm();
    last = p;
    path.push_back({along, p});
  }
  info.drive_length = along;
  std::vector<std::string> seen;
  for (const sim::ScenarioRsu& r : s.rsus) {
    const std::string key = std::to_string(r.position.x()) + "," + std::to_string(r.position.y());
    if (std::find(seen.begin(), seen.end(), key) != seen.end()) continue;
    seen.push_back(key);
    double best = 1e300, best_along = 0.0;
    for (const auto& [a, p] : path)
      if ((p - r.position).norm() < best) best = (p - r.position).norm(), best_along = a;
    info.rsu_along.push_back(best_along);
  }
  return info;
}

struct Job {
  ExperimentRun run;
  std::string log, map;
  std::shared_ptr<replay::ReplayCache> cache;  ///< shared by the drive's replays
  pipeline::Config config;
  std::optional<rsu_client::RsuRegistry> registry;  ///< the fused RSUs, their fixes through the registry's checks
  std::vector<std::string> fix_topics;  ///< the fused RSUs' topics (every RSU of the LiDAR model), none for NDT only
  std::vector<std::string> fix_sources;  ///< the filter's sources of the same RSUs
  std::vector<Eigen::Vector2d> rsu_positions;
  bool smooth = false;     ///< also smooth the log: `smoothed`
  bool calibrate = false;  ///< smooth with the RSUs' calibrations: `calibrations`, `calibrated`
  Stamp until = 0;         ///< the replay ends here (0: at the log's end): replay::ReplayOptions::until
  bool keep_ndt_errors = false;  ///< keep NDT's own error per pose: `ndt_errors`
  std::vector<replay::ErrorSample> ndt_errors;
  /// Where NDT was accurate on the site's noise calibration drive: the filter beside NDT there too.
  /// With the drives recorded, the replay reads them from that drive's input_error.csv instead
  /// (config.replay.input_reference), as `coloc fuse` of the written configuration does.
  std::shared_ptr<const replay::AccuratePlaces> places;
  std::string input_error_csv;  ///< write the replay's input_error.csv here (the recorded noise calibration drive's)
  std::optional<ExperimentRun> smoothed;
  std::map<std::string, smoother::RsuCalibration> calibrations;  ///< per RSU id, with `calibrate`
  std::optional<rsu_client::RsuRegistry> calibrated;  ///< the registry with the calibrations found
};

// A replay's configuration beside the recorded drive, as `coloc fuse` takes it: the same log, map,
// configuration and registry give the same result as the experiment's replay.
void writeReplayConfig(const Job& job, const std::string& dir) {
  const std::string name = slug(job.run.label(), "_");
  fs::create_directories(dir);
  pipeline::Config config = job.config;
  if (job.registry) {
    std::ofstream(dir + "/" + name + "_rsu.yaml") << job.registry->toYaml();
    config.rsu.registry = name + "_rsu.yaml";
  }
  // As coloc fuse reads it: relative to the configuration's folder.
  if (!config.ndt.quality_map.empty())
    config.ndt.quality_map = fs::relative(fs::absolute(config.ndt.quality_map), fs::absolute(dir)).string();
  if (!config.replay.input_reference.empty())
    config.replay.input_reference = fs::relative(fs::absolute(config.replay.input_reference), fs::absolute(dir)).string();
  // Its figures all lie within coverage: the experiment ended the replay there (the same figures).
  const std::string ended = job.until ? "# (the experiment ended it at stamp " + formatSeconds(job.until) + ", past the RSUs' coverage)\n" : std::string();
  std::ofstream(dir + "/" + name + ".yaml") << pipeline::configYaml(
      config, "# " + job.run.label() + ", as the experiment replayed it:\n# coloc fuse " + job.log + " --map " + job.map + " --config " + dir + "/" +
                  name + ".yaml\n" + ended + "\n");
}

// A run's error along the drive from a replay's ground truth and error samples.
void fillRun(ExperimentRun& run, const std::vector<io::TrajectoryPoint>& ground_truth, const std::vector<replay::ErrorSample>& errors,
             const std::vector<Eigen::Vector2d>& rsu_positions) {
  // Distance along the drive at each ground-truth sample.
  std::vector<double> along(ground_truth.size(), 0.0);
  for (std::size_t i = 1; i < ground_truth.size(); ++i)
    along[i] = along[i - 1] + (ground_truth[i].pose.position.head<2>() - ground_truth[i - 1].pose.position.head<2>()).norm();
  for (const replay::ErrorSample& e : errors) {
    const auto it = std::lower_bound(ground_truth.begin(), ground_truth.end(), e.stamp,
                                     [](const io::TrajectoryPoint& p, Stamp s) { return p.stamp < s; });
    const std::size_t i = std::min<std::size_t>(it - ground_truth.begin(), along.size() - 1);
    double to_rsu = 1e300;
    for (const Eigen::Vector2d& p : rsu_positions) to_rsu = std::min(to_rsu, (e.truth - p).norm());
    run.along.push_back(along[i]);
    run.to_rsu.push_back(to_rsu);
    run.error.push_back(e.error);
  }
}

// The calibration study's second drive, past the same miscalibrated RSUs: its replays are the runs
// kNextMiscalibrated, kNextCalibrated and kNextPerfect.
constexpr const char* kNextDrive = "next drive";

// Whether every figure the report draws from a run lies within the RSUs' coverage: the network grid
// (Tables II and III), the calibration study's next drives, and Table I's second covariance unless the
// sweeps table lists it over all samples too. Such a run need not be replayed past coverage.
bool reportedWithinCoverageOnly(const ExperimentRun& run, const ExperimentConfig& config) {
  if (run.lidar.empty()) return false;  // NDT only: Table I's all-samples columns and figures 4 and 5
  if (run.delay > 0.0 || run.loss > 0.0) return true;
  if (run.variant == kNextMiscalibrated || run.variant == kNextCalibrated || run.variant == kNextPerfect) return true;
  return !config.sweeps && run.variant.rfind("covariance ", 0) == 0;
}

// Where a replay of the drive can end with every figure within coverage as a whole replay has it: a
// second after the vehicle was last within `range` of an RSU of the site, or after the last fix of the
// fused RSUs arrived through a link of `delay` (the fix counters count it), whichever is later. The
// second covers a tick between two ground-truth samples and NDT's answer to the last scan.
Stamp coverageEnd(const TwinRecordingSummary& drive, const std::vector<Eigen::Vector2d>& rsus, double range, const std::vector<std::string>& fix_topics,
                  double delay) {
  Stamp end = 0;
  for (const auto& [stamp, position] : drive.truth)
    for (const Eigen::Vector2d& rsu : rsus)
      if ((position - rsu).norm() <= range) end = std::max(end, stamp);
  if (drive.log)
    for (const io::BagMessage& m : drive.log->messages())
      if (std::find(fix_topics.begin(), fix_topics.end(), m.topic) != fix_topics.end()) end = std::max(end, m.log_time + fromSeconds(delay));
  return end + kNanosPerSecond;
}

// Replays one configuration (and smooths it, when asked) and measures its error along the drive.
void runJob(Job& job) {
  replay::ReplayOptions options;
  options.config = job.config;
  options.registry = job.registry;
  options.map = job.map;
  options.cache = job.cache;
  options.until = job.until;
  replay::ReplayResult r;
  if (job.smooth || job.calibrate) {
    replay::SmoothOptions so;
    so.replay = options;
    so.smoother = replay::smootherOptionsFor(job.config, job.calibrate);
    so.smoother.threads = 1;  // as NDT's: the jobs run side by side instead (the same results, checked)
    so.calibrate_rsus = job.calibrate;
    replay::SmoothResult s = replay::smoothLog(job.log, so);
    if (job.calibrate && job.registry) {
      job.calibrations = s.calibrations;
      job.calibrated = s.calibratedRegistry();
    }
    if (job.smooth) {
      ExperimentRun run = job.run;  // before its errors are filled in
      run.variant = kSmootherVariant;
      fillRun(run, s.filter.ground_truth, s.errors, job.rsu_positions);
      run.replay_seconds = s.wall_seconds;
      job.smoothed = std::move(run);
    }
    r = std::move(s.filter);
  } else {
    r = replay::replayLog(job.log, options);
  }
  fillRun(job.run, r.ground_truth, r.errors, job.rsu_positions);
  if (const auto c = r.input_comparison.find(pipeline::kNdtSource); c != r.input_comparison.end()) {
    job.run.ndt = c->second;
    if (job.places && !c->second.places_given)
      job.run.ndt = replay::compareWithInput(r.input_errors[pipeline::kNdtSource], r.fused_at_inputs[pipeline::kNdtSource],
                                             r.settled_at_inputs[pipeline::kNdtSource], c->second.stretch_length, c->second.accurate_below,
                                             job.places.get());
  }
  if (!job.input_error_csv.empty()) r.writeInputErrorCsv(job.input_error_csv);
  if (job.keep_ndt_errors)
    if (auto e = r.input_errors.find(pipeline::kNdtSource); e != r.input_errors.end()) job.ndt_errors = std::move(e->second);
  const auto fused = [&](const std::string& topic) { return std::find(job.fix_topics.begin(), job.fix_topics.end(), topic) != job.fix_topics.end(); };
  for (const fusion::SourceReport& s : r.sources)
    if (s.name == pipeline::kNdtSource) {
      job.run.ndt_nis_sum = s.counters.nis_sum, job.run.ndt_nis_dof = s.counters.nis_dof;
      for (std::size_t k = 0; k < job.run.ndt_nis_component_sum.size(); ++k)
        job.run.ndt_nis_component_sum[k] = s.counters.nis_component_sum[k], job.run.ndt_nis_component_samples[k] = s.counters.nis_component_samples[k],
        job.run.ndt_nis_prediction_share_sum[k] = s.counters.nis_prediction_share_sum[k];
    }
  for (const fusion::SourceReport& s : r.sources)
    if (std::find(job.fix_sources.begin(), job.fix_sources.end(), s.name) != job.fix_sources.end()) {
      job.run.fixes_applied += s.counters.applied;
      job.run.fixes_gated += s.counters.gated;
    }
  for (const replay::TopicUse& t : r.topics)
    if (fused(t.topic)) job.run.fixes_lost += t.link_dropped;
  job.run.replay_seconds = r.wall_seconds;
}

// The drives' jobs side by side on a few threads. Each drive's jobs run longest first (a smoothed
// replay, then a whole one, then one that ends with the coverage), and the drives in the order they
// are queued: a thread that ends a drive's last job goes on to the next drive's instead of waiting for
// its partner, which left a thread idle at every drive's end (on the full run 24 s of 410 s of
// replays, most of it drives of two or three replays alike). Each job is computed alone, so the order
// changes no result.
class JobPool {
 public:
  /// One drive's jobs; `left` counts those not yet run.
  struct Batch {
    std::vector<Job>* jobs = nullptr;
    std::size_t left = 0;
    std::exception_ptr failure;  ///< the first job's error: the drive's other jobs are skipped
  };

  explicit JobPool(int threads) {
    for (int t = 0; t < std::max(1, threads); ++t) workers_.emplace_back([this] { work(); });
  }
  ~JobPool() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
      queue_.clear();  // an error stopped the experiment: what is queued is not wanted
    }
    wake_.notify_all();
    for (std::thread& t : workers_) t.join();
  }
  JobPool(const JobPool&) = delete;
  JobPool& operator=(const JobPool&) = delete;

  /// Queues `batch`'s jobs, which must stay where they are until wait(batch) returns.
  void submit(Batch& batch) {
    std::vector<Job>& jobs = *batch.jobs;
    std::vector<std::size_t> order(jobs.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    const auto weight = [](const Job& j) { return (j.smooth || j.calibrate ? 2 : 0) + (j.until == 0 ? 1 : 0); };
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return weight(jobs[a]) > weight(jobs[b]); });
    {
      std::lock_guard<std::mutex> lock(mutex_);
      batch.left = jobs.size();
      for (std::size_t i : order) queue_.emplace_back(&batch, i);
    }
    wake_.notify_all();
  }
  /// Until every job of `batch` has run; rethrows the first error of one.
  void wait(Batch& batch) {
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [&] { return batch.left == 0; });
    if (batch.failure) std::rethrow_exception(batch.failure);
  }

 private:
  void work() {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      wake_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;
      const auto [batch, i] = queue_.front();
      queue_.pop_front();
      const bool skip = batch->failure != nullptr;
      lock.unlock();
      std::exception_ptr failure;
      if (!skip) {
        try {
          runJob((*batch->jobs)[i]);
        } catch (...) {
          failure = std::current_exception();
        }
      }
      lock.lock();
      if (failure && !batch->failure) batch->failure = failure;
      if (--batch->left == 0) done_.notify_all();
    }
  }

  std::mutex mutex_;
  std::condition_variable wake_, done_;
  std::deque<std::pair<Batch*, std::size_t>> queue_;
  bool stopping_ = false;
  std::vector<std::thread> workers_;
};

// The variance per axis of an RSU's fix errors against ground truth: the "estimated from the data"
// covariance, as a calibration drive past the RSU would give it. Robust (from the median absolute
// error, as for a normal distribution), because a few gross misfits - the fit on the wrong corner -
// are the gate's business, not the covariance's.
// None from fewer than kFewestFixes fixes (an RSU the drive hardly passes).
constexpr std::size_t kFewestFixes = 5;
// The fixes' error by range is measured in bands of this many metres: one pass of the noise
// calibration drive puts 10-20 fixes in each at 10 m/s and 10 Hz.
constexpr double kFixErrorBand = 10.0;
std::optional<double> robustFixVariance(const std::vector<Eigen::Vector2d>& errors) {
  if (errors.size() < kFewestFixes) return std::nullopt;
  std::vector<double> abs_errors;
  for (const Eigen::Vector2d& e : errors) {
    abs_errors.push_back(std::abs(e.x()));
    abs_errors.push_back(std::abs(e.y()));
  }
  std::nth_element(abs_errors.begin(), abs_errors.begin() + abs_errors.size() / 2, abs_errors.end());
  const double sigma = 1.4826 * abs_errors[abs_errors.size() / 2];
  return sigma * sigma;
}

// The fixes' variance per axis as the filter gets them: the mean square, tails included. A calibrated
// RSU's fixes are a centimetre or better with tails of several (a real body's curves, a few points at
// the edge of a beam gap); a median-based figure describes the core and the filter then follows the tails.
std::optional<double> meanSquareFixVariance(const std::vector<Eigen::Vector2d>& errors) {
  if (errors.size() < kFewestFixes) return std::nullopt;
  double sum = 0.0;
  for (const Eigen::Vector2d& e : errors) sum += e.squaredNorm();
  return sum / (2.0 * static_cast<double>(errors.size()));
}

// The odometry's error as the filter gets it, per component: the speed after the scale the pipeline
// learns from NDT (here the least-squares scale against the truth), the yaw rate as it is (the
// filter has no gyro bias state, so a bias is part of its error). Samples at standstill say nothing of
// the scale and are left out.
Eigen::Vector2d odometryVariance(const std::vector<Eigen::Vector4d>& samples, const std::string& site) {
  double mt = 0.0, tt = 0.0;
  for (const Eigen::Vector4d& s : samples)
    if (s[1] > 0.5) mt += s[0] * s[1], tt += s[1] * s[1];
  if (tt <= 0.0) throw Error(site + ": the noise calibration drive never moved: no odometry covariance to estimate");
  const double scale = mt / tt;
  double speed = 0.0, yaw_rate = 0.0;
  int n = 0;
  for (const Eigen::Vector4d& s : samples) {
    if (s[1] <= 0.5) continue;
    speed += std::pow(s[0] / scale - s[1], 2);
    yaw_rate += std::pow(s[2] - s[3], 2);
    ++n;
  }
  return {speed / n, yaw_rate / n};
}

// NDT's variance per axis as the filter gets it, from its own poses on a drive with ground truth: the
// mean square (tails included, as for the fixes), x and y pooled; yaw about its mean, which is the
// LiDAR's mounting yaw that the pipeline learns and takes out.
Eigen::Vector2d ndtVariance(const replay::InputComparison& ndt, const std::string& site) {
  if (ndt.samples < 20) throw Error(site + ": too few NDT poses on the noise calibration drive to estimate their covariance");
  return {ndt.mean_square_xy, ndt.yaw_variance};
}

}  // namespace

std::string ExperimentRun::label() const {
  if (lidar.empty()) return variant.empty() ? "NDT only" : "NDT only, " + variant;
  std::string s = "NDT + " + lidar;
  if (delay > 0.0 || loss > 0.0) {
    char buf[64];
    std::snprintf(buf, sizeof buf, ", %.0f ms, %.0f %% loss", delay * 1e3, loss * 1e2);
    s += buf;
  }
  if (!variant.empty()) s += ", " + variant;
  return s;
}

ExperimentResults runExperiment(const ExperimentConfig& config, const std::string& out_dir, const ExperimentProgress& progress) {
  const auto start = Clock::now();
  ExperimentResults results;
  results.config = config;
  results.work_dir = out_dir + "/recordings";
  pipeline::Config base;
  base.fusion.pose_gate_recovery = config.gate_recovery;
  // NDT's covariance is the experiment's own choice (ndt_covariance): Autoware's fixed matrix, as
  // the paper, wherever that choice does not replace it (the noise calibration drive, `published`).
  base.ndt.source.ndt.covariance = ndt::CovarianceMode::kFixed;
  // Nor is NDT held against the fixes: the experiment's NDT covariance is NDT's error measured against
  // the truth on the site's calibration drive, its bias included, and widening it again where the fixes
  // disagree counts that bias twice (site C's VLP-16, whose commissioning leaves it 4-6 cm off where NDT
  // is right: 1.5 -> 1.9 cm, above NDT's 1.8).
  base.pipeline.fix_agreement_window = 0.0;
  if (!config.fuse_config.empty()) base = pipeline::loadConfig(config.fuse_config);  // a full configuration: its own gate recovery
  base.ndt.source.ndt.threads = 1;  // the replays run side by side instead: small scans scale poorly over threads

  // The work, counted in drives; each drive is followed by its replays.
  struct Drive {
    std::size_t site;
    int trial;
    std::string variant;  ///< sweep and calibration drives
    double rsu_height = 0.0, speed = 0.0;
  };
  // The calibration drives: their own seeds, far from the trials'.
  constexpr int kNoiseTrial = 499, kCalibrationTrial = 500, kNextTrial = 501;
  // First, per site, a drive that is never evaluated: on it the fixes' variance and the odometry's
  // covariance are measured against ground truth, as a surveyed vehicle would measure them.
  // Those of the first two sites come first; each later site's follows the first trial of the site two
  // before it: drives are replayed in this order, and a trial's replays then need not wait for the
  // calibration drive of a site they do not use (the order within the trials, and within the
  // calibration drives, is the tables' row order and stays as it was).
  std::vector<Drive> drives;
  for (std::size_t s = 0; s < std::min<std::size_t>(2, config.sites.size()); ++s) drives.push_back({s, kNoiseTrial, kNoiseCalibrationDrive, 0.0, 0.0});
  for (std::size_t s = 0; s < config.sites.size(); ++s)
    for (int t = 0; t < config.trials; ++t) {
      drives.push_back({s, t, "", 0.0, 0.0});
      if (t == 0 && s + 2 < config.sites.size()) drives.push_back({s + 2, kNoiseTrial, kNoiseCalibrationDrive, 0.0, 0.0});
    }
  if (config.sweeps)
    for (std::size_t s = 0; s < config.sites.size(); ++s)
      for (int t = 0; t < std::min(config.sweep_trials, config.trials); ++t) {
        for (double h : config.rsu_heights) drives.push_back({s, t, "RSU height", h, 0.0});
        for (double v : config.speeds) drives.push_back({s, t, "speed", 0.0, v});
      }
  if (config.calibration)
    for (std::size_t s = 0; s < config.sites.size(); ++s) {
      drives.push_back({s, kCalibrationTrial, kCalibrationDrive, 0.0, 0.0});
      drives.push_back({s, kNextTrial, kNextDrive, 0.0, 0.0});
    }
  // Per site and LiDAR, the registry the calibration drive found; per site and RSU, the entry the noise
  // calibration drive found (commissioning), which the evaluated drives use.
  std::map<std::pair<std::size_t, std::string>, rsu_client::RsuRegistry> calibrated_registries;
  std::map<std::pair<std::size_t, std::string>, rsu_client::RsuInfo> commissioned;

  std::vector<sim::Scenario> scenarios;
  std::vector<std::string> maps(config.sites.size());
  // A site's drives follow one route on one map: they share its NDT targets (about 15 along a drive).
  std::vector<std::shared_ptr<ndt::TargetCache>> site_targets;
  for (std::size_t s = 0; s < config.sites.size(); ++s) site_targets.push_back(std::make_shared<ndt::TargetCache>(32));
  // And the roof LiDAR's ray hits, cast once per site and speed (169 MB at the cruise speed in a quick
  // run) instead of once per drive; the RSUs' frames likewise, once per site, speed and RSU height.
  // A cache is let go after the last drive that uses it has been simulated.
  auto roofKey = [&](const Drive& d) { return std::to_string(d.site) + (d.variant == "speed" ? " speed " + std::to_string(d.speed) : ""); };
  auto framesKey = [&](const Drive& d) { return roofKey(d) + (d.variant == "RSU height" ? " height " + std::to_string(d.rsu_height) : ""); };
  std::mutex sweeps_mutex;
  std::map<std::string, std::shared_ptr<sim::SweepCache>> sweep_caches;
  std::map<std::string, std::size_t> last_use;  // cache key -> the last drive that uses it
  for (std::size_t d = 0; d < drives.size(); ++d) last_use["roof " + roofKey(drives[d])] = last_use["frames " + framesKey(drives[d])] = d;
  auto sweepCache = [&](const std::string& key) {
    std::lock_guard<std::mutex> lock(sweeps_mutex);
    auto& cache = sweep_caches[key];
    if (!cache) cache = std::make_shared<sim::SweepCache>();
    return cache;
  };
  for (const std::string& site : config.sites) {
    scenarios.push_back(siteScenario(site, config));
    if (scenarios.back().rsus.empty())
      throw Error(site + ": the site has no RSU (rsus:), and the experiment compares NDT alone with NDT + an RSU's fixes "
                  "(coloc simulate and coloc fuse drive and replay a site without one)");
    results.sites.push_back(siteInfo(scenarios.back()));
  }
  std::vector<std::map<std::string, double>> measured_variance(config.sites.size());  // per site: RSU id -> variance
  std::vector<std::map<std::string, std::vector<rsu_client::RsuInfo::ErrorAtRange>>> measured_error_by_range(config.sites.size());
  std::vector<Eigen::Vector2d> twist_variance(config.sites.size(), Eigen::Vector2d::Zero());  // per site: vx, wz
  std::vector<std::optional<Eigen::Vector2d>> ndt_variance(config.sites.size());  // per site: x/y, yaw
  std::vector<std::string> ndt_quality(config.sites.size());  // per site: NDT's error by place (its file)
  // Per site: where NDT was accurate on the noise calibration drive (by InputComparison's criterion).
  std::vector<std::shared_ptr<const replay::AccuratePlaces>> accurate_places(config.sites.size());
  std::vector<std::string> reference_errors(config.sites.size());  // per site, recorded: that drive's input_error.csv
  std::vector<double> ndt_quality_default(config.sites.size(), 0.0);  // and its mean square over the drive

  // What the site's noise calibration drive measured of NDT, into a replay's configuration.
  auto takeNdtFigures = [&](pipeline::Config& replay, std::size_t site) {
    const auto& v = ndt_variance[site];
    if (!v) return;
    Vector6d& cov = replay.ndt.source.ndt.fixed_covariance;
    cov[0] = cov[1] = (*v)[0];
    if (config.ndt_covariance == NdtCovarianceSource::kEstimated) cov[5] = (*v)[1];
    if (config.ndt_covariance != NdtCovarianceSource::kMultiNdtScore) return;
    replay.ndt.source.ndt.covariance = ndt::CovarianceMode::kMultiNdtScore;
    if (ndt_quality[site].empty()) {
      replay.ndt.source.ndt.covariance_floor = cov;  // NDT's error on the calibration drive the floor
      return;
    }
    // NDT's error on the calibration drive where the pose is the floor; the aligner's own at its default.
    replay.ndt.quality_map = ndt_quality[site];
    if (config.map_match_bias_length > 0.0) {
      // Its spread before the first pose is looked up: the drive's mean square.
      replay.fusion.map_match_bias_sd = std::sqrt(std::max(ndt_quality_default[site], 1e-6));
      replay.fusion.map_match_bias_length = config.map_match_bias_length;
    }
  };

  // Drive d + 1 is simulated while drive d's replays run: the simulation is mostly one thread.
  struct Recorded {
    sim::Scenario scenario;
    std::string name, variant;
    TwinRecordingOptions options;
    TwinRecordingSummary summary;
    double seconds = 0.0;
  };
  auto record = [&](std::size_t d) {
    const Drive& drive = drives[d];
    Recorded r;
    r.scenario = scenarios[drive.site];
    r.scenario.seed += 1000 * static_cast<std::uint64_t>(drive.trial);  // trial 0 is the scenario as written
    r.name = r.scenario.name + "/trial_" + std::to_string(drive.trial);
    char buf[64];
    if (drive.variant == "RSU height") {
      for (sim::ScenarioRsu& rsu : r.scenario.rsus) rsu.height = drive.rsu_height;
      std::snprintf(buf, sizeof buf, "RSU height %.1f m", drive.rsu_height);
      r.variant = buf;
      std::snprintf(buf, sizeof buf, "_height_%.1f", drive.rsu_height);
      r.name += buf;
    } else if (drive.variant == "speed") {
      r.scenario.speed.cruise = drive.speed;
      std::snprintf(buf, sizeof buf, "speed %.0f m/s", drive.speed);
      r.variant = buf;
      std::snprintf(buf, sizeof buf, "_speed_%.0f", drive.speed);
      r.name += buf;
    } else if (!drive.variant.empty()) {  // the calibration drives: every RSU miscalibrated on two of them
      r.variant = drive.variant;
      r.name = r.scenario.name + (drive.variant == kNoiseCalibrationDrive ? "/noise_calibration_drive"
                                  : drive.variant == kCalibrationDrive    ? "/calibration_drive"
                                                                          : "/next_drive");
      if (drive.variant == kCalibrationDrive || drive.variant == kNextDrive)
        for (sim::ScenarioRsu& rsu : r.scenario.rsus) {
          rsu.survey_error = Eigen::Vector3d(config.calibration_error[0], config.calibration_error[1], config.calibration_error[2] * M_PI / 180.0);
          rsu.clock_offset = 1e-3 * config.calibration_clock_offset_ms;
        }
    }
    const auto t0 = Clock::now();
    r.options.out_dir = results.work_dir + "/" + r.name;
    fs::remove_all(r.options.out_dir);
    r.options.map_dir = maps[drive.site];
    r.options.perception_ablation = drive.trial == 0 && drive.variant.empty();
    r.options.roof_sweeps = sweepCache("roof " + roofKey(drive));
    r.options.rsu_frames = sweepCache("frames " + framesKey(drive));
    r.options.ideal_comparison = drive.variant == kNoiseCalibrationDrive && !config.ideal_twin;
    r.options.write_log = config.recordings;
    r.options.keep_log = true;
    // The next drive past the miscalibrated RSUs also carries what they would send perfectly surveyed
    // and synchronised: the same drive for the perfect RSU's replays (the survey and the clock are not
    // where the LiDAR is, only where its fixes are said to be, and when).
    r.options.perfect_rsus = drive.variant == kNextDrive;
    r.options.oracle_fix_limit = config.oracle_fix_limit;
    if (!config.rsu_background_learned) r.options.rsu_commissioning_frames = 0;  // the surveyed empty street
    // The noise calibration drive is the commissioning pass: its vehicle is the operator's probe, whose
    // size is entered as measured, not as a CAM rounds it; the variance of its fixes as sent is the
    // operating vehicles'.
    r.options.probe_size_for_commissioning = drive.variant == kNoiseCalibrationDrive;
    r.summary = recordTwin(r.scenario, r.options);
    r.seconds = since(t0);
    return r;
  };
  // Up to two drives are simulated ahead of the one being replayed. With three (the choice while a
  // replay took longer), the quick run took as long (31.3-32.5 s against 30.9-31.3 s) and the full run
  // with the sweeps too (134.5 s against 135.3 s), for 0.55 GB more at the peak (4.27 GB against 3.73). The
  // first drive of a site surveys its map, which the site's later drives share: none of them starts
  // before that map is noted.
  constexpr std::size_t kSimulatedAhead = 2;
  std::deque<std::future<Recorded>> ahead;
  std::size_t launched = 0;
  auto launch = [&](std::size_t consumed) {
    while (launched < drives.size() && launched < consumed + kSimulatedAhead) {
      const std::size_t site = drives[launched].site;
      // An earlier drive of the site, not yet noted, is making its map.
      if (maps[site].empty() && std::any_of(drives.begin(), drives.begin() + launched, [&](const Drive& e) { return e.site == site; })) return;
      ahead.push_back(std::async(std::launch::async, record, launched++));
    }
  };
  // A drive whose replays are queued: noted (its runs into the results, what later drives read of it)
  // in the order of the drives, once its replays have run.
  struct InFlight {
    std::size_t d = 0;
    Recorded recorded;
    std::vector<Job> jobs;
    std::shared_ptr<replay::ReplayCache> cache;
    Clock::time_point t1;
    JobPool::Batch batch;
  };
  std::deque<std::unique_ptr<InFlight>> in_flight;
  JobPool pool(config.jobs);
  auto note = [&](InFlight& f) {
    const std::size_t d = f.d;
    const Drive& drive = drives[d];
    const sim::Scenario& scenario = f.recorded.scenario;
    const std::string& name = f.recorded.name;
    const std::string& variant = f.recorded.variant;
    const TwinRecordingOptions& rec = f.recorded.options;
    const double simulated_in = f.recorded.seconds;
    const auto t1 = f.t1;
    std::vector<Job>& jobs = f.jobs;
    const std::shared_ptr<replay::ReplayCache>& cache = f.cache;
    std::size_t replays_again = 0;  // the noise calibration drive's further passes
    {
      const ndt::AlignmentMemoStats shared = cache->alignments()->stats();
      results.timing.matches_asked += shared.asked;
      results.timing.matches_computed += shared.computed;
      results.timing.preprocessings_computed += shared.preprocessings_computed;
    }
    for (Job& j : jobs) {
      results.timing.replay += j.run.replay_seconds;
      if (drive.variant == kNoiseCalibrationDrive) {
        const pipeline::Config first = j.config;  // before it took any of what the drive measures
        const bool by_place = config.ndt_quality_by_place && config.ndt_covariance == NdtCovarianceSource::kMultiNdtScore;
        for (int pass = 1;; ++pass) {
          ndt_variance[drive.site] = ndtVariance(j.run.ndt, scenario.name);
          const bool last = !by_place || pass >= config.ndt_quality_passes;
          if (by_place) {
            // The evaluated drives' map under its own name, an earlier pass's (which the next replayed
            // with) under its pass's.
            const pipeline::NdtQualityMap quality = replay::ndtQualityMap(j.ndt_errors);
            const std::string file = last ? "/ndt_quality.yaml" : "/ndt_quality_pass_" + std::to_string(pass) + ".yaml";
            ndt_quality[drive.site] = fs::absolute(rec.out_dir + file).lexically_normal().string();
            std::ofstream(ndt_quality[drive.site]) << quality.toYaml();
            ndt_quality_default[drive.site] = quality.defaultVariance();
            results.ndt_quality_cells[scenario.name] = quality.cells();
          }
          if (last) break;
          // Again with what this pass measured, as the evaluated drives take it.
          j.config = first;
          takeNdtFigures(j.config, drive.site);
          j.run.variant = variant + ", pass " + std::to_string(pass + 1);
          if (config.recordings) writeReplayConfig(j, rec.out_dir + "/replays");
          runJob(j);
          results.timing.replay += j.run.replay_seconds;
          ++replays_again;
        }
        results.estimated_ndt_variance[scenario.name] = *ndt_variance[drive.site];
        accurate_places[drive.site] = std::make_shared<const replay::AccuratePlaces>(replay::AccuratePlaces::fromErrors(
            j.ndt_errors, j.run.ndt.stretch_length, j.run.ndt.accurate_below, replay::AccuratePlaces::kMinPoses));
        continue;  // never evaluated
      }
      if (j.calibrate && j.registry) {
        bool any = false;
        for (const rsu_client::RsuInfo& info : j.registry->rsus()) {
          CalibrationResult c;
          c.site = scenario.name;
          c.lidar = j.run.lidar;
          c.rsu = info.id;
          for (const sim::ScenarioRsu& r : scenario.rsus)
            if (r.id == info.id) c.rsu = siteRsuId(r);
          c.dx = config.calibration_error[0], c.dy = config.calibration_error[1];
          c.dyaw = config.calibration_error[2] * M_PI / 180.0;
          c.clock_offset = 1e-3 * config.calibration_clock_offset_ms;
          if (const auto found = j.calibrations.find(info.id); found != j.calibrations.end()) c.found = found->second;
          else c.found.note = "no fix of this RSU on the drive";
          results.calibrations.push_back(c);
          if (const rsu_client::RsuInfo* calibrated = j.calibrated ? j.calibrated->find(info.id) : nullptr) any = any || calibrated->calibration.has_value();
        }
        if (any) calibrated_registries.emplace(std::make_pair(drive.site, j.run.lidar), *j.calibrated);
      }
      if (j.smoothed) {
        results.timing.replay += j.smoothed->replay_seconds;
        results.runs.push_back(std::move(*j.smoothed));
      }
      results.runs.push_back(std::move(j.run));
    }
    results.timing.replays += jobs.size() + replays_again;
    if (progress.fraction) progress.fraction(static_cast<double>(d + 1) / drives.size());
    if (progress.step) {
      char line[256];
      std::snprintf(line, sizeof line, "[%zu/%zu] %s%s%s: drive simulated in %.1f s, %zu replays in %.1f s", d + 1, drives.size(),
                    name.c_str(), variant.empty() ? "" : ", ", variant.c_str(), simulated_in, jobs.size() + replays_again, since(t1));
      progress.step(line);
    }
  };
  auto noteFirst = [&] {
    pool.wait(in_flight.front()->batch);
    note(*in_flight.front());
    in_flight.pop_front();
  };
  // At most two drives in flight (their logs in memory beside the drives simulated ahead), and a site's
  // noise calibration drive (NDT's figures, the RSUs' variance) or calibration drive (the calibrated
  // registries) noted before the site's next drive's replays are made from what it found.
  constexpr std::size_t kDrivesInFlight = 2;
  const auto feeds = [&](const InFlight& f, std::size_t d) {
    const Drive& earlier = drives[f.d];
    return earlier.site == drives[d].site && (earlier.variant == kNoiseCalibrationDrive || earlier.variant == kCalibrationDrive);
  };
  launch(0);
  for (std::size_t d = 0; d < drives.size(); ++d) {
    while (!in_flight.empty() &&
           (in_flight.size() >= kDrivesInFlight || std::any_of(in_flight.begin(), in_flight.end(), [&](const auto& f) { return feeds(*f, d); })))
      noteFirst();
    const Drive& drive = drives[d];
    if (ahead.empty()) launch(d);
    auto flight = std::make_unique<InFlight>();
    flight->d = d;
    flight->recorded = ahead.front().get();
    Recorded& recorded = flight->recorded;
    ahead.pop_front();
    if (maps[drive.site].empty()) {
      maps[drive.site] = recorded.summary.map_dir;
      results.timing.survey += recorded.summary.map_seconds;
    }
    {
      std::lock_guard<std::mutex> lock(sweeps_mutex);
      for (const auto& [key, last] : last_use)
        if (last == d) sweep_caches.erase(key);
    }
    launch(d + 1);
    const sim::Scenario& scenario = recorded.scenario;
    const std::string& variant = recorded.variant;
    const TwinRecordingOptions& rec = recorded.options;
    const TwinRecordingSummary& summary = recorded.summary;
    results.timing.simulation += summary.wall_seconds - summary.map_seconds;
    results.timing.ray_casting += summary.ray_casting_seconds;
    results.timing.perception += summary.perception_seconds;
    results.timing.rays += summary.rays;
    results.timing.reused_sweeps += summary.reused_sweeps;
    results.timing.lidar += summary.lidar_seconds;
    results.timing.driven_seconds += summary.drive_seconds;

    // Its replays.
    pipeline::Config fuse = base;
    fuse.pipeline.initial_pose = Eigen::Vector4d(scenario.route_start.x(), scenario.route_start.y(), 0.0, scenario.route_heading);
    // The start is the twin's truth, not a person's guess: holding it against the map (about 125 NDT
    // matches from rings around it in the first 10 s) finds nothing and cost a third of each replay.
    fuse.pipeline.start_check_radii.clear();
    fuse.ndt.source.lidar_pose = Vector6d::Zero();
    fuse.ndt.source.lidar_pose[2] = scenario.vehicle_lidar_height;
    fuse.ndt.lidar_pose_given = true;
    // The map's survey accuracy, as coloc simulate writes it into fuse.yaml: reported, never filtered
    // (the sites' replays had 0.3-13 % of their localized ticks beyond 3 sd without it, none with it).
    if (fuse.fusion.map_error_sd == 0.0) fuse.fusion.map_error_sd = scenario.errors.map_position_sd;
    // The car knows its own size and what its CAM rounds it to, as coloc simulate writes them.
    if (scenario.errors.cam_size_step > 0.0 && fuse.rsu.vehicle_length == 0.0) {
      fuse.rsu.vehicle_length = summary.ego_length;
      fuse.rsu.vehicle_width = summary.ego_width;
      fuse.rsu.cam_size_step = scenario.errors.cam_size_step;
    }
    std::vector<Eigen::Vector2d> rsu_positions;
    for (const sim::ScenarioRsu& r : scenario.rsus) rsu_positions.push_back(r.position);
    // The drive's replays read its log once, and each NDT target of the site is built once (the same
    // results as apart).
    flight->cache = std::make_shared<replay::ReplayCache>(site_targets[drive.site]);
    const std::shared_ptr<replay::ReplayCache>& cache = flight->cache;
    cache->add(rec.out_dir + "/log", summary.log);
    // The fixes' variance under each way of setting it; the estimate comes from the site's noise calibration
    // drive (none for an RSU that sent too few fixes there: its fixes keep the covariance they carry).
    auto varianceFor = [&](RsuCovariance how, const sim::ScenarioRsu& r) -> std::optional<double> {
      const rsu_client::LidarModel* model = rsu_client::findLidarModel(r.lidar_model);
      if (how == RsuCovariance::kStandardDeviation) return model->sigma * model->sigma;
      if (how == RsuCovariance::kEstimated) {
        const auto& measured = measured_variance[drive.site];
        if (const auto found = measured.find(r.id); found != measured.end()) return found->second;
      }
      return std::nullopt;  // the fix's own covariance, as published
    };
    // NDT with every RSU of the LiDAR model `lidar` at the site (none: NDT only).
    auto makeJob = [&](const std::string& lidar, double delay, double loss, const std::string& job_variant, RsuCovariance how) {
      Job job;
      job.run.site = scenario.name;
      job.run.trial = drive.trial;
      job.run.lidar = lidar;
      job.run.delay = delay;
      job.run.loss = loss;
      job.run.variant = job_variant;
      job.log = rec.out_dir + "/log";
      job.map = maps[drive.site];
      job.cache = cache;
      job.places = accurate_places[drive.site];
      job.config = fuse;
      if (job.places && config.recordings) job.config.replay.input_reference = reference_errors[drive.site];
      job.config.rsu.checks.station_id = scenario.vehicle_station_id;  // the ego takes the fixes addressed to it
      job.rsu_positions = rsu_positions;
      takeNdtFigures(job.config, drive.site);
      if (config.twist_covariance_estimated) {
        pipeline::InputConfig twist;
        twist.role = pipeline::InputRole::kTwist;
        Vector6d diagonal = Vector6d::Constant(kInfinity);
        diagonal[0] = twist_variance[drive.site][0];
        diagonal[5] = twist_variance[drive.site][1];
        twist.covariance_diagonal = diagonal;
        job.config.inputs["/vehicle/twist"] = twist;
      }
      std::vector<rsu_client::RsuInfo> fused;
      for (const sim::ScenarioRsu& r : scenario.rsus) {
        pipeline::InputConfig input;
        const std::string topic = rsu_client::addressedFixTopic(r.id);
        if (r.lidar_model == lidar) {
          // The fixes pass the same checks as fixes over DDS; the registry carries the variance chosen.
          input.role = pipeline::InputRole::kRsuFix;
          job.fix_topics.push_back(topic);
          job.fix_sources.push_back(rsu_client::fixTopic(r.id));
          rsu_client::RsuInfo info = registryEntry(r);
          info.calibrated_variance = varianceFor(how, r);
          if (how == RsuCovariance::kEstimated && info.calibrated_variance)
            if (const auto b = measured_error_by_range[drive.site].find(r.id); b != measured_error_by_range[drive.site].end())
              info.calibrated_error_by_range = b->second;
          const bool same_installation = drive.variant.empty() || drive.variant == "RSU height" || drive.variant == "speed";
          if (const auto c = commissioned.find({drive.site, r.id}); same_installation && c != commissioned.end())
            info.calibration = c->second.calibration;
          if (delay > 0.0 || loss > 0.0) {
            rsu_client::LinkConfig link;
            link.delay = delay;
            link.loss = loss;
            // Each RSU's link its own draws (the first RSU's as with one RSU per site).
            link.seed = 7919 * (drive.trial + 1) + static_cast<std::uint64_t>(std::llround(delay * 1e4 + loss * 1e2)) + 104729 * fused.size();
            input.link = link;
          }
          fused.push_back(info);
        }
        job.config.inputs[topic] = input;
      }
      if (!fused.empty()) job.registry = rsu_client::RsuRegistry(fused, rsu_client::CovariancePlacement::kPublished);
      return job;
    };
    const RsuCovariance main_covariance = config.rsu_covariance;
    std::vector<Job>& jobs = flight->jobs;
    if (drive.variant == kNoiseCalibrationDrive) {
      for (const sim::ScenarioRsu& r : scenario.rsus) {
        const auto errors = summary.fix_errors.find(r.id);
        const std::size_t fixes = errors == summary.fix_errors.end() ? 0 : errors->second.size();
        if (const auto v = robustFixVariance(fixes ? errors->second : std::vector<Eigen::Vector2d>{})) {
          measured_variance[drive.site][r.id] = *v;
          results.estimated_variance[reportKey(scenario, r)] = *v;
        } else {
          results.notes.push_back(reportKey(scenario, r) + ": " + std::to_string(fixes) + " fixes on the noise calibration drive, too few (" +
                                  std::to_string(kFewestFixes) + ") to estimate their variance: they keep the covariance they are sent with");
        }
      }
      twist_variance[drive.site] = odometryVariance(summary.odometry, scenario.name);
      // NDT alone on this drive, against ground truth: its covariance for the evaluated drives.
      if (config.ndt_covariance != NdtCovarianceSource::kPublished) {
        jobs.push_back(makeJob("", 0.0, 0.0, variant, main_covariance));
        jobs.back().keep_ndt_errors = true;  // NDT's error by place
        if (config.recordings) {
          reference_errors[drive.site] = fs::absolute(rec.out_dir + "/input_error.csv").lexically_normal().string();
          jobs.back().input_error_csv = reference_errors[drive.site];
        }
      }
      for (const sim::ScenarioRsu& r : scenario.rsus)
        if (const auto f = summary.rsu_frames.find(r.id); f != summary.rsu_frames.end()) results.ideal_comparison[reportKey(scenario, r)] = f->second;
      results.estimated_twist_variance[scenario.name] = twist_variance[drive.site];
      if (config.calibrate_rsus)
        for (const sim::ScenarioRsu& r : scenario.rsus) {
          // Commissioning against the reference vehicle: its fixes matched by stamp to where the
          // vehicle was; the evaluated drives then use the calibration, and the fixes' variance is
          // measured as the calibrated registry passes them on.
          const auto samplesOf = [&](const std::map<std::string, std::vector<rsu_client::CommissioningSample>>& all) {
            const auto found = all.find(r.id);
            return found == all.end() ? std::vector<rsu_client::CommissioningSample>{} : found->second;
          };
          const std::vector<rsu_client::CommissioningSample> sent = samplesOf(summary.fix_samples), probe = samplesOf(summary.probe_fix_samples);
          // The probe's own size where its CAM would round it; the survey is then not the rounding's.
          const std::vector<rsu_client::CommissioningSample>& samples = probe.empty() ? sent : probe;
          const rsu_client::RsuInfo entry = registryEntry(r);
          Commissioning c;
          c.site = scenario.name;
          c.lidar = r.lidar_model;
          c.rsu = siteRsuId(r);
          c.dx = r.survey_error.x(), c.dy = r.survey_error.y(), c.dyaw = r.survey_error.z(), c.clock_offset = r.clock_offset;
          c.found = rsu_client::commissionRsu(entry.position, samples);
          // The fixes as sent, calibrated, against where the vehicle was at their (corrected) stamps.
          const std::vector<Eigen::Vector2d> residuals =
              probe.empty() ? c.found.residuals : rsu_client::commissioningResiduals(entry.position, sent, c.found.calibration);
          // Each against its own fit's covariance: is what a fix says of itself honest?
          if (const auto fc = summary.fix_covariances.find(r.id);
              c.found.determined && fc != summary.fix_covariances.end() && fc->second.size() == residuals.size()) {
            double sum = 0.0;
            for (std::size_t i = 0; i < residuals.size(); ++i) {
              const Eigen::Matrix2d& C = fc->second[i];
              if (!C.allFinite() || !residuals[i].allFinite() || C.determinant() <= 0.0) continue;
              const double d2 = residuals[i].dot(C.ldlt().solve(residuals[i]));
              sum += d2;
              ++c.fixes;
              c.beyond_3sd += d2 > 9.0 ? 1 : 0;
            }
            c.mean_nes = c.fixes ? sum / static_cast<double>(c.fixes) : 0.0;
          }
          results.commissioning.push_back(c);
          if (!c.found.determined) continue;
          rsu_client::RsuInfo calibrated = entry;
          calibrated.calibration = c.found.calibration;
          commissioned[{drive.site, r.id}] = calibrated;
          // The fixes' variance as the filter will see them: after the vehicle has taken its CAM's
          // rounding of its size back (rsu.vehicle_length, rsu.vehicle_width), which moves a fix by a
          // centimetre or two towards the end and side the RSU sees and is no error of the fixes the
          // filter gets (site E's VLP-32C within 10 m: 1.5 cm along the road as sent, 0.6 cm taken).
          // With rsu_fix_error: by_range also by range, along and across the line of sight.
          const pipeline::CamSizeCorrection cam{fuse.rsu.vehicle_length, fuse.rsu.vehicle_width, fuse.rsu.cam_size_step, fuse.rsu.cam_length,
                                                fuse.rsu.cam_width};
          std::vector<Eigen::Vector2d> at, taken = residuals;
          std::vector<double> headings;
          for (std::size_t i = 0; i < sent.size(); ++i) {
            at.push_back(sent[i].fix);
            const Eigen::Vector2d& v = sent[i].velocity;
            const double heading = v.norm() > 0.1 ? std::atan2(v.y(), v.x()) : std::nan("");  // none standing
            headings.push_back(heading);
            if (cam.enabled() && i < taken.size() && std::isfinite(heading)) taken[i] += cam.apply(sent[i].fix, entry.position, heading) - sent[i].fix;
          }
          const std::vector<rsu_client::RsuInfo::ErrorAtRange> by_range =
              config.rsu_fix_error_by_range
                  ? rsu_client::fixErrorByRange(entry.position, at, taken, kFixErrorBand, kFewestFixes,
                                                config.rsu_fix_error_mean ? headings : std::vector<double>{})
                  : std::vector<rsu_client::RsuInfo::ErrorAtRange>{};
          if (const auto v = meanSquareFixVariance(taken)) {
            measured_variance[drive.site][r.id] = *v;
            results.estimated_variance[reportKey(scenario, r)] = *v;
            if (by_range.empty()) measured_error_by_range[drive.site].erase(r.id);
            else measured_error_by_range[drive.site][r.id] = by_range;
          }
        }
    } else if (drive.variant.empty()) {
      for (const sim::ScenarioRsu& r : scenario.rsus)
        if (const auto f = summary.rsu_frames.find(r.id); f != summary.rsu_frames.end()) {
          auto& all = results.rsu_frames[scenario.name + " " + r.lidar_model];  // every RSU of the model together
          all.insert(all.end(), f->second.begin(), f->second.end());
        }
      jobs.push_back(makeJob("", 0.0, 0.0, "", main_covariance));
      for (const std::string& lidar : config.lidars) {
        for (double delay : config.delays)
          for (double loss : config.losses)
            if ((delay == 0.0 && loss == 0.0) || (config.network && drive.trial < config.network_trials))
              jobs.push_back(makeJob(lidar, delay, loss, "", main_covariance));
      }
      // Table I compares with a second covariance on every trial; the sweeps add the third.
      const RsuCovariance reference = referenceCovariance(main_covariance);
      for (const std::string& lidar : config.lidars) {
        jobs.push_back(makeJob(lidar, 0.0, 0.0, std::string("covariance ") + toString(reference), reference));
        if (config.sweeps && drive.trial < config.sweep_trials)
          for (RsuCovariance how : {RsuCovariance::kPublished, RsuCovariance::kStandardDeviation, RsuCovariance::kEstimated})
            if (how != main_covariance && how != reference)
              jobs.push_back(makeJob(lidar, 0.0, 0.0, std::string("covariance ") + toString(how), how));
      }
    } else if (drive.variant == kCalibrationDrive) {
      for (const std::string& lidar : config.lidars) {
        jobs.push_back(makeJob(lidar, 0.0, 0.0, variant, main_covariance));
        jobs.back().calibrate = true;
      }
    } else if (drive.variant == kNextDrive) {
      for (const std::string& lidar : config.lidars) {
        jobs.push_back(makeJob(lidar, 0.0, 0.0, kNextMiscalibrated, main_covariance));
        const auto found = calibrated_registries.find({drive.site, lidar});
        if (found == calibrated_registries.end()) continue;
        // Each RSU with the calibration the calibration drive found for it, where it found one.
        Job calibrated = makeJob(lidar, 0.0, 0.0, kNextCalibrated, main_covariance);
        std::vector<rsu_client::RsuInfo> rsus = calibrated.registry->rsus();
        for (rsu_client::RsuInfo& info : rsus)
          if (const rsu_client::RsuInfo* c = found->second.find(info.id)) info.calibration = c->calibration;
        calibrated.registry = rsu_client::RsuRegistry(rsus, rsu_client::CovariancePlacement::kPublished);
        jobs.push_back(std::move(calibrated));
      }
      // The same RSUs perfect: their twins' topics fused under their twins' ids, the RSUs' own ignored.
      for (const std::string& lidar : config.lidars) {
        Job perfect = makeJob(lidar, 0.0, 0.0, kNextPerfect, main_covariance);
        std::vector<rsu_client::RsuInfo> twins;
        perfect.fix_topics.clear();
        perfect.fix_sources.clear();
        for (const sim::ScenarioRsu& r : scenario.rsus) {
          const std::string own = rsu_client::addressedFixTopic(r.id), twin = rsu_client::addressedFixTopic(perfectRsuId(r.id));
          perfect.config.inputs[twin] = perfect.config.inputs[own];
          perfect.config.inputs[own] = pipeline::InputConfig();
          if (r.lidar_model != lidar) continue;
          sim::ScenarioRsu exact = r;
          exact.id = perfectRsuId(r.id);
          exact.survey_error.setZero();
          exact.clock_offset = 0.0;
          rsu_client::RsuInfo info = registryEntry(exact);
          info.calibrated_variance = perfect.registry->find(r.id)->calibrated_variance;
          info.calibrated_error_by_range = perfect.registry->find(r.id)->calibrated_error_by_range;
          twins.push_back(info);
          perfect.fix_topics.push_back(twin);
          perfect.fix_sources.push_back(rsu_client::fixTopic(perfectRsuId(r.id)));
        }
        perfect.registry = rsu_client::RsuRegistry(twins, rsu_client::CovariancePlacement::kPublished);
        jobs.push_back(std::move(perfect));
      }
      // The twins' topics are not the other replays' inputs.
      for (Job& j : jobs)
        for (const sim::ScenarioRsu& r : scenario.rsus) j.config.inputs.emplace(rsu_client::addressedFixTopic(perfectRsuId(r.id)), pipeline::InputConfig());
    } else {
      if (drive.variant == "speed") jobs.push_back(makeJob("", 0.0, 0.0, variant, main_covariance));
      for (const std::string& lidar : config.lidars) jobs.push_back(makeJob(lidar, 0.0, 0.0, variant, main_covariance));
    }
    // Runs whose figures all lie within coverage end there.
    double widest = 0.0;
    for (const std::string& lidar : config.lidars)
      if (const rsu_client::LidarModel* m = rsu_client::findLidarModel(lidar)) widest = std::max(widest, m->range);
    for (Job& j : jobs)
      if (reportedWithinCoverageOnly(j.run, config)) j.until = coverageEnd(summary, rsu_positions, widest, j.fix_topics, j.run.delay);
    // Table I's smoother column: the NDT-only replay and each LiDAR's on the ideal network.
    if (drive.variant.empty() && config.smoother)
      for (Job& j : jobs)
        if (j.run.variant.empty() && j.run.delay == 0.0 && j.run.loss == 0.0) j.smooth = true;
    if (config.recordings)
      for (const Job& j : jobs) writeReplayConfig(j, rec.out_dir + "/replays");
    flight->t1 = Clock::now();
    flight->batch.jobs = &jobs;
    pool.submit(flight->batch);
    in_flight.push_back(std::move(flight));
  }
  while (!in_flight.empty()) noteFirst();
  results.timing.total = since(start);
  return results;
}

}  // namespace coloc::twin
