#include "coloc/pipeline/pipeline.hpp"

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <sstream>
#include <thread>
#include <variant>

#include "coloc/core/error.hpp"
#include "coloc/core/principal_variances.hpp"
#include "coloc/rsu_client/dds_transport.hpp"
#include "inbox.hpp"
#include "initializer.hpp"
#include "speed_scale.hpp"
#include "coloc/pipeline/cam_size_correction.hpp"
#include "fix_agreement.hpp"
#include "coloc/pipeline/ndt_quality_map.hpp"
#include "travel_check.hpp"
#include "mount_yaw.hpp"
#include "yaw_rate_bias.hpp"

namespace coloc::pipeline {

namespace {

struct ScanInput {
  std::shared_ptr<const ndt::PointCloud> cloud;  ///< shared, not copied, when the caller shares it
  Stamp stamp;
};
struct TwistInput {
  fusion::SourceId source;
  TwistMeasurement twist;
};
struct PoseInput {
  fusion::SourceId source;
  PoseMeasurement pose;
};
struct FixInput {
  rsu_client::RsuFix fix;
};
struct InitialPoseInput {
  PoseMeasurement pose;
};
/// NDT's result for a scan, back from the NDT thread.
struct NdtResult {
  ndt::ScanOutcome outcome;
  Stamp scan_stamp;
  std::uint64_t timeline;  ///< the pipeline's timeline when the scan was submitted (see Impl::timeline)
};
using Input = std::variant<ScanInput, TwistInput, PoseInput, FixInput, InitialPoseInput, NdtResult>;

Stamp stampOf(const Input& input) {
  return std::visit(
      [](const auto& i) -> Stamp {
        using T = std::decay_t<decltype(i)>;
        if constexpr (std::is_same_v<T, ScanInput>) return i.stamp;
        else if constexpr (std::is_same_v<T, TwistInput>) return i.twist.stamp;
        else if constexpr (std::is_same_v<T, FixInput>) return i.fix.stamp;
        else if constexpr (std::is_same_v<T, NdtResult>) return i.scan_stamp;
        else return i.pose.stamp;
      },
      input);
}

PoseMeasurement initialPose(const Eigen::Vector4d& xyz_yaw, Stamp stamp) {
  PoseMeasurement m;
  m.stamp = stamp;
  m.pose.position = xyz_yaw.head<3>();
  m.pose.orientation = quaternionFromRollPitchYaw(0.0, 0.0, xyz_yaw[3]);
  m.covariance = Matrix6d::Zero();
  m.covariance.diagonal() << 1.0, 1.0, 1.0, kInfinity, kInfinity, 0.01;  // a rough start, as a hand-placed pose
  return m;
}

constexpr std::size_t kKeptRejections = 20;
constexpr std::size_t kKeptEvents = 50;

}  // namespace

// NDT on a thread of its own (live): one scan matched at a time; a newer scan replaces the one waiting.
class NdtThread {
 public:
  using Done = std::function<void(ndt::ScanOutcome, Stamp scan_stamp, std::uint64_t timeline)>;
  /// `use`: held while the source matches, so that the pipeline's own use of it (a heading search) waits.
  NdtThread(ndt::NdtPoseSource& source, std::mutex& use, Done done)
      : source_(source), use_(use), done_(std::move(done)), thread_([this] { run(); }) {}
  ~NdtThread() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    thread_.join();
  }
  /// False if a waiting scan was replaced.
  bool submit(std::shared_ptr<const ndt::PointCloud> cloud, Stamp stamp, const fusion::Estimate& guess, std::uint64_t timeline) {
    std::lock_guard<std::mutex> lock(mutex_);
    const bool replaced = job_.has_value();
    job_ = Job{std::move(cloud), stamp, guess, timeline};
    wake_.notify_all();
    return !replaced;
  }
  ndt::NdtPoseSourceCounters counters() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return counters_;
  }
  ndt::DynamicMapStats mapStats() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return map_stats_;
  }

 private:
  struct Job {
    std::shared_ptr<const ndt::PointCloud> cloud;
    Stamp stamp;
    fusion::Estimate guess;
    std::uint64_t timeline;
  };
  void run() {
    for (;;) {
      Job job;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return stop_ || job_.has_value(); });
        if (stop_) return;
        job = std::move(*job_);
        job_.reset();
      }
      ndt::ScanOutcome outcome;
      {
        std::lock_guard<std::mutex> using_source(use_);
        outcome = source_.process(job.cloud, job.stamp, job.guess.pose, job.guess.state[4], job.guess.state[5]);
      }
      {
        std::lock_guard<std::mutex> lock(mutex_);
        counters_ = source_.counters();
        map_stats_ = source_.map().stats();
      }
      done_(std::move(outcome), job.stamp, job.timeline);
    }
  }
  ndt::NdtPoseSource& source_;
  std::mutex& use_;
  Done done_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<Job> job_;
  bool stop_ = false;
  ndt::NdtPoseSourceCounters counters_;
  ndt::DynamicMapStats map_stats_;
  std::thread thread_;  // last: starts once everything above exists
};

struct Pipeline::Impl {
  Config config;
  Duration step;
  std::function<Stamp()> now;
  Inbox<Input> inbox;

