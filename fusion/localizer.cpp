#include "coloc/fusion/localizer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <unordered_map>

#include "coloc/core/error.hpp"
#include "coloc/core/chi_square.hpp"
#include "integrity_monitor.hpp"
#include "measurement_record.hpp"
#include "state_history.hpp"

namespace coloc::fusion {

namespace {

constexpr std::int64_t kMaxTicksPerAdvance = 10'000'000;  // ~55 h at 50 Hz: beyond that the clock jumped

void requireConfig(bool ok, const char* key, const std::string& why) {
  if (!ok) throw Error("fusion config: " + std::string(key) + " " + why);
}

void validate(const EkfConfig& c) {
  requireConfig(std::isfinite(c.predict_frequency) && c.predict_frequency > 0.0 && c.predict_frequency <= 10000.0,
                "predict_frequency", "must be in (0, 10000] Hz");
  requireConfig(c.history_steps >= 0 && c.history_steps <= 100000, "history_steps", "must be in [0, 100000]");
  requireConfig(c.pose_smoothing_steps >= 1, "pose_smoothing_steps", "must be >= 1");
  requireConfig(c.twist_smoothing_steps >= 1, "twist_smoothing_steps", "must be >= 1");
  requireConfig(c.max_pose_queue_size >= 1, "max_pose_queue_size", "must be >= 1");
  requireConfig(c.max_twist_queue_size >= 1, "max_twist_queue_size", "must be >= 1");
  requireConfig(c.pose_gate_alpha >= 0.0 && c.pose_gate_alpha < 1.0, "pose_gate_alpha", "must be in [0, 1)");
  requireConfig(c.pose_gate_recovery >= 0, "pose_gate_recovery", "must be >= 0");
  requireConfig(c.twist_gate_recovery >= 0, "twist_gate_recovery", "must be >= 0");
  requireConfig(c.twist_gate_alpha >= 0.0 && c.twist_gate_alpha < 1.0, "twist_gate_alpha", "must be in [0, 1)");
  requireConfig(c.integrity_lost_after_gated_anchors >= 0, "integrity_lost_after_gated_anchors", "must be >= 0");
  requireConfig(c.integrity_degraded_after_gated >= 0, "integrity_degraded_after_gated", "must be >= 0");
  requireConfig(c.integrity_anchor_window >= 0 && c.integrity_anchor_window <= 1000, "integrity_anchor_window", "must be in [0, 1000]");
  requireConfig(std::isfinite(c.integrity_anchor_mean_nis) && c.integrity_anchor_mean_nis > 0.0, "integrity_anchor_mean_nis", "must be finite and > 0");
  const std::pair<const char*, double> non_negative[] = {
      {"proc_stddev_yaw_c", c.proc_stddev_yaw_c},       {"proc_stddev_vx_c", c.proc_stddev_vx_c},
      {"proc_stddev_wz_c", c.proc_stddev_wz_c},         {"yaw_bias_walk", c.yaw_bias_walk},
      {"z_filter_proc_dev", c.z_filter_proc_dev},
      {"roll_filter_proc_dev", c.roll_filter_proc_dev}, {"pitch_filter_proc_dev", c.pitch_filter_proc_dev},
      {"threshold_observable_velocity_mps", c.threshold_observable_velocity_mps},
      {"future_tolerance", c.future_tolerance},         {"initial_yaw_bias_variance", c.initial_yaw_bias_variance},
      {"integrity_anchor_agreement", c.integrity_anchor_agreement},
      {"integrity_lost_min_distance", c.integrity_lost_min_distance},
      {"integrity_dead_reckoning_limit", c.integrity_dead_reckoning_limit},
      {"integrity_anchor_memory", c.integrity_anchor_memory},
      {"map_error_sd", c.map_error_sd},                 {"map_match_bias_sd", c.map_match_bias_sd},
      {"odometry_scale_sd", c.odometry_scale_sd},       {"odometry_scale_walk", c.odometry_scale_walk},
      {"odometry_yaw_rate_bias_sd", c.odometry_yaw_rate_bias_sd},
      {"odometry_yaw_rate_bias_walk", c.odometry_yaw_rate_bias_walk}};
  for (const auto& [key, value] : non_negative) requireConfig(std::isfinite(value) && value >= 0.0, key, "must be finite and >= 0");
  requireConfig(std::isfinite(c.map_match_bias_length) && c.map_match_bias_length > 0.0, "map_match_bias_length", "must be finite and > 0");
  requireConfig(c.odometry_scale_sd <= 0.5, "odometry_scale_sd", "must be at most 0.5 (a wheel half as large again)");
  requireConfig(c.odometry_yaw_rate_bias_sd <= 1.0, "odometry_yaw_rate_bias_sd", "must be at most 1 rad/s");
  requireConfig(std::isfinite(c.initial_vx_variance) && c.initial_vx_variance > 0.0, "initial_vx_variance", "must be finite and > 0");
  requireConfig(std::isfinite(c.initial_wz_variance) && c.initial_wz_variance > 0.0, "initial_wz_variance", "must be finite and > 0");
}

HistoryOptions historyOptions(const EkfConfig& c) {
  HistoryOptions o;
  o.steps = c.history_steps;
  o.step = static_cast<Duration>(std::llround(1e9 / c.predict_frequency));
  o.noise = {c.proc_stddev_yaw_c, c.proc_stddev_vx_c, c.proc_stddev_wz_c, c.enable_yaw_bias_estimation ? c.yaw_bias_walk : 0.0};
  o.aux_proc_dev = {c.z_filter_proc_dev, c.roll_filter_proc_dev, c.pitch_filter_proc_dev};
  o.relinearize = c.relinearize_on_replay;
  o.extra.bias_length = c.map_match_bias_length;
  o.extra.scale_walk = c.odometry_scale_walk;
  o.extra.gyro_bias_walk = c.odometry_yaw_rate_bias_walk;
  return o;
}

std::array<double, 4> gateThresholds(double alpha) {
  std::array<double, 4> t{};
  for (int m = 1; m <= 3; ++m) t[m] = alpha > 0.0 ? chiSquareQuantile(m, alpha) : kInfinity;
  return t;
}

// One sample's 95 % band per dimension: the chi-square's 2.5 % and 97.5 % quantiles.
std::array<std::pair<double, double>, 4> sampleNisBands() {
  std::array<std::pair<double, double>, 4> b{};
  for (int m = 1; m <= 3; ++m) b[m] = {chiSquareQuantile(m, 0.975), chiSquareQuantile(m, 0.025)};
  return b;
}

}  // namespace

struct Localizer::Impl {
  struct Source {
    std::string name;
    SourceKind kind;
    SourceCounters counters;
    int gated_in_a_row = 0;
    int smoothing_steps = 0;  ///< 0: the configuration's for the kind
    bool anchor = false;      ///< independent of the vehicle's map matching (see integrity.hpp)
    /// A twist source's newest yaw rate taken in, and its stamp (EkfConfig::yaw_rate_sampling_noise).
    std::optional<std::pair<Stamp, double>> last_yaw_rate;
  };
  // A measurement still being applied over its smoothing steps.
  struct Active {
    SourceId source;
    Stamp stamp;
    UpdateRecord record;
    int uses_left;
    int uses_total;
  };
  // A measurement whose tick the filter's clock has not reached yet.
  struct Pending {
    SourceId source;
    Stamp stamp;
    UpdateRecord record;
  };

