#include "log_replay.hpp"

#include <algorithm>
#include <chrono>
#include <memory>
#include <cmath>
#include <set>
#include <variant>

#include "coloc/core/error.hpp"
#include "coloc/io/bag_reader.hpp"
#include "coloc/io/ros_messages.hpp"
#include "point_cloud2_convert.hpp"

namespace coloc::tools {

namespace {

using io::MessageKind;

// A measurement waiting to be replayed.
struct Event {
  Stamp log_time;
  Stamp stamp;
  Stamp arrival;  ///< log_time on the stamp clock
  std::uint64_t order;
  std::size_t topic;
  std::variant<PoseMeasurement, TwistMeasurement, ndt::PointCloud> measurement;
};

bool canServe(InputRole role, MessageKind kind) {
  switch (role) {
    case InputRole::kScan:
      return kind == MessageKind::kPointCloud2;
    case InputRole::kPose:
    case InputRole::kGroundTruth:
      return kind == MessageKind::kPoseWithCovarianceStamped || kind == MessageKind::kPoseStamped ||
             kind == MessageKind::kOdometry;
    case InputRole::kTwist:
      return kind == MessageKind::kTwistWithCovarianceStamped || kind == MessageKind::kTwistStamped ||
             kind == MessageKind::kOdometry || kind == MessageKind::kImu;
    case InputRole::kIgnore:
      return true;
  }
  return false;
}

// The role a topic gets when the config does not name it.
InputRole defaultRole(const std::string& topic, MessageKind kind, bool have_map, std::string& note) {
  const bool truth_name = topic.find("ground_truth") != std::string::npos || topic.find("groundtruth") != std::string::npos;
  switch (kind) {
    case MessageKind::kPoseWithCovarianceStamped: return truth_name ? InputRole::kGroundTruth : InputRole::kPose;
    case MessageKind::kOdometry: return truth_name ? InputRole::kGroundTruth : InputRole::kTwist;
    case MessageKind::kTwistWithCovarianceStamped:
    case MessageKind::kImu: return InputRole::kTwist;
    case MessageKind::kPoseStamped:
      if (truth_name) return InputRole::kGroundTruth;
      note = "PoseStamped carries no covariance: give it a role in the config to use it";
      return InputRole::kIgnore;
    case MessageKind::kTwistStamped:
      note = "TwistStamped carries no covariance: give it a role in the config to use it";
      return InputRole::kIgnore;
    case MessageKind::kPointCloud2:
      if (have_map) return InputRole::kScan;
      note = "point clouds feed NDT, which needs a map (--map)";
      return InputRole::kIgnore;
  }
  return InputRole::kIgnore;
}

// Completes a message's covariance as the config says: an override, a fallback when the message
// carries none, and zeros read as "not measured".
Matrix6d completeCovariance(Matrix6d C, const Vector6d& fallback, const InputConfig* input, const ReplayConfig& replay,
                            bool& used_fallback) {
  used_fallback = false;
  if (input && input->covariance_diagonal) return Matrix6d(input->covariance_diagonal->asDiagonal());
  const auto diagonal = C.diagonal();
  const bool none = (diagonal.array() == 0.0).all() || (diagonal.array() == kInfinity).all();
  if (none) {
    used_fallback = true;
    return Matrix6d(fallback.asDiagonal());
  }
  if (replay.zero_variance_is_unmeasured) {
    for (int i = 0; i < 6; ++i) {
      if (C(i, i) != 0.0) continue;
      C.row(i).setZero();
      C.col(i).setZero();
      C(i, i) = kInfinity;
    }
  }
  return C;
}

TwistMeasurement twistFromImu(const io::Imu& imu) {
  TwistMeasurement t;
  t.stamp = imu.header.stamp;
  t.angular = imu.angular_velocity;
  t.covariance = Matrix6d::Zero();
  t.covariance.diagonal().head<3>().setConstant(kInfinity);  // an IMU does not measure velocity
  t.covariance.bottomRightCorner<3, 3>() = imu.angular_velocity_covariance;
  if (imu.angular_velocity_covariance(0, 0) == -1.0) t.covariance.bottomRightCorner<3, 3>().diagonal().setConstant(kInfinity);
  return t;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// Linear interpolation of the planar ground truth at `t`, if samples bracket it closely enough.
std::optional<Eigen::Vector2d> truthAt(const std::vector<io::TrajectoryPoint>& truth, Stamp t, Duration max_gap) {
  auto after = std::lower_bound(truth.begin(), truth.end(), t, [](const io::TrajectoryPoint& p, Stamp s) { return p.stamp < s; });
  if (after == truth.end()) return std::nullopt;
  if (after->stamp == t) return after->pose.position.head<2>();
  if (after == truth.begin()) return std::nullopt;
  const auto before = after - 1;
  if (after->stamp - before->stamp > max_gap) return std::nullopt;
  const double w = static_cast<double>(t - before->stamp) / static_cast<double>(after->stamp - before->stamp);
  return ((1.0 - w) * before->pose.position.head<2>() + w * after->pose.position.head<2>()).eval();
}

ndt::NdtPoseSourceConfig ndtSourceConfig(const FuseConfig& config) {
  ndt::NdtPoseSourceConfig c = config.ndt.source;
  c.map.background = false;  // offline: the same log gives the same bytes, whatever the machine's speed
  return c;
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

}  // namespace

ReplayResult replayLog(const std::string& log_path, const ReplayOptions& options) {
  const auto wall_start = std::chrono::steady_clock::now();
  const FuseConfig& config = options.config;
  io::BagReader bag = io::BagReader::open(log_path);
  ReplayResult result;

  // 1. Decide what each topic is for.
  std::map<std::string, std::size_t> topic_index;
  std::vector<std::optional<MessageKind>> kinds;
  for (const io::TopicInfo& t : bag.topics()) {
    TopicUse use;
    use.topic = t.name;
    use.type = t.type;
    const std::optional<MessageKind> kind = io::messageKindOf(t.type);
    const auto configured = config.inputs.find(t.name);
    if (configured != config.inputs.end()) {
      use.role = configured->second.role;
      use.source = configured->second.source;
      use.from_config = true;
      if (use.role != InputRole::kIgnore && (!kind || !canServe(use.role, *kind)))
        throw Error("config: inputs." + t.name + ".role: a " + (t.type.empty() ? std::string("message of unknown type") : t.type) +
                    " cannot serve as " + toString(use.role));
    } else if (!kind) {
      use.note = "type not decoded by coloc";
    } else {
      use.role = defaultRole(t.name, *kind, !options.map.empty(), use.note);
      use.source = use.role == InputRole::kScan ? "ndt" : t.name;
    }
    if (use.role != InputRole::kIgnore && t.serialization_format != "cdr") {
      use.note = "serialization format '" + t.serialization_format + "' is not CDR";
      use.role = InputRole::kIgnore;
    }
    topic_index[t.name] = result.topics.size();
    result.topics.push_back(use);
    kinds.push_back(kind);
  }
  for (const auto& [topic, input] : config.inputs)
    if (!topic_index.count(topic)) result.rejections.push_back("config names topic " + topic + ", which the log does not have");

  // 2. Decode every message of a used topic.
  std::vector<Event> events;
  const std::uint64_t total = std::max<std::uint64_t>(bag.messageCount(), 1);
  io::BagMessage message;
  Stamp first_log = 0, last_log = 0;
  std::vector<std::vector<double>> delays(result.topics.size());
  while (bag.next(message)) {
    if (result.messages_read == 0) first_log = message.log_time;
    last_log = message.log_time;
    if (options.progress && result.messages_read % 256 == 0) options.progress(0.5 * result.messages_read / total);
    ++result.messages_read;
    const auto found = topic_index.find(message.topic);
    if (found == topic_index.end()) continue;
    const std::size_t ti = found->second;
    TopicUse& use = result.topics[ti];
    ++use.messages;
    if (use.role == InputRole::kIgnore) continue;
    const InputConfig* input = use.from_config ? &config.inputs.at(use.topic) : nullptr;
    try {
      const io::RosMessage decoded = io::decodeMessage(*kinds[ti], message.data);
      bool fallback = false;
      std::variant<PoseMeasurement, TwistMeasurement, ndt::PointCloud> m;
      if (use.role == InputRole::kScan) {
        if (options.map.empty()) throw Error("a scan topic needs a map (--map)");
        const io::PointCloud2& cloud = std::get<io::PointCloud2>(decoded);
        events.push_back({message.log_time, cloud.header.stamp, 0, message.index, ti, toPointCloud(cloud)});
        continue;
      }
      if (use.role == InputRole::kTwist) {
        TwistMeasurement t;
        if (const auto* odom = std::get_if<io::Odometry>(&decoded)) t = odom->twist;
        else if (const auto* st = std::get_if<io::StampedTwist>(&decoded)) t = st->measurement;
        else t = twistFromImu(std::get<io::Imu>(decoded));
        t.covariance = completeCovariance(t.covariance, config.replay.fallback_twist_variance, input, config.replay, fallback);
        m = t;
      } else {
        PoseMeasurement p = std::holds_alternative<io::Odometry>(decoded) ? std::get<io::Odometry>(decoded).pose
                                                                          : std::get<io::StampedPose>(decoded).measurement;
        if (use.role == InputRole::kGroundTruth) {
          result.ground_truth.push_back({p.stamp, p.pose});
          continue;
        }
        p.covariance = completeCovariance(p.covariance, config.replay.fallback_pose_variance, input, config.replay, fallback);
        m = p;
      }
      if (fallback) ++use.fallback_covariance;
      Stamp stamp = std::holds_alternative<PoseMeasurement>(m) ? std::get<PoseMeasurement>(m).stamp : std::get<TwistMeasurement>(m).stamp;
      if (input && input->additional_delay > 0.0) {
        stamp -= fromSeconds(input->additional_delay);
        if (auto* pose = std::get_if<PoseMeasurement>(&m)) pose->stamp = stamp;
        if (auto* twist = std::get_if<TwistMeasurement>(&m)) twist->stamp = stamp;
      }
      events.push_back({message.log_time, stamp, 0, message.index, ti, std::move(m)});
    } catch (const Error& e) {
      if (use.decode_errors++ == 0)
        use.first_error = "topic " + use.topic + " message #" + std::to_string(message.index) + ": " + e.what();
    }
  }
  result.log_duration = toSeconds(last_log - first_log);

  // 3. One clock: arrival times on the stamp clock.
  Duration min_offset = std::numeric_limits<Duration>::max();
  for (const Event& e : events) min_offset = std::min(min_offset, e.log_time - e.stamp);
  const Duration tolerance = fromSeconds(config.fusion.future_tolerance);
  result.clock = config.replay.clock;
  if (result.clock == ClockMode::kAuto)
    result.clock = events.empty() || (min_offset >= -tolerance && min_offset <= 10 * kNanosPerSecond) ? ClockMode::kSame
                                                                                                       : ClockMode::kSeparate;
  if (result.clock == ClockMode::kSeparate && !events.empty()) {
    std::vector<ClockSample> samples;
    samples.reserve(events.size());
    for (const Event& e : events) samples.push_back({e.log_time, e.stamp});
    result.clock_fit = fitClock(samples);
  }
  for (Event& e : events)
    e.arrival = result.clock == ClockMode::kSeparate ? std::max(result.clock_fit.toStampClock(e.log_time), e.stamp) : e.log_time;
  // Topics replayed through an emulated link: each message, in recorded order, is delayed or lost.
  std::map<std::size_t, rsu_client::LinkEmulator> links;
  for (std::size_t i = 0; i < result.topics.size(); ++i)
    if (result.topics[i].from_config && config.inputs.at(result.topics[i].topic).link)
      links.emplace(i, rsu_client::LinkEmulator(*config.inputs.at(result.topics[i].topic).link));
  if (!links.empty()) {
    std::vector<Event> kept;
    kept.reserve(events.size());
    for (Event& e : events) {
      const auto link = links.find(e.topic);
      if (link != links.end()) {
        const std::optional<Stamp> delivered = link->second.transmit(e.arrival);
        if (!delivered) {
          ++result.topics[e.topic].link_dropped;
          continue;
        }
        e.arrival = *delivered;
      }
      kept.push_back(std::move(e));
    }
    events = std::move(kept);
  }
  for (const Event& e : events) delays[e.topic].push_back(toSeconds(e.arrival - e.stamp));
  for (std::size_t i = 0; i < delays.size(); ++i) {
    if (delays[i].empty()) continue;
    result.topics[i].delay_median = median(delays[i]);
    result.topics[i].delay_max = *std::max_element(delays[i].begin(), delays[i].end());
  }
  std::sort(events.begin(), events.end(), [&](const Event& a, const Event& b) {
    return a.arrival != b.arrival ? a.arrival < b.arrival : a.order < b.order;
  });

  // 4. Replay through the filter, recording the estimate at every tick.
  fusion::Localizer localizer(config.fusion);
  std::vector<fusion::SourceId> source_of(result.topics.size(), -1);
  std::unique_ptr<ndt::NdtPoseSource> ndt_source;
  for (std::size_t i = 0; i < result.topics.size(); ++i) {
    if (result.topics[i].role == InputRole::kScan && !ndt_source) {
      ndt_source = std::make_unique<ndt::NdtPoseSource>(ndt::TileMap::open(options.map, config.ndt.map_tile_size), ndtSourceConfig(config));
      result.ndt_used = true;
    }
    if (result.topics[i].role == InputRole::kPose || result.topics[i].role == InputRole::kScan)
      source_of[i] = localizer.addPoseSource(result.topics[i].source);
    if (result.topics[i].role == InputRole::kTwist) source_of[i] = localizer.addTwistSource(result.topics[i].source);
  }
  localizer.setVerdictListener([&](const fusion::Verdict& v) {
    if (v.rejected() && result.rejections.size() < 20) result.rejections.push_back(v.message());
  });
  const Duration step = static_cast<Duration>(std::llround(1e9 / config.fusion.predict_frequency));
  auto runTo = [&](Stamp now) {
    if (localizer.initialized()) {
      Stamp latest = localizer.estimate()->stamp;
      if ((now - latest) / step < 1'000'000) {
        for (Stamp tick = latest + step; tick <= now; tick += step) {
          localizer.advanceTo(tick);
          const fusion::Estimate e = *localizer.estimate();
          result.fused.push_back({e.stamp, e.pose});
        }
      }
    }
    localizer.advanceTo(now);
  };
  for (std::size_t i = 0; i < events.size(); ++i) {
    const Event& e = events[i];
    if (options.progress && (i % 256 == 0 || std::holds_alternative<ndt::PointCloud>(e.measurement)))
      options.progress(0.5 + 0.5 * i / events.size());
    if (i == 0 && config.replay.initial_pose) localizer.initialize(initialPose(*config.replay.initial_pose, e.stamp));
    runTo(e.arrival);
    if (const auto* scan = std::get_if<ndt::PointCloud>(&e.measurement)) {
      // NDT starts from the filter's prediction for the scan's stamp, and its pose goes back in as a
      // measurement stamped with the scan: the filter compensates the matching time as any delay.
      const std::optional<fusion::Estimate> guess = localizer.estimateAt(e.stamp);
      if (!guess) {
        ++result.scans_without_guess;
        continue;
      }
      const ndt::ScanOutcome outcome = ndt_source->process(*scan, e.stamp, guess->pose, guess->state[4], guess->state[5]);
      if (outcome.produced) {
        result.pose_inputs.push_back({outcome.pose.stamp, outcome.pose.pose});
        localizer.feedPose(source_of[e.topic], outcome.pose);
      } else if (result.rejections.size() < 20) {
        result.rejections.push_back("scan stamped " + formatSeconds(e.stamp) + ": " + outcome.detail);
      }
      continue;
    }
    if (const auto* p = std::get_if<PoseMeasurement>(&e.measurement)) {
      result.pose_inputs.push_back({p->stamp, p->pose});
      const bool was_initialized = localizer.initialized();
      localizer.feedPose(source_of[e.topic], *p);
      if (!was_initialized && localizer.initialized()) {
        const fusion::Estimate est = *localizer.estimate();
        result.fused.push_back({est.stamp, est.pose});
      }
    } else {
      localizer.feedTwist(source_of[e.topic], std::get<TwistMeasurement>(e.measurement));
    }
  }
  if (options.progress) options.progress(1.0);
  if (ndt_source) {
    result.ndt = ndt_source->counters();
    result.map = ndt_source->map().stats();
  }
  result.sources = localizer.sources();
  result.unknown_source_inputs = localizer.unknownSourceCount();
  if (!result.fused.empty()) {
    result.first_stamp = result.fused.front().stamp;
    result.last_stamp = result.fused.back().stamp;
  }

  // 5. Error against ground truth at every tick it covers.
  std::sort(result.ground_truth.begin(), result.ground_truth.end(),
            [](const io::TrajectoryPoint& a, const io::TrajectoryPoint& b) { return a.stamp < b.stamp; });
  const Duration max_gap = fromSeconds(config.replay.ground_truth_max_gap);
  for (const io::TrajectoryPoint& p : result.fused) {
    if (const auto truth = truthAt(result.ground_truth, p.stamp, max_gap)) {
      const Eigen::Vector2d estimate = p.pose.position.head<2>();
      result.errors.push_back({p.stamp, estimate, *truth, (estimate - *truth).norm()});
    }
  }
  result.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return result;
}

}  // namespace coloc::tools