  mutable std::mutex state_mutex;  // the filter and everything below; held while draining
  fusion::Localizer localizer;
  std::vector<std::string> source_names;  // by SourceId
  std::unique_ptr<ndt::NdtPoseSource> ndt;
  std::mutex ndt_use;  // live: the NDT thread's matching and the pipeline's heading search take turns
  // The newest scan pushed, for align(): matched on the caller's thread.
  std::mutex last_scan_mutex;
  std::shared_ptr<const ndt::PointCloud> last_scan;
  Stamp last_scan_stamp = 0;
  fusion::SourceId ndt_id = -1;
  Initializer initializer;
  // A start given by hand is held against the map at the next scan and every start_check_interval
  // after, until an RSU's fix agrees with the filter.
  bool check_start = false;
  bool start_ambiguous = false;  // the start check found another place that matches as well
  static constexpr double kElsewhere = 1.0;  // m: a match landing farther from the estimate's is elsewhere
  Stamp next_start_check = 0, start_check_end = 0;
  fusion::LocalizationState last_state = fusion::LocalizationState::kInitialising;
  std::optional<rsu_client::FixChecker> checker;
  std::map<std::string, fusion::SourceId> fix_sources;  // by RSU id
  SpeedScaleConfig speed_scale_config;
  YawRateBiasConfig yaw_rate_bias_config;
  MountYawConfig mount_yaw_config;
  SpeedScaleEstimator speed_scale;
  YawRateBiasEstimator yaw_rate_bias;
  MountYawEstimator mount_yaw;
  TravelCheck travel_check;
  FixAgreement fix_agreement;
  NdtQualityMap ndt_quality;  ///< empty without ndt.quality_map
  CamSizeCorrection cam_size;
  Eigen::Isometry3d base_to_lidar = Eigen::Isometry3d::Identity();  // the configured extrinsic
  bool first_input_seen = false;
  Stamp clock = 0;
  std::optional<Stamp> last_anchor;  ///< stamp of the newest roadside fix the filter took
  std::optional<Stamp> last_release;  ///< of the newest fix NDT's followed bias was let in before
  /// Counts the clock's jumps back: NDT's results from scans submitted before one are dropped.
  std::uint64_t timeline = 0;
  bool clock_set = false;
  PipelineReport report;
  std::function<void(const fusion::Estimate&)> on_estimate;
  std::function<void(const std::string&, const PoseMeasurement&)> on_pose_input, on_pose_weighed;
  std::function<void(const std::string&, const fusion::Estimate&)> on_pose_settled;
  struct Settling {
    std::string source;
    Stamp stamp, fed;  ///< the pose's stamp, and the pipeline's clock when the filter took it
  };
  std::deque<Settling> settling;
  std::function<void(const std::string&, const TwistMeasurement&, const TwistMeasurement&)> on_twist_input;
  std::function<void(const std::string&)> on_rejection;
  std::function<void(const std::string&)> on_event;

  mutable std::mutex estimate_mutex;
  std::optional<fusion::Estimate> latest;

  std::unique_ptr<NdtThread> ndt_thread;  // declared after what it uses, so it stops first
  std::thread loop;
  std::mutex loop_mutex;
  std::condition_variable loop_wake;
  bool loop_stop = false;

  Impl(const Config& c, PipelineOptions& options)
      : config(c),
        step(static_cast<Duration>(std::llround(1e9 / c.fusion.predict_frequency))),
        now(options.clock ? options.clock : std::function<Stamp()>(rsu_client::systemNow)),
        localizer(c.fusion),
        speed_scale_config{c.pipeline.speed_scale_estimation && options.map.has_value(), 5.0, c.pipeline.speed_scale_memory, c.pipeline.speed_scale_min_distance},
        yaw_rate_bias_config{c.pipeline.yaw_rate_bias_estimation && options.map.has_value(), 2.0, c.pipeline.yaw_rate_bias_memory},
        mount_yaw_config{c.pipeline.mount_yaw_estimation && options.map.has_value(), 5.0, c.pipeline.mount_yaw_memory},
        speed_scale(speed_scale_config),
        yaw_rate_bias(yaw_rate_bias_config),
        mount_yaw(mount_yaw_config),
        travel_check(TravelCheckConfig{options.map.has_value() ? c.pipeline.travel_check_window : 0.0, c.pipeline.travel_check_tolerance,
                                       c.pipeline.travel_check_tolerance_per_metre, 5.0, c.pipeline.travel_check_turn_tolerance}),
        fix_agreement(FixAgreementConfig{options.map.has_value() ? c.pipeline.fix_agreement_window : 0.0, c.pipeline.fix_agreement_tolerance}),
        cam_size{c.rsu.vehicle_length, c.rsu.vehicle_width, c.rsu.cam_size_step, c.rsu.cam_length, c.rsu.cam_width} {
    const Vector6d& e = c.ndt.source.lidar_pose;
    base_to_lidar = Eigen::Translation3d(e.head<3>()) * Eigen::Quaterniond(quaternionFromRollPitchYaw(e[3], e[4], e[5]));
    localizer.setVerdictListener([this](const fusion::Verdict& v) {
      if (v.rejected()) reject(v.message());
    });
    if (options.map && !c.ndt.quality_map.empty()) ndt_quality = NdtQualityMap::load(c.ndt.quality_map);
    localizer.setMapMatchBiasVariance(0.0);  // held until a roadside fix tells the bias apart (handle())
    if (options.map) {
      ndt::NdtPoseSourceConfig ndt_config = config.ndt.source;
      // Offline the target is built inline: the same log then gives the same bytes, whatever the machine's speed.
      if (!options.ndt_thread) ndt_config.map.background = false;
      ndt = std::make_unique<ndt::NdtPoseSource>(std::move(*options.map), ndt_config, options.targets, options.alignments);
      ndt_id = addSource(kNdtSource, fusion::SourceKind::kPose);
      report.ndt_used = true;
      if (options.ndt_thread)
        ndt_thread = std::make_unique<NdtThread>(*ndt, ndt_use, [this](ndt::ScanOutcome outcome, Stamp stamp, std::uint64_t line) {
          inbox.push(NdtResult{std::move(outcome), stamp, line}, now());
        });
    }
    if (options.registry) {
      checker.emplace(std::move(*options.registry), config.rsu.checks);
      for (const rsu_client::RsuInfo& rsu : checker->registry().rsus())
        fix_sources[rsu.id] = addSource(rsu_client::fixTopic(rsu.id), fusion::SourceKind::kPose, config.rsu.smoothing_steps, true);  // anchors
    }
  }

  fusion::SourceId addSource(const std::string& name, fusion::SourceKind kind, int smoothing_steps = 0, bool anchor = false) {
    const fusion::SourceId id = kind == fusion::SourceKind::kPose ? localizer.addPoseSource(name, smoothing_steps, anchor) : localizer.addTwistSource(name);
    if (static_cast<std::size_t>(id) >= source_names.size()) source_names.resize(id + 1);
    source_names[id] = name;
    return id;
  }

  void reject(const std::string& line) {
    ++report.rejections;
    if (report.first_rejections.size() < kKeptRejections) report.first_rejections.push_back(line);
    if (on_rejection) on_rejection(line);
  }

  // Starts, recoveries, state changes and clock resets: said once each, as they happen.
  void event(const std::string& line) {
    ++report.events;
    if (report.first_events.size() < kKeptEvents) report.first_events.push_back(line);
    if (on_event) on_event(line);
  }