  EkfConfig config;
  StateHistory history;
  std::array<double, 4> pose_gate, twist_gate;
  std::array<std::pair<double, double>, 4> nis_band = sampleNisBands();
  bool initialized = false;
  bool clock_set = false;
  Stamp clock = 0;
  Duration future_tolerance;
  std::vector<Source> sources;
  std::unordered_map<std::string, SourceId> by_name;
  std::vector<Active> active;
  std::vector<Pending> pending;
  std::uint64_t unknown_sources = 0;
  std::function<void(const Verdict&)> listener;
  IntegrityMonitor integrity;

  explicit Impl(const EkfConfig& c)
      : config((validate(c), c)),
        history(historyOptions(c)),
        pose_gate(gateThresholds(c.pose_gate_alpha)),
        twist_gate(gateThresholds(c.twist_gate_alpha)),
        future_tolerance(fromSeconds(c.future_tolerance)),
        integrity(c) {
    history.setBiasVariance(c.map_match_bias_sd * c.map_match_bias_sd);
  }

  SourceId add(const std::string& name, SourceKind kind, int smoothing_steps = 0, bool anchor = false) {
    if (smoothing_steps < 0) throw Error("source '" + name + "': smoothing_steps must be >= 1 (0: the configuration's), got " + std::to_string(smoothing_steps));
    if (auto it = by_name.find(name); it != by_name.end()) {
      if (sources[it->second].kind != kind)
        throw Error("source '" + name + "' is already registered as a " +
                    (kind == SourceKind::kPose ? "twist" : "pose") + " source");
      return it->second;
    }
    sources.emplace_back();
    sources.back().name = name;
    sources.back().kind = kind;
    sources.back().smoothing_steps = smoothing_steps;
    sources.back().anchor = anchor;
    by_name.emplace(name, static_cast<SourceId>(sources.size() - 1));
    return static_cast<SourceId>(sources.size() - 1);
  }

  Verdict report(Verdict v) {
    if (listener) listener(v);
    return v;
  }

  InputKind inputKind(SourceId id) const {
    return id >= 0 && sources[id].kind == SourceKind::kTwist ? InputKind::kTwist : InputKind::kPose;
  }

  Verdict reject(SourceId id, Stamp stamp, Reason reason, std::string why) {
    Verdict v{Outcome::kRejected, reason, inputKind(id), id >= 0 ? sources[id].name : std::string(), stamp, -1, 0.0,
              std::move(why)};
    if (id >= 0) {
      SourceCounters& c = sources[id].counters;
      switch (reason) {
        case Reason::kNotInitialized: ++c.not_initialized; break;
        case Reason::kInvalid: ++c.invalid; break;
        case Reason::kTooOld: ++c.too_old; break;
        case Reason::kFromFuture: ++c.from_future; break;
        case Reason::kGated: ++c.gated; break;
        case Reason::kNumerical: ++c.numerical; break;
        default: break;
      }
    }
    return report(std::move(v));
  }

  Verdict accept(SourceId id, Stamp stamp, Outcome outcome, int ticks_back, double d2, std::string note = {}) {
    return report(Verdict{outcome, Reason::kNone, inputKind(id), sources[id].name, stamp, ticks_back, d2, std::move(note)});
  }

  int smoothingSteps(const Source& s) const {
    if (s.smoothing_steps > 0) return s.smoothing_steps;
    return s.kind == SourceKind::kPose ? config.pose_smoothing_steps : config.twist_smoothing_steps;
  }
  int queueCapacity(const Source& s) const {
    const int queue = s.kind == SourceKind::kPose ? config.max_pose_queue_size : config.max_twist_queue_size;
    return std::max(queue, smoothingSteps(s));
  }

  // Applies the remaining smoothing uses of active[i] at once (same total information) and drops it.
  void fold(std::size_t i) {
    Active& a = active[i];
    if (auto back = history.ticksBack(a.stamp)) {
      UpdateRecord r = a.record;
      r.scale = static_cast<double>(a.uses_total) / a.uses_left;
      history.addUpdate(*back, r);
    }
    ++sources[a.source].counters.smoothing_shortened;
    active.erase(active.begin() + static_cast<std::ptrdiff_t>(i));
  }