  void noteState() {
    const fusion::IntegrityStatus& s = localizer.integrity();
    report.state = s.state;
    report.state_reason = s.reason;
    report.degradations = s.degradations;
    report.losses = s.losses;
    if (s.state == last_state) return;
    last_state = s.state;
    if (s.state != fusion::LocalizationState::kInitialising)
      event(formatSeconds(s.since) + " " + toString(s.state) + (s.reason.empty() ? std::string() : ": " + s.reason));
  }

  // Starts (or restarts) the filter from a pose the initializer found, saying how and why.
  void start(const StartPose& start, const std::string& why) {
    resetChecks();
    localizer.initialize(start.pose, initializer.twist());
    if (!localizer.initialized()) return;
    last_state = fusion::LocalizationState::kLocalized;
    noteState();
    report.started_how = start.how;
    event(formatSeconds(start.pose.stamp) + " " + why + ": " + start.how);
    emit(*localizer.estimate());
  }

  // A start from a pose given by hand: counted and said, and held against the map from the next scan.
  void startedByHand(const std::string& how, Stamp stamp) {
    resetChecks();
    ++report.starts;
    report.started_how = how;
    check_start = true;
    start_ambiguous = false;
    next_start_check = 0;
    last_state = fusion::LocalizationState::kLocalized;
    event(formatSeconds(stamp) + " started: " + how);
    // Until the map has been asked, the filter has only a person's word for where it is.
    if (ndt && !config.pipeline.start_check_radii.empty()) {
      localizer.doubt("a pose given by hand, not yet held against the map", Eigen::Matrix2d::Zero().eval());
      start_ambiguous = true;
    }
    noteState();
  }

  void tryStart() {
    std::lock_guard<std::mutex> using_ndt(ndt_use);
    std::string waiting;
    const std::optional<StartPose> found = initializer.tryStart(ndt.get(), std::nullopt, waiting);
    report.state_reason = waiting;
    if (!found) return;
    ++report.starts;
    start(*found, "started");
  }

  // A lost filter starts again from the sources that agree: the RSU's position first, the heading
  // searched by NDT near the filter's own, or the direction of travel.
  void tryRecover() {
    const std::string why = localizer.integrity().reason;
    const double heading = rollPitchYaw(fusion::measuredPose(*localizer.estimate()).orientation)[2];
    std::lock_guard<std::mutex> using_ndt(ndt_use);
    std::string waiting;
    const std::optional<StartPose> found = initializer.tryStart(ndt.get(), heading, waiting);
    if (!found) return;
    ++report.recoveries;
    if (report.recovery_reasons.size() < kKeptRejections) report.recovery_reasons.push_back(why);
    // NDT's poses of a filter that was lost matched another place: what they taught about the odometry
    // and the mounting is not the vehicle's.
    forgetLearned();
    start(*found, "recovered (" + why + ")");
  }

  bool lost() const { return localizer.integrity().state == fusion::LocalizationState::kLost; }

  // A pose given by hand is a person's guess, and NDT started from a wrong one confirms it: the scans
  // after it are also matched from rings around it. A clearly better match elsewhere makes the filter
  // degraded, its reported covariance covering the distance, until an RSU's fix agrees. A match
  // elsewhere about as good means the map cannot tell the two places apart (a street alike along its
  // length): degraded as well, until a later check finds the estimate's place clearly the best or an
  // RSU's fix agrees, since a filter that may be metres off must not say it is localized.
  void checkStart(const ScanInput& scan, const fusion::Estimate& guess) {
    next_start_check = scan.stamp + fromSeconds(config.pipeline.start_check_interval);
    if (!ndt || config.pipeline.start_check_radii.empty()) return;
    const fusion::IntegrityStatus& integrity = localizer.integrity();
    const bool checkable = integrity.state == fusion::LocalizationState::kLocalized ||
                           (start_ambiguous && integrity.state == fusion::LocalizationState::kDegraded && integrity.doubted);
    if (!checkable) return;
    ndt::ScanOutcome at_start;
    std::vector<ndt::Landing> landings;
    {
      std::lock_guard<std::mutex> using_ndt(ndt_use);
      ndt->searchAround(*scan.cloud, scan.stamp, guess.pose, config.pipeline.start_check_radii, 8, guess.state[4], at_start, &landings);
    }
    ++report.start_checks;
    const double own = at_start.produced ? at_start.alignment.nvtl : 0.0;
    const double margin = config.pipeline.start_check_margin;
    // Every place elsewhere (more than kElsewhere from where the estimate's own match lands) that
    // matches about as well or better, each counted once: the reported covariance covers each of them
    // within one standard deviation.
    const Eigen::Vector2d own_place = (at_start.produced ? at_start.pose.pose.position : guess.pose.position).head<2>();
    std::vector<Eigen::Vector2d> places;
    Eigen::Matrix2d spread = Eigen::Matrix2d::Zero();
    const ndt::Landing* best = nullptr;
    for (const ndt::Landing& l : landings) {
      if ((l.position - own_place).norm() <= kElsewhere || l.nvtl <= own - margin) continue;
      if (!best || l.nvtl > best->nvtl) best = &l;
      const Eigen::Vector2d offset = l.position - guess.pose.position.head<2>();
      bool seen = false;
      for (const Eigen::Vector2d& p : places) seen = seen || (p - offset).norm() <= kElsewhere;
      if (seen) continue;
      places.push_back(offset);
      spread += offset * offset.transpose();
    }
    if (!best) {  // nothing elsewhere as good: the map vouches for the estimate
      if (start_ambiguous) {
        start_ambiguous = false;
        localizer.confirm();
        noteState();
      }
      return;
    }
    const Eigen::Vector2d offset = best->position - guess.pose.position.head<2>();
    const bool better = best->nvtl >= own + margin;
    std::ostringstream why;
    why.precision(3);
    why << "NDT matches the map " << (better ? "better " : "as well ") << offset.norm() << " m from the filter's estimate, which a pose given by hand started (NVTL "
        << best->nvtl << " against " << own;
    if (places.size() > 1) why << "; " << places.size() << " such places";
    why << ")";
    localizer.doubt(why.str(), spread);
    // Said even when the state stays degraded: what the map said is why it stays so.
    if (last_state == fusion::LocalizationState::kDegraded) event(formatSeconds(scan.stamp) + " start check: " + why.str());
    noteState();
    start_ambiguous = !better;
    if (better) check_start = false;  // degraded now, until an RSU's fix agrees
  }

  // NDT's poses before a start or a reset are another story's: no chord, and no fix's comparison,
  // spans the jump.
  void resetChecks() {
    travel_check.reset();
    fix_agreement.reset();
  }