  // First use of a measurement whose tick exists: gate it, then apply it (over its smoothing steps).
  Verdict firstUse(SourceId id, Stamp stamp, UpdateRecord record, int back) {
    Source& src = sources[id];
    // A pose taken between ticks is compared with the tick's state carried to its stamp; the offset is
    // fixed in the record, so every use and replay linearizes the same model at its own state.
    if (src.kind == SourceKind::kPose && config.pose_time_alignment) record.time_offset = toSeconds(stamp - history.stampAt(back));
    const NormalizedInnovation normalized = normalizedInnovation(history.stateAt(back), record);
    const double d2 = normalized.d2;
    if (record.m > 0 && std::isfinite(d2)) {
      SourceCounters& c = src.counters;
      ++c.nis_samples;
      c.nis_dof += static_cast<std::uint64_t>(record.m);
      c.nis_sum += d2;
      c.nis_above += d2 > nis_band[record.m].second ? 1 : 0;
      c.nis_below += d2 < nis_band[record.m].first ? 1 : 0;
      const std::array<double, kNisComponents>& parts = normalized.components;
      for (std::size_t k = 0; k < parts.size(); ++k) {
        if (!std::isfinite(parts[k]) || !std::isfinite(normalized.prediction_share[k])) continue;
        c.nis_component_sum[k] += parts[k];
        c.nis_prediction_share_sum[k] += normalized.prediction_share[k];
        ++c.nis_component_samples[k];
      }
    }
    const auto& gate = src.kind == SourceKind::kPose ? pose_gate : twist_gate;
    std::string note;
    if (record.m > 0 && !(d2 <= gate[record.m])) {
      std::ostringstream why;
      why << "squared Mahalanobis distance " << d2 << " exceeds the chi-square(" << record.m << ") gate "
          << gate[record.m];
      const int recovery = src.kind == SourceKind::kPose ? config.pose_gate_recovery : config.twist_gate_recovery;
      const bool recover = recovery > 0 && src.gated_in_a_row >= recovery && std::isfinite(d2);
      if (!recover) {
        ++src.gated_in_a_row;
        if (src.kind == SourceKind::kPose)
          integrity.onPose(src.name, src.anchor, false, planarInnovation(back, record), d2, src.gated_in_a_row, clock);
        Verdict v{Outcome::kRejected, Reason::kGated, inputKind(id), src.name, stamp, back, d2, why.str()};
        ++src.counters.gated;
        return report(std::move(v));
      }
      // Scale S = HPH' + R by k = d2 / gate through R alone, R' = (k - 1) HPH' + k R: the measurement
      // then sits exactly on the gate and moves the state 1/k of the way a trusted one would.
      const double k = d2 / gate[record.m];
      const Eigen::Matrix3d hph = innovation(history.stateAt(back), record, 1.0).S - record.R;
      record.R = (k - 1.0) * hph + k * record.R;
      ++src.counters.gate_recovered;
      why << "; applied at 1/" << k << " weight (gate recovery after " << src.gated_in_a_row << " gated in a row)";
      note = why.str();
    } else {
      src.gated_in_a_row = 0;
    }
    if (src.kind == SourceKind::kPose)
      integrity.onPose(src.name, src.anchor, true, src.anchor ? planarInnovation(back, record) : Eigen::Vector2d::Zero(), d2, 0, clock);
    const int steps = smoothingSteps(src);
    // The tick must stay in the history for all uses; fewer, heavier uses carry the same information.
    const int uses = std::max(1, std::min(steps, 1 + config.history_steps - back));
    record.scale = uses;
    if (!history.addUpdate(back, record))
      return reject(id, stamp, Reason::kNumerical, "innovation covariance is not positive definite");
    ++src.counters.applied;
    if (uses < steps) ++src.counters.smoothing_shortened;
    if (uses > 1) {
      int queued = 0;
      std::size_t oldest = active.size();
      for (std::size_t i = 0; i < active.size(); ++i)
        if (active[i].source == id && queued++ == 0) oldest = i;
      if (queued >= queueCapacity(src)) fold(oldest);
      active.push_back({id, stamp, record, uses - 1, uses});
    }
    return accept(id, stamp, Outcome::kApplied, back, d2, note);
  }

  // Measured minus predicted x and y at the tick (NaN for a component the record does not measure).
  Eigen::Vector2d planarInnovation(int back, const UpdateRecord& record) {
    Eigen::Vector2d out = Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
    const Innovation in = innovation(history.stateAt(back), record, 1.0);
    for (int i = 0; i < record.m; ++i) {
      if (record.index[i] == kX) out.x() = in.e[i];
      if (record.index[i] == kY) out.y() = in.e[i];
    }
    return out;
  }

  FilterState initialState(const UpdateRecord& r, const std::optional<TwistMeasurement>& moving) const {
    FilterState s;
    s.x.setZero();
    s.P = Matrix6d::Zero();
    for (int i = 0; i < r.m; ++i) {
      s.x[r.index[i]] = r.value[i];
      s.P(r.index[i], r.index[i]) = r.R(i, i);
    }
    s.x[kYaw] = wrapAngle(s.x[kYaw]);
    s.P(kYawBias, kYawBias) = config.enable_yaw_bias_estimation ? config.initial_yaw_bias_variance : 0.0;
    s.P(kVx, kVx) = config.initial_vx_variance;
    s.P(kWz, kWz) = config.initial_wz_variance;
    // A vehicle started while moving: its odometry says how fast, so the first ticks do not predict it
    // standing (a start from the roadside or a recovery happens at speed).
    if (moving) {
      const double var_vx = moving->covariance(0, 0), var_wz = moving->covariance(5, 5);
      if (std::isfinite(moving->linear.x()) && std::isfinite(var_vx) && var_vx > 0.0) s.x[kVx] = moving->linear.x(), s.P(kVx, kVx) = var_vx;
      if (std::isfinite(moving->angular.z()) && std::isfinite(var_wz) && var_wz > 0.0) s.x[kWz] = moving->angular.z(), s.P(kWz, kWz) = var_wz;
    }
    for (int a = 0; a < 3; ++a)
      if (r.aux_mask & (1 << a)) s.aux[a] = {r.aux_value[a], r.aux_variance[a], true};
    if (config.map_match_bias_sd > 0.0) {
      // The bias is unknown but for its spread at this place; a start from a biased pose (NDT's) knows
      // the position only as well as the pose and the bias together, and knows their sum exactly as
      // well as the pose: x = z - b, so x and b start anti-correlated.
      const double variance = history.biasVariance();
      s.extra.bias_modelled = true;
      s.extra.P.topLeftCorner<2, 2>() = Eigen::Matrix2d::Identity() * variance;
      for (int i = 0; i < r.m && r.biased; ++i) {
        const int si = r.index[i];
        if (si != kX && si != kY) continue;
        const int bi = si == kX ? ExtraStates::kBiasX : ExtraStates::kBiasY;
        s.x[si] -= s.extra.v[bi];
        s.P(si, si) += variance;
        s.extra.cross(si, bi) = -variance;
      }
    }
    if (config.modelsOdometryErrors()) {
      // The odometry's errors start unknown but for their spread: what a start learned is not kept
      // (a recovery starts afresh, as the pipeline's own learners do).
      s.extra.odometry_modelled = true;
      s.extra.P(ExtraStates::kScale, ExtraStates::kScale) = config.odometry_scale_sd * config.odometry_scale_sd;
      s.extra.P(ExtraStates::kGyroBias, ExtraStates::kGyroBias) = config.odometry_yaw_rate_bias_sd * config.odometry_yaw_rate_bias_sd;
    }
    return s;
  }

  void start(Stamp stamp, const UpdateRecord& record, const std::optional<TwistMeasurement>& moving = std::nullopt) {
    history.reset(stamp, initialState(record, moving));
    active.clear();  // their information went into the history just discarded
    initialized = true;
    if (!clock_set || clock < stamp) clock = stamp;
    clock_set = true;
    for (Source& s : sources) s.gated_in_a_row = 0;  // a run of gated poses was against the old start
    integrity.restart(stamp, true);
    // A start at a stamp the clock has passed (a scan matched after it arrived) is predicted up to the
    // clock, so that the estimate is always at the newest tick.
    while (history.latestStamp() + history.options().step <= clock) history.advance();
    // Waiting measurements older than the new start can never find their tick.
    std::vector<Pending> waiting;
    waiting.swap(pending);
    for (Pending& p : waiting) {
      if (p.stamp < stamp - history.options().step / 2) {
        --sources[p.source].counters.pending;
        reject(p.source, p.stamp, Reason::kTooOld, "older than the filter's new initial pose");
      } else {
        pending.push_back(std::move(p));
      }
    }
  }

  // The heading's error from a yaw rate that changed since the source's previous twist at a moment
  // between the two (uniform): (change x interval)^2 / 12. A twist older than the newest taken adds
  // nothing; it is within an interval already counted.
  static double samplingVariance(Source& src, Stamp stamp, const UpdateRecord& record) {
    for (int i = 0; i < record.m; ++i) {
      if (record.index[i] != kWz) continue;
      if (src.last_yaw_rate && stamp <= src.last_yaw_rate->first) return 0.0;
      const double wz = record.value[i];
      double added = 0.0;
      if (src.last_yaw_rate) {
        const double turned = (wz - src.last_yaw_rate->second) * toSeconds(stamp - src.last_yaw_rate->first);
        added = turned * turned / 12.0;
      }
      src.last_yaw_rate = std::make_pair(stamp, wz);
      return added;
    }
    return 0.0;
  }