  void forgetLearned() {
    speed_scale = SpeedScaleEstimator(speed_scale_config);
    resetChecks();
    yaw_rate_bias = YawRateBiasEstimator(yaw_rate_bias_config);
    mount_yaw = MountYawEstimator(mount_yaw_config);
  }

  // The clock went back (a log played again, a player restarted): everything the filter knew belongs
  // to the other timeline. As a ROS 2 node on a jump back in time, it starts again.
  void clockWentBack(Stamp now) {
    const std::size_t dropped = inbox.dropArrivedAfter(now);
    event(formatSeconds(now) + " clock went back by " + formatSeconds(clock - now) + " s: the filter starts again" +
          (dropped ? " (" + std::to_string(dropped) + " inputs from before the jump dropped)" : std::string()));
    ++report.clock_resets;
    ++timeline;
    report.inputs_dropped_by_reset += dropped;
    localizer.reset();
    initializer.reset();
    settling.clear();
    forgetLearned();
    if (checker) checker->forgetRecent();
    first_input_seen = false;
    last_state = fusion::LocalizationState::kInitialising;
    noteState();
    clock = now;
  }

  void emit(const fusion::Estimate& e) {
    ++report.ticks;
    {
      std::lock_guard<std::mutex> lock(estimate_mutex);
      latest = e;
    }
    if (on_estimate) on_estimate(e);
  }

  // Runs the filter's ticks up to `now`, giving out each tick's estimate.
  void runTo(Stamp now) {
    if (clock_set && now < clock) now = clock;  // live: an input taken late arrived before the last drain
    if (localizer.initialized()) {
      const Stamp latest_tick = localizer.estimate()->stamp;
      if ((now - latest_tick) / step < 1'000'000) {
        for (Stamp tick = latest_tick + step; tick <= now; tick += step) {
          localizer.advanceTo(tick);
          if (localizer.integrity().state != last_state) noteState();
          emit(*localizer.estimate());
          settle(tick);
        }
      }
    }
    localizer.advanceTo(now);
    clock = now;
    clock_set = true;
  }

  // `alone`: the pose as it is worth on its own, where the filter takes it otherwise (NDT's, beside the
  // filter's bias state); what onPoseInput reports.
  fusion::Verdict feedPose(fusion::SourceId source, const PoseMeasurement& pose, const PoseMeasurement* alone = nullptr) {
    if (on_pose_input) on_pose_input(source_names[source], alone ? *alone : pose);
    if (on_pose_weighed) on_pose_weighed(source_names[source], pose);
    const bool was_initialized = localizer.initialized();
    const fusion::Verdict v = localizer.feedPose(source, pose);
    if (!was_initialized && localizer.initialized()) emit(*localizer.estimate());
    if (on_pose_settled && !v.rejected()) settling.push_back({source_names[source], pose.stamp, clock});
    return v;
  }

  // The filter's estimate for the stamp of each pose it took, once the pose's smoothing is over: what
  // it knows of that moment from everything stamped up to it, as the source's own pose does.
  void settle(Stamp tick) {
    const Duration smoothing = (config.fusion.pose_smoothing_steps + 1) * step;
    while (!settling.empty() && settling.front().fed + smoothing <= tick) {
      if (const auto e = localizer.estimateAt(settling.front().stamp)) on_pose_settled(settling.front().source, *e);
      settling.pop_front();
    }
  }

  // NDT's bias's spread at `at` for a vehicle heading `heading`: its place's whole error less its
  // scan-to-scan noise (the filter's own figure where the map has none).
  double biasSpreadAt(const Eigen::Vector2d& at, double heading) const {
    const double place = ndt_quality.varianceAt(at);
    if (!(place > 0.0)) return config.fusion.map_match_bias_sd * config.fusion.map_match_bias_sd;
    const bool by_direction = config.ndt.quality_floor == "noise" || config.ndt.quality_noise_by_direction;
    if (const std::optional<Eigen::Matrix2d> noise = by_direction ? ndt_quality.noiseAt(at, heading) : std::nullopt)
      return std::max(place - 0.5 * noise->trace(), 0.0);
    return std::max(place - ndt_quality.noiseVariance(), 0.0);
  }

  // Whether the bias is told apart at `stamp`: a roadside fix within its length of travel, or the
  // odometry's slow errors modelled as states (handle() says why).
  bool biasToldApart(Stamp stamp, const std::optional<fusion::Estimate>& now) const {
    return config.fusion.modelsOdometryErrors() || (last_anchor && stamp - *last_anchor <= biasHold(now));
  }
  // The time a fix tells the bias apart for: its length of travel at the filter's speed (1 m/s at least).
  Duration biasHold(const std::optional<fusion::Estimate>& now) const {
    return fromSeconds(config.fusion.map_match_bias_length / std::max(now ? std::abs(now->linear_velocity.x()) : 0.0, 1.0));
  }

  // Before a roadside fix that tells NDT's bias apart where NDT's poses followed it (ndt.quality_floor:
  // noise): the position carries the bias, by its place's spread. Held at nothing until the fix, the
  // filter could not move by it: on the twin's site E, entering coverage 9 cm off across the road
  // behind NDT, the first fixes moved it by nothing for 0.8 s.
  void releaseFollowedBias(Stamp stamp) {
    if (!(config.fusion.map_match_bias_sd > 0.0 && config.ndt.quality_floor == "noise" && localizer.initialized())) return;
    const std::optional<fusion::Estimate> now = localizer.estimate();
    if (!now || biasToldApart(stamp, now)) return;
    // Once for a stretch of fixes the filter refuses: each would let it in again.
    if (last_release && stamp >= *last_release && stamp - *last_release <= biasHold(now)) return;
    last_release = stamp;
    const double spread = biasSpreadAt(now->pose.position.head<2>(), rollPitchYaw(now->pose.orientation)[2]);
    localizer.setMapMatchBiasVariance(spread);
    localizer.releaseMapMatchBias(stamp, spread);
  }