  Verdict feed(SourceId id, SourceKind kind, Stamp stamp, const RecordOrError& made) {
    if (id < 0 || static_cast<std::size_t>(id) >= sources.size()) {
      ++unknown_sources;
      return report(Verdict{Outcome::kRejected, Reason::kUnknownSource,
                            kind == SourceKind::kTwist ? InputKind::kTwist : InputKind::kPose, "#" + std::to_string(id),
                            stamp, -1, 0.0, "no source with this id or name was registered"});
    }
    Source& src = sources[id];
    if (src.kind != kind)
      throw Error("source '" + src.name + "' is a " + (src.kind == SourceKind::kPose ? "pose" : "twist") +
                  " source; it cannot take a " + (kind == SourceKind::kPose ? "pose" : "twist"));
    ++src.counters.received;
    if (const auto* why = std::get_if<std::string>(&made)) return reject(id, stamp, Reason::kInvalid, *why);
    UpdateRecord record = std::get<UpdateRecord>(made);
    record.biased = kind == SourceKind::kPose && !src.anchor;  // map matching; an anchor is independent of it
    if (!initialized) {
      const Duration history_span = static_cast<Duration>(config.history_steps) * history.options().step;
      if (clock_set && stamp < clock - history_span - history.options().step / 2)
        return reject(id, stamp, Reason::kTooOld,
                      "stamp is " + formatSeconds(clock - stamp) + " s behind the clock: too old to start the filter from");
      if (kind == SourceKind::kPose && config.auto_initialize && measuresPlanarPose(record)) {
        start(stamp, record);
        ++src.counters.applied;
        return accept(id, stamp, Outcome::kApplied, 0, 0.0, "initialised the filter");
      }
      return reject(id, stamp, Reason::kNotInitialized, "no initial pose yet");
    }
    if (stamp > clock + future_tolerance)
      return reject(id, stamp, Reason::kFromFuture,
                    "stamp is " + formatSeconds(stamp - clock) + " s ahead of the clock (tolerance " +
                        formatSeconds(future_tolerance) + " s)");
    const std::optional<int> back = history.ticksBack(stamp);
    if (!back && stamp < history.latestStamp()) {
      return reject(id, stamp, Reason::kTooOld,
                    "stamp is " + formatSeconds(history.latestStamp() - stamp) + " s behind the newest tick; the history reaches back " +
                        formatSeconds(history.latestStamp() - history.oldestStamp()) + " s");
    }
    if (kind == SourceKind::kTwist && config.yaw_rate_sampling_noise) record.yaw_variance_added = samplingVariance(src, stamp, record);
    if (back) return firstUse(id, stamp, record, *back);
    pending.push_back({id, stamp, record});
    ++src.counters.pending;
    return accept(id, stamp, Outcome::kPending, -1, 0.0, "waits for the filter's clock to reach its stamp");
  }

  void tick() {
    history.advance();
    // Continuing smoothing uses first: they were accepted before anything that resolves now.
    for (std::size_t i = 0; i < active.size();) {
      Active& a = active[i];
      const auto back = history.ticksBack(a.stamp);
      UpdateRecord r = a.record;
      r.scale = a.uses_total;
      if (back) history.addUpdate(*back, r);
      if (--a.uses_left == 0 || !back) {
        active.erase(active.begin() + static_cast<std::ptrdiff_t>(i));
      } else {
        ++i;
      }
    }
    // Measurements that waited for this tick, in stamp order (stable for equal stamps).
    std::stable_sort(pending.begin(), pending.end(), [](const Pending& a, const Pending& b) { return a.stamp < b.stamp; });
    std::size_t resolved = 0;
    while (resolved < pending.size()) {
      const auto back = history.ticksBack(pending[resolved].stamp);
      if (!back) break;
      ++resolved;
    }
    std::vector<Pending> ready(pending.begin(), pending.begin() + static_cast<std::ptrdiff_t>(resolved));
    pending.erase(pending.begin(), pending.begin() + static_cast<std::ptrdiff_t>(resolved));
    for (Pending& p : ready) {
      --sources[p.source].counters.pending;
      firstUse(p.source, p.stamp, p.record, *history.ticksBack(p.stamp));
    }
  }

  Verdict advanceTo(Stamp now) {
    if (clock_set && now < clock)
      return report(Verdict{Outcome::kRejected, Reason::kClockBackwards, InputKind::kClock, "", now, -1, 0.0,
                            "before the previous time " + formatSeconds(clock)});
    if (initialized) {
      const std::int64_t ticks = (now - history.latestStamp()) / history.options().step;
      if (ticks > kMaxTicksPerAdvance)
        return report(Verdict{Outcome::kRejected, Reason::kClockJump, InputKind::kClock, "", now, -1, 0.0,
                              "a jump of " + formatSeconds(now - history.latestStamp()) +
                                  " s would need more than 10 million prediction ticks; initialise the filter again"});
    }
    clock = now;
    clock_set = true;
    if (initialized) {
      while (history.latestStamp() + history.options().step <= now) tick();
      integrity.onTick(history.latestStamp());
    }
    return Verdict{Outcome::kApplied, Reason::kNone, InputKind::kClock, "", now, -1, 0.0, {}};
  }

  Estimate estimate() { return describe(history.latest(), history.latestStamp()); }

  // The state at a past tick, or predicted ahead (without changing the filter) for a later stamp.
  std::optional<Estimate> estimateAt(Stamp stamp) {
    if (const auto back = history.ticksBack(stamp)) return describe(history.stateAt(*back), history.stampAt(*back));
    if (stamp < history.latestStamp()) return std::nullopt;  // older than the history
    FilterState s = history.latest();
    const double dt = toSeconds(stamp - history.latestStamp());
    Matrix6d A;
    const double vx = s.x[kVx];
    s.x = predictState(s.x, dt, A);
    s.P = propagateCovariance(A, s.P, processNoise(history.options().noise, dt));
    if (s.extra.any()) propagateExtra(s.extra, A, vx, dt, history.options().extra);
    predictAux(s, history.options().aux_proc_dev, dt);
    return describe(s, stamp);
  }

  Estimate describe(const FilterState& s, Stamp stamp) const {
    const double map_error_variance = config.map_error_sd * config.map_error_sd;
    Estimate e;
    e.stamp = stamp;
    e.state = s.x;
    e.state_covariance = s.P;
    e.yaw_bias = s.x[kYawBias];
    if (s.extra.bias_modelled) e.map_match_bias = s.extra.bias(), e.map_match_bias_covariance = s.extra.biasCovariance();
    if (s.extra.odometry_modelled) {
      e.odometry_scale_error = s.extra.v[ExtraStates::kScale];
      e.odometry_yaw_rate_bias = s.extra.v[ExtraStates::kGyroBias];
      e.odometry_error_covariance = s.extra.P.bottomRightCorner<2, 2>();
    }
    const double z = s.aux[kAuxZ].initialized ? s.aux[kAuxZ].value : 0.0;
    const double roll = s.aux[kAuxRoll].initialized ? s.aux[kAuxRoll].value : 0.0;
    const double pitch = s.aux[kAuxPitch].initialized ? s.aux[kAuxPitch].value : 0.0;
    e.pose.position = {s.x[kX], s.x[kY], z};
    e.pose.orientation = quaternionFromRollPitchYaw(roll, pitch, wrapAngle(s.x[kYaw] + s.x[kYawBias]));
    const int rows[3] = {0, 1, 5};
    const int states[3] = {kX, kY, kYaw};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) e.pose_covariance(rows[i], rows[j]) = s.P(states[i], states[j]);
    for (int a = 0; a < 3; ++a) e.pose_covariance(2 + a, 2 + a) = s.aux[a].variance;  // +inf until measured
    e.localization = integrity.status().state;
    if (e.localization == LocalizationState::kDegraded || e.localization == LocalizationState::kLost)
      e.pose_covariance.topLeftCorner<2, 2>() += integrity.inflation();
    e.pose_covariance.topLeftCorner<2, 2>().diagonal().array() += map_error_variance;
    e.linear_velocity = {s.x[kVx], 0.0, 0.0};
    e.angular_velocity = {0.0, 0.0, s.x[kWz]};
    for (int i = 1; i < 5; ++i) e.twist_covariance(i, i) = kInfinity;  // vy, vz, wx, wy are not estimated
    e.twist_covariance(0, 0) = s.P(kVx, kVx);
    e.twist_covariance(0, 5) = e.twist_covariance(5, 0) = s.P(kVx, kWz);
    e.twist_covariance(5, 5) = s.P(kWz, kWz);
    return e;
  }
};

Localizer::Localizer(const EkfConfig& config) : impl_(std::make_unique<Impl>(config)) {}
Localizer::~Localizer() = default;
Localizer::Localizer(Localizer&&) noexcept = default;
Localizer& Localizer::operator=(Localizer&&) noexcept = default;

SourceId Localizer::addPoseSource(const std::string& name, int smoothing_steps, bool anchor) {
  return impl_->add(name, SourceKind::kPose, smoothing_steps, anchor);
}
SourceId Localizer::addTwistSource(const std::string& name) { return impl_->add(name, SourceKind::kTwist); }

std::optional<SourceId> Localizer::findSource(std::string_view name) const {
  auto it = impl_->by_name.find(std::string(name));
  if (it == impl_->by_name.end()) return std::nullopt;
  return it->second;
}

Verdict Localizer::initialize(const PoseMeasurement& pose, const std::optional<TwistMeasurement>& moving) {
  const RecordOrError made = makePoseRecord(pose);
  Verdict v{Outcome::kRejected, Reason::kInvalid, InputKind::kInitialPose, "", pose.stamp, -1, 0.0, {}};
  if (const auto* why = std::get_if<std::string>(&made)) {
    v.detail = *why;
  } else if (!measuresPlanarPose(std::get<UpdateRecord>(made))) {
    v.detail = "x, y and yaw must all have finite variance";
  } else {
    impl_->start(pose.stamp, std::get<UpdateRecord>(made), moving);
    v = {Outcome::kApplied, Reason::kNone, InputKind::kInitialPose, "", pose.stamp, 0, 0.0, "filter initialised"};
  }
  return impl_->report(std::move(v));
}