  void handle(const ndt::ScanOutcome& outcome, Stamp scan_stamp) {
    if (!outcome.produced) return reject("scan stamped " + formatSeconds(scan_stamp) + ": " + outcome.detail);
    // The LiDAR's mounting yaw as learned so far: the LiDAR is where NDT put it, the car is turned
    // back by the yaw about the LiDAR's own axis (B = B_ndt E Rz(-yaw) E^-1, E the configured extrinsic).
    PoseMeasurement pose = outcome.pose;
    const double raw_yaw = rollPitchYaw(pose.pose.orientation)[2];
    if (mount_yaw.usable()) {
      const Eigen::Isometry3d ndt_base = Eigen::Translation3d(pose.pose.position) * pose.pose.orientation;
      const Eigen::Isometry3d base = ndt_base * base_to_lidar * Eigen::AngleAxisd(-mount_yaw.yaw(), Eigen::Vector3d::UnitZ()) * base_to_lidar.inverse();
      pose.pose.position = base.translation();
      pose.pose.orientation = Eigen::Quaterniond(base.rotation()).normalized();
    }
    // NDT's poses, where the filter takes them, anchor the odometry's speed scale and yaw-rate bias
    // and the mounting yaw (each from NDT's poses as matched: the yaw's differences do not see it).
    // Not while the filter is lost: NDT's poses may then match another place, and a recovery forgets
    // what they taught. While a pose given by hand is still doubted (other places match the map as
    // well), they teach all the same: a chord's length and a turn are the vehicle's wherever NDT
    // follows it, and a filter that waited follows an odometry 1 % fast and a LiDAR turned 0.6 deg for
    // the start check's seconds (the uncalibrated start, taken up at 8 m/s: 2.34 cm against NDT's
    // 1.10 over the drive; learning, 0.96 against 1.16).
    // Where a drive with a reference measured NDT's error (ndt.quality_map), its pose is worth no more
    // than NDT was there, whatever the fit's sharpness says. Where the filter models the bias NDT's
    // poses share (fusion.map_match_bias_sd), the place's error is that bias's spread there, and each
    // pose is worth NDT's scan-to-scan noise: counted once per pose, the bias would be counted again
    // with every scan.
    // The bias is told apart only by a roadside fix: it is let loose while one is within the bias's
    // length of travel. Without one, the odometry alone would split NDT's moves between the bias and
    // the vehicle, and its own slow errors (a gyro's bias, a wheel's scale) would pass for NDT's: the
    // bias is then held to nothing (it fades over its length) and the pose floored at its place's whole
    // error, as without the bias (site C's NDT alone, in coverage: 2.7 cm with the bias loose, 1.4 cm).
    // Where the filter models those slow errors as states (fusion.odometry_scale_sd,
    // odometry_yaw_rate_bias_sd), the odometry is what the filter says it is, and the bias is loose
    // everywhere.
    const Eigen::Vector2d at = pose.pose.position.head<2>();
    const double yaw = rollPitchYaw(pose.pose.orientation)[2];  // NDT's, the mounting yaw taken out
    const double place = ndt_quality.varianceAt(at);
    const bool at_noise = place > 0.0 && config.ndt.quality_floor == "noise";
    // NDT's scan-to-scan noise here, along and across the vehicle turned to the map by NDT's own
    // heading, and in yaw; a pose floored at it where its bias is followed or held apart.
    const std::optional<Eigen::Matrix2d> noise = place > 0.0 && (at_noise || config.ndt.quality_noise_by_direction)
                                                     ? ndt_quality.noiseAt(at, yaw)
                                                     : std::nullopt;
    const auto floorAtNoise = [&] {
      if (!noise) return false;
      const Eigen::Matrix2d xy = pose.covariance.topLeftCorner<2, 2>();
      pose.covariance.topLeftCorner<2, 2>() = coveringAtLeast(xy, *noise);
      if (pose.covariance.topLeftCorner<2, 2>() != xy) ++report.ndt_quality_raised;
      return true;
    };
    // At most what NDT was here on the reference drive, in each direction (and at least its noise):
    // where the scene holds NDT only loosely its score's probes, half a metre apart, spread as if it
    // held nothing (site E's open square: 0.03-0.14 m^2 along the road, where its innovations were
    // 1e-4), and trusted at that NDT's poses count for nothing along the road and its figure there
    // is 0.1-0.3. In a cutting the reference drive's error is NDT's slide and the cap stays high.
    const auto capAtError = [&] {
      const std::optional<Eigen::Matrix2d> error = ndt_quality.errorAt(at, yaw);
      if (!noise || !error) return;
      const Eigen::Matrix2d xy = pose.covariance.topLeftCorner<2, 2>();
      pose.covariance.topLeftCorner<2, 2>() = coveringAtLeast(coveredAtMost(xy, *error), *noise);
      if (pose.covariance.topLeftCorner<2, 2>() != xy) ++report.ndt_quality_lowered;
    };
    double floor = place;
    if (at_noise) {
      // The bias NDT's poses share is followed where nothing tells it apart: each pose counts only
      // what is its own. Where the map measured no noise by direction, its noise per axis.
      floor = floorAtNoise() ? 0.0 : ndt_quality.noiseVariance();
      capAtError();
      if (const std::optional<double> yaw = ndt_quality.yawNoiseAt(at)) pose.covariance(5, 5) = std::max(pose.covariance(5, 5), *yaw);
    }
    const std::optional<fusion::Estimate> now = localizer.estimate();
    if (config.fusion.map_match_bias_sd > 0.0) {
      const bool told_apart = biasToldApart(pose.stamp, now);
      double spread = 0.0;
      if (told_apart) {
        spread = biasSpreadAt(at, yaw);
        if (place > 0.0) floor = ndt_quality.noiseVariance();
        if (noise && (at_noise || floorAtNoise())) floor = 0.0;
      }
      localizer.setMapMatchBiasVariance(spread);
    }
    // The pose on its own, for whoever takes it without the filter's bias state (the smoother, NDT's
    // own topic, plots): at its place's whole error, which the bias's share is part of.
    PoseMeasurement alone = pose;
    if (place > 0.0) alone.covariance.topLeftCorner<2, 2>() = principalVariancesAtLeast(pose.covariance.topLeftCorner<2, 2>(), place);
    if (const std::optional<double> yaw = at_noise ? ndt_quality.yawErrorAt(at) : std::nullopt) alone.covariance(5, 5) = std::max(alone.covariance(5, 5), *yaw);
    if (floor > 0.0) {
      const Eigen::Matrix2d xy = pose.covariance.topLeftCorner<2, 2>();
      pose.covariance.topLeftCorner<2, 2>() = principalVariancesAtLeast(xy, floor);
      if (pose.covariance.topLeftCorner<2, 2>() != xy) ++report.ndt_quality_raised;
    }
    // Where NDT's travel disagrees with the odometry's, its pose is worth no more than the disagreement.
    // A pose with nothing to compare yet is taken at no better than the unverified figure.
    // The odometry's travel is laid along the direction of motion: NDT's yaw plus the filter's yaw bias
    // (a LiDAR turned 0.6 deg from its calibration puts a 4 m chord 4 cm aside of NDT's own heading).
    const std::optional<Eigen::Vector2d> excess =
        travel_check.check(pose.stamp, pose.pose.position.head<2>(), yaw + (now ? now->yaw_bias : 0.0));
    if (!excess) {
      for (PoseMeasurement* p : {&pose, &alone})
        p->covariance.topLeftCorner<2, 2>() = principalVariancesAtLeast(p->covariance.topLeftCorner<2, 2>(),
                                                                        config.pipeline.travel_check_unverified_sd * config.pipeline.travel_check_unverified_sd);
      ++report.ndt_travel_unverified;
    } else if (excess->squaredNorm() > 0.0) {
      for (PoseMeasurement* p : {&pose, &alone}) p->covariance.topLeftCorner<2, 2>() += *excess * excess->transpose();
      ++report.ndt_travel_disagreements;
      report.ndt_travel_max_excess = std::max(report.ndt_travel_max_excess, excess->norm());
    }
    if (const double turn = travel_check.turnDisagreement(); turn > 0.0) {
      for (PoseMeasurement* p : {&pose, &alone}) p->covariance(5, 5) += turn * turn;
      ++report.ndt_turn_disagreements;
      report.ndt_turn_max_disagreement = std::max(report.ndt_turn_max_disagreement, turn);
    }
    // Where the roadside's fixes disagree with NDT's position, its pose is worth no more than that.
    if (const std::optional<Eigen::Vector2d> off = fix_agreement.check(pose.stamp, pose.pose.position.head<2>(), yaw, place); off && off->squaredNorm() > 0.0) {
      for (PoseMeasurement* p : {&pose, &alone}) p->covariance.topLeftCorner<2, 2>() += *off * off->transpose();
      ++report.ndt_fix_disagreements;
      report.ndt_fix_max_excess = std::max(report.ndt_fix_max_excess, off->norm());
    }
    const fusion::IntegrityStatus& integrity = localizer.integrity();
    if (!feedPose(ndt_id, pose, &alone).rejected() && integrity.state != fusion::LocalizationState::kLost) {
      // NDT's own word on the pose, before any floor or check here widened it.
      speed_scale.addPose(outcome.pose.stamp, outcome.pose.pose.position.head<2>(),
                          std::sqrt(largestPrincipalVariance(outcome.pose.covariance.topLeftCorner<2, 2>())));
      yaw_rate_bias.addPose(outcome.pose.stamp, raw_yaw);
      mount_yaw.addPose(outcome.pose.pose.position.head<2>(), raw_yaw);
    }
  }

  void apply(Input& input, Stamp arrival) {
    if (auto* scan = std::get_if<ScanInput>(&input)) {
      if (!ndt) {
        ++report.scans_without_map;
        return reject("scan stamped " + formatSeconds(scan->stamp) + ": no map to match it against");
      }
      // Kept a short while: a start or a recovery searches NDT's heading on the scan nearest a position.
      initializer.addScan(scan->cloud, scan->stamp);
      if (!localizer.initialized()) {
        tryStart();
        if (!localizer.initialized()) ++report.scans_without_guess;
        return;
      }
      if (lost()) {
        tryRecover();
        if (!lost()) return;
      }
      // NDT starts from the filter's prediction for the scan's stamp; its pose goes back in stamped
      // with the scan, and the filter compensates the matching time as any delay.
      // Where the filter models the bias NDT's poses share, NDT still starts from the position without
      // it: in a weak direction the filter's odometry-held position is the better start (started from
      // position + bias on site D's cutting, NDT erred 13.0 cm instead of 11.1).
      std::optional<fusion::Estimate> guess = localizer.estimateAt(scan->stamp);
      if (!guess) {
        ++report.scans_without_guess;
        return;
      }
      // With the yaw NDT measures, not the heading of motion (fusion::measuredPose says why).
      guess->pose = fusion::measuredPose(*guess);
      if (check_start && scan->stamp >= next_start_check) {
        if (next_start_check == 0) start_check_end = scan->stamp + fromSeconds(config.pipeline.start_check_duration);
        if (scan->stamp <= start_check_end) checkStart(*scan, *guess);
        else check_start = false;
      }
      if (ndt_thread) {
        if (!ndt_thread->submit(std::move(scan->cloud), scan->stamp, *guess, timeline)) ++report.scans_superseded;
        return;
      }
      handle(ndt->process(scan->cloud, scan->stamp, guess->pose, guess->state[4], guess->state[5]), scan->stamp);
    } else if (auto* result = std::get_if<NdtResult>(&input)) {
      // A scan matched across a jump back in time belongs to the timeline before it: its pose would
      // start (or move) the filter there.
      if (result->timeline != timeline) {
        ++report.inputs_dropped_by_reset;
        return;
      }
      handle(result->outcome, result->scan_stamp);
    } else if (auto* twist = std::get_if<TwistInput>(&input)) {
      // A twist that measures speed (odometry, not an IMU) is scaled by what NDT taught about it, and
      // one that measures yaw rate has the bias NDT showed taken out.
      TwistMeasurement t = twist->twist;
      if (std::isfinite(t.covariance(0, 0))) {
        speed_scale.addTwist(t.stamp, t.linear.x());
        t.linear.x() *= speed_scale.scale();
        if (config.pipeline.speed_scale_uncertainty && speed_scale_config.enabled) {
          const double doubt = speed_scale.scaleSd() * t.linear.x();
          t.covariance(0, 0) += doubt * doubt;
        }
        travel_check.addSpeed(t.stamp, t.linear.x());
        fix_agreement.addSpeed(t.stamp, t.linear.x());
      }
      if (std::isfinite(t.covariance(5, 5))) {
        yaw_rate_bias.addTwist(t.stamp, t.angular.z());
        t.angular.z() -= yaw_rate_bias.bias();
        travel_check.addYawRate(t.stamp, t.angular.z());
      }
      initializer.setTwist(t);
      if (on_twist_input) on_twist_input(source_names[twist->source], t, twist->twist);
      localizer.feedTwist(twist->source, t);
    } else if (auto* pose = std::get_if<PoseInput>(&input)) {
      // A position without a heading (GNSS) can start the filter as a roadside fix does.
      const Matrix6d& c = pose->pose.covariance;
      if (!localizer.initialized() && std::isfinite(c(0, 0)) && std::isfinite(c(1, 1)) && !std::isfinite(c(5, 5)) &&
          pose->pose.pose.position.head<2>().allFinite() && c(0, 0) > 0.0 && c(1, 1) > 0.0) {
        initializer.addPosition(source_names[pose->source], pose->pose.stamp, pose->pose.pose.position.head<2>(), std::max(c(0, 0), c(1, 1)));
        tryStart();
      }
      feedPose(pose->source, pose->pose);
    } else if (auto* fix = std::get_if<FixInput>(&input)) {
      if (!checker) {
        report.fixes[fix->fix.rsu_id].received++;
        report.fixes[fix->fix.rsu_id].unknown_rsu++;
        return reject("fix from '" + fix->fix.rsu_id + "' stamped " + formatSeconds(fix->fix.stamp) +
                      " rejected (unknown_rsu): no RSU registry is configured");
      }
      rsu_client::FixVerdict v = checker->check(fix->fix, arrival);
      if (!v.accepted()) return reject(v.detail);
      // The CAM's rounding of this vehicle's size, and the mean error a calibration of the RSU by
      // range measured in the vehicle's frame, taken back where the heading is known.
      if (localizer.initialized())
        if (const rsu_client::RsuInfo* rsu = checker->registry().find(fix->fix.rsu_id);
            rsu && (cam_size.enabled() || !rsu->calibrated_error_by_range.empty())) {
          const double heading = rollPitchYaw(localizer.estimate()->pose.orientation)[2];
          if (cam_size.enabled())
            v.measurement.pose.position.head<2>() = cam_size.apply(v.measurement.pose.position.head<2>(), rsu->position, heading);
          v.measurement.pose.position.head<2>() -= checker->registry().meanErrorAt(*rsu, v.measurement.pose.position.head<2>(), heading);
        }
      const fusion::SourceId source = fix_sources.at(fix->fix.rsu_id);
      fix_agreement.addFix(v.measurement.stamp, v.measurement.pose.position.head<2>(), 0.5 * v.measurement.covariance.topLeftCorner<2, 2>().trace());
      initializer.addPosition(source_names[source], v.measurement.stamp, v.measurement.pose.position.head<2>(), v.measurement.covariance(0, 0));
      if (!localizer.initialized()) tryStart();
      releaseFollowedBias(v.measurement.stamp);
      const fusion::Verdict taken = feedPose(source, v.measurement);
      if (!taken.rejected()) last_anchor = std::max(last_anchor.value_or(v.measurement.stamp), v.measurement.stamp);
      if (taken.applied()) check_start = false;  // the roadside agrees: the start is confirmed
      if (lost()) tryRecover();
    } else {
      const PoseMeasurement& pose = std::get<InitialPoseInput>(input).pose;
      if (localizer.initialize(pose).applied()) {
        startedByHand("initial pose", pose.stamp);
        emit(*localizer.estimate());
      }
    }
    if (localizer.integrity().state != last_state) noteState();
  }