bool Localizer::initialized() const { return impl_->initialized; }

void Localizer::reset() {
  Impl& d = *impl_;
  for (const Impl::Pending& p : d.pending) --d.sources[p.source].counters.pending;
  d.pending.clear();
  d.active.clear();
  d.initialized = false;
  d.clock_set = false;
  d.clock = 0;
  for (Impl::Source& s : d.sources) s.gated_in_a_row = 0, s.last_yaw_rate.reset();
  d.integrity.restart(0, false);
}

void Localizer::setMapMatchBiasVariance(double variance) {
  if (!(std::isfinite(variance) && variance >= 0.0 && variance <= 1e6))
    throw Error("map-matching bias variance: must be finite and in [0, 1e6] m^2, got " + std::to_string(variance));
  if (impl_->config.map_match_bias_sd > 0.0) impl_->history.setBiasVariance(variance);
}

void Localizer::releaseMapMatchBias(Stamp stamp, double variance) {
  if (!(std::isfinite(variance) && variance >= 0.0 && variance <= 1e6))
    throw Error("map-matching bias release: must be finite and in [0, 1e6] m^2, got " + std::to_string(variance));
  if (!(impl_->config.map_match_bias_sd > 0.0 && impl_->initialized)) return;
  impl_->history.releaseBias(impl_->history.ticksBack(stamp).value_or(0), variance * Eigen::Matrix2d::Identity());
}

const IntegrityStatus& Localizer::integrity() const { return impl_->integrity.status(); }

void Localizer::doubt(const std::string& reason, const Eigen::Vector2d& offset) {
  if (impl_->initialized) impl_->integrity.doubt(reason, offset, impl_->history.latestStamp());
}

void Localizer::doubt(const std::string& reason, const Eigen::Matrix2d& spread) {
  if (impl_->initialized) impl_->integrity.doubt(reason, spread, impl_->history.latestStamp());
}

void Localizer::confirm() {
  if (impl_->initialized) impl_->integrity.confirm(impl_->history.latestStamp());
}

Verdict Localizer::feedPose(SourceId source, const PoseMeasurement& m) {
  return impl_->feed(source, SourceKind::kPose, m.stamp, makePoseRecord(m));
}

Verdict Localizer::feedTwist(SourceId source, const TwistMeasurement& m) {
  return impl_->feed(source, SourceKind::kTwist, m.stamp,
                     makeTwistRecord(m, impl_->config.threshold_observable_velocity_mps));
}

Verdict Localizer::feedPose(std::string_view source, const PoseMeasurement& m) {
  return feedPose(findSource(source).value_or(-1), m);
}

Verdict Localizer::feedTwist(std::string_view source, const TwistMeasurement& m) {
  return feedTwist(findSource(source).value_or(-1), m);
}

Verdict Localizer::advanceTo(Stamp now) { return impl_->advanceTo(now); }

std::optional<Estimate> Localizer::estimate() {
  if (!impl_->initialized) return std::nullopt;
  return impl_->estimate();
}

Pose measuredPose(const Estimate& estimate) {
  Pose pose = estimate.pose;
  const Eigen::Vector3d rpy = rollPitchYaw(pose.orientation);
  pose.orientation = quaternionFromRollPitchYaw(rpy[0], rpy[1], wrapAngle(rpy[2] - estimate.yaw_bias));
  return pose;
}

std::optional<Estimate> Localizer::estimateAt(Stamp stamp) {
  if (!impl_->initialized) return std::nullopt;
  return impl_->estimateAt(stamp);
}

void Localizer::setVerdictListener(std::function<void(const Verdict&)> listener) { impl_->listener = std::move(listener); }

std::vector<SourceReport> Localizer::sources() const {
  std::vector<SourceReport> out;
  for (const auto& s : impl_->sources) out.push_back({s.name, s.kind, s.counters});
  return out;
}

const SourceCounters& Localizer::counters(SourceId source) const { return impl_->sources.at(source).counters; }
const EkfConfig& Localizer::config() const { return impl_->config; }
std::uint64_t Localizer::unknownSourceCount() const { return impl_->unknown_sources; }

}  // namespace coloc::fusion