  void drain(Stamp now) {
    std::lock_guard<std::mutex> lock(state_mutex);
    if (clock_set && now + step < clock) clockWentBack(now);
    while (auto item = inbox.takeArrivedBy(now)) {
      auto& [arrival, input] = *item;
      if (!first_input_seen) {
        first_input_seen = true;
        if (config.pipeline.initial_pose && !localizer.initialized() &&
            localizer.initialize(initialPose(*config.pipeline.initial_pose, stampOf(input))).applied())
          startedByHand("pipeline.initial_pose", stampOf(input));
      }
      runTo(arrival);
      apply(input, arrival);
    }
    runTo(now);
  }

  void liveLoop() {
    std::unique_lock<std::mutex> lock(loop_mutex);
    while (!loop_stop) {
      lock.unlock();
      drain(now());
      lock.lock();
      loop_wake.wait_for(lock, std::chrono::nanoseconds(step), [&] { return loop_stop; });
    }
  }
};

Pipeline::Pipeline(const Config& config, PipelineOptions options) : impl_(std::make_unique<Impl>(config, options)) {}

Pipeline::~Pipeline() { stop(); }

fusion::SourceId Pipeline::addPoseSource(const std::string& name) {
  std::lock_guard<std::mutex> lock(impl_->state_mutex);
  return impl_->addSource(name, fusion::SourceKind::kPose);
}

fusion::SourceId Pipeline::addTwistSource(const std::string& name) {
  std::lock_guard<std::mutex> lock(impl_->state_mutex);
  return impl_->addSource(name, fusion::SourceKind::kTwist);
}

std::optional<fusion::SourceId> Pipeline::fixSource(const std::string& rsu_id) const {
  std::lock_guard<std::mutex> lock(impl_->state_mutex);
  const auto found = impl_->fix_sources.find(rsu_id);
  if (found == impl_->fix_sources.end()) return std::nullopt;
  return found->second;
}

void Pipeline::pushScan(ndt::PointCloud scan, Stamp stamp, Stamp arrival) {
  pushScan(std::make_shared<const ndt::PointCloud>(std::move(scan)), stamp, arrival);
}

void Pipeline::pushScan(std::shared_ptr<const ndt::PointCloud> scan, Stamp stamp, Stamp arrival) {
  if (!scan) scan = std::make_shared<const ndt::PointCloud>();  // nothing to match: counted as an empty scan
  {
    std::lock_guard<std::mutex> lock(impl_->last_scan_mutex);
    impl_->last_scan = scan;
    impl_->last_scan_stamp = stamp;
  }
  impl_->inbox.push(ScanInput{std::move(scan), stamp}, arrival);
}

AlignOutcome Pipeline::align(const Pose& around) {
  AlignOutcome out;
  if (!impl_->ndt) {
    out.why = "no map: NDT cannot align";
    return out;
  }
  std::shared_ptr<const ndt::PointCloud> scan;
  Stamp stamp = 0;
  {
    std::lock_guard<std::mutex> lock(impl_->last_scan_mutex);
    scan = impl_->last_scan;
    stamp = impl_->last_scan_stamp;
  }
  if (!scan || scan->empty()) {
    out.why = "no scan received yet";
    return out;
  }
  // A pose given by a person or a GNSS is off by metres and degrees; NDT converges from within about
  // a metre and 15 deg: the heading first, then the position around the best heading.
  std::lock_guard<std::mutex> using_ndt(impl_->ndt_use);
  const double yaw = rollPitchYaw(around.orientation)[2];
  ndt::ScanOutcome best;
  for (const double turn_deg : {0.0, 15.0, -15.0, 30.0, -30.0}) {
    Pose start = around;
    start.orientation = quaternionFromRollPitchYaw(0.0, 0.0, yaw + turn_deg * M_PI / 180.0);
    ndt::ScanOutcome at;
    impl_->ndt->searchAround(*scan, stamp, start, {}, 8, 0.0, at);
    ++out.starts;
    if (at.produced && (!best.produced || at.alignment.nvtl > best.alignment.nvtl)) best = at;
  }
  if (best.produced) {
    ndt::ScanOutcome at;
    const ndt::ScanOutcome ring = impl_->ndt->searchAround(*scan, stamp, best.pose.pose, {1.5, 3.0}, 8, 0.0, at);
    out.starts += 17;
    if (ring.produced && ring.alignment.nvtl > best.alignment.nvtl) best = ring;
  }
  if (!best.produced) {
    out.why = "NDT converged from none of the " + std::to_string(out.starts) + " starting poses";
    return out;
  }
  out.success = true;
  out.pose = best.pose;
  out.nvtl = best.alignment.nvtl;
  out.reliable = best.alignment.nvtl > impl_->config.ndt.source.ndt.nvtl_threshold;
  return out;
}
void Pipeline::pushTwist(fusion::SourceId source, const TwistMeasurement& twist, Stamp arrival) {
  impl_->inbox.push(TwistInput{source, twist}, arrival);
}
void Pipeline::pushPose(fusion::SourceId source, const PoseMeasurement& pose, Stamp arrival) {
  impl_->inbox.push(PoseInput{source, pose}, arrival);
}
void Pipeline::pushFix(const rsu_client::RsuFix& fix, Stamp arrival) { impl_->inbox.push(FixInput{fix}, arrival); }
void Pipeline::pushInitialPose(const PoseMeasurement& pose, Stamp arrival) { impl_->inbox.push(InitialPoseInput{pose}, arrival); }

void Pipeline::onEstimate(std::function<void(const fusion::Estimate&)> callback) {
  std::lock_guard<std::mutex> lock(impl_->state_mutex);
  impl_->on_estimate = std::move(callback);
}
void Pipeline::onPoseSettled(std::function<void(const std::string&, const fusion::Estimate&)> callback) {
  std::lock_guard<std::mutex> lock(impl_->state_mutex);
  impl_->on_pose_settled = std::move(callback);
}

void Pipeline::onPoseWeighed(std::function<void(const std::string&, const PoseMeasurement&)> callback) {
  impl_->on_pose_weighed = std::move(callback);
}

void Pipeline::onPoseInput(std::function<void(const std::string&, const PoseMeasurement&)> callback) {
  std::lock_guard<std::mutex> lock(impl_->state_mutex);
  impl_->on_pose_input = std::move(callback);
}
void Pipeline::onTwistInput(std::function<void(const std::string&, const TwistMeasurement&, const TwistMeasurement&)> callback) {
  std::lock_guard<std::mutex> lock(impl_->state_mutex);
  impl_->on_twist_input = std::move(callback);
}
void Pipeline::onRejection(std::function<void(const std::string&)> callback) {
  std::lock_guard<std::mutex> lock(impl_->state_mutex);
  impl_->on_rejection = std::move(callback);
}
void Pipeline::onEvent(std::function<void(const std::string&)> callback) {
  std::lock_guard<std::mutex> lock(impl_->state_mutex);
  impl_->on_event = std::move(callback);
}

void Pipeline::runUntil(Stamp now) { impl_->drain(now); }

void Pipeline::start() {
  if (impl_->loop.joinable()) return;
  impl_->loop_stop = false;
  impl_->loop = std::thread([this] { impl_->liveLoop(); });
}

void Pipeline::stop() {
  if (!impl_->loop.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(impl_->loop_mutex);
    impl_->loop_stop = true;
  }
  impl_->loop_wake.notify_all();
  impl_->loop.join();
  impl_->drain(impl_->now());  // what arrived before the stop still counts
}

PipelineReport Pipeline::report() const {
  std::lock_guard<std::mutex> lock(impl_->state_mutex);
  PipelineReport r = impl_->report;
  r.sources = impl_->localizer.sources();
  r.unknown_source_inputs = impl_->localizer.unknownSourceCount();
  if (impl_->ndt_thread) {
    r.ndt = impl_->ndt_thread->counters();
    r.map = impl_->ndt_thread->mapStats();
  } else if (impl_->ndt) {
    r.ndt = impl_->ndt->counters();
    r.map = impl_->ndt->map().stats();
  }
  if (impl_->checker)
    for (const auto& [id, c] : impl_->checker->counters()) r.fixes[id] = c;
  // What the filter made of the fixes that passed the checks.
  for (const auto& [id, source] : impl_->fix_sources)
    if (r.fixes.count(id)) r.filter_of_fixes[id] = impl_->localizer.counters(source);
  r.speed_scale = impl_->speed_scale.scale();
  r.speed_scale_distance = impl_->speed_scale.comparedDistance();
  r.yaw_rate_bias = impl_->yaw_rate_bias.bias();
  r.yaw_rate_bias_time = impl_->yaw_rate_bias.comparedTime();
  r.mount_yaw = impl_->mount_yaw.yaw();
  r.mount_yaw_distance = impl_->mount_yaw.comparedDistance();
  if (impl_->config.fusion.modelsOdometryErrors()) {
    std::lock_guard<std::mutex> lock(impl_->estimate_mutex);
    if (impl_->latest) {
      const fusion::Estimate& e = *impl_->latest;
      r.filter_odometry_modelled = true;
      r.filter_odometry_scale_error = e.odometry_scale_error;
      r.filter_odometry_scale_sd = std::sqrt(std::max(e.odometry_error_covariance(0, 0), 0.0));
      r.filter_yaw_rate_bias = e.odometry_yaw_rate_bias;
      r.filter_yaw_rate_bias_sd = std::sqrt(std::max(e.odometry_error_covariance(1, 1), 0.0));
    }
  }
  return r;
}

std::optional<fusion::Estimate> Pipeline::estimate() const {
  std::lock_guard<std::mutex> lock(impl_->estimate_mutex);
  return impl_->latest;
}

}  // namespace coloc::pipeline
