#include "coloc/replay/log_replay.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <type_traits>
#include <variant>

#include "coloc/core/error.hpp"
#include "coloc/io/bag_reader.hpp"
#include "coloc/io/ros_messages.hpp"
#include "coloc/pipeline/message_inputs.hpp"
#include "coloc/pipeline/static_transforms.hpp"
#include "coloc/replay/accurate_places.hpp"
#include "coloc/rsu_client/link_emulator.hpp"

namespace coloc::replay {

namespace {

using pipeline::InputConfig;

// A decoded input waiting to be replayed.
struct Event {
  Stamp log_time;
  Stamp stamp;
  Stamp arrival;  ///< log_time on the stamp clock
  std::uint64_t order;
  std::size_t topic;
  /// A scan is owned when decoded from the file, shared when it comes from a ReplayCache.
  std::variant<PoseMeasurement, TwistMeasurement, ndt::PointCloud, std::shared_ptr<const ndt::PointCloud>, rsu_client::RsuFix> input;
};

using SharedScan = std::shared_ptr<const ndt::PointCloud>;

// The log's messages in order, from the file or from a log held in memory (ReplayCache).
class MessageSource {
 public:
  explicit MessageSource(io::BagReader& bag) : bag_(&bag) {}
  explicit MessageSource(const RecordedLog& log) : log_(&log) {}
  std::uint64_t count() const { return bag_ ? bag_->messageCount() : log_->messages().size(); }
  const io::BagMessage* next() {
    if (bag_) return bag_->next(message_) ? &message_ : nullptr;
    return next_ < log_->messages().size() ? &log_->messages()[next_++] : nullptr;
  }
  /// Message m as a point cloud (PointCloud2 as `kind`) into `e`: shared from the log in memory, or
  /// decoded. Returns the scan's frame.
  std::string scan(const io::BagMessage& m, io::MessageKind kind, Event& e) const {
    if (log_) {
      RecordedLog::Scan shared = log_->scan(m.index, kind);
      e.stamp = shared.stamp;
      e.input = std::move(shared.cloud);
      return shared.frame_id;
    }
    io::RosMessage decoded = io::decodeMessage(kind, m.data);
    io::PointCloud2& cloud = std::get<io::PointCloud2>(decoded);
    e.stamp = cloud.header.stamp;
    e.input = pipeline::toPointCloud(cloud);
    return std::move(cloud.header.frame_id);
  }

 private:
  io::BagReader* bag_ = nullptr;
  io::BagMessage message_;
  const RecordedLog* log_ = nullptr;
  std::size_t next_ = 0;
};

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// Stage 2: every message of a used topic, decoded; ground truth goes straight into the result, static
// transforms into `frames`.
std::vector<Event> decodeAll(MessageSource& source, const pipeline::Config& config, ReplayResult& result, pipeline::StaticTransforms& frames,
                             const std::function<void(double)>& progress) {
  std::map<std::string, std::size_t> topic_index;
  for (std::size_t i = 0; i < result.topics.size(); ++i) topic_index[result.topics[i].topic] = i;
  std::vector<Event> events;
  const std::uint64_t total = std::max<std::uint64_t>(source.count(), 1);
  // Earliest and latest, not first and last: files need not be in time order.
  Stamp first_log = 0, last_log = 0;
  while (const io::BagMessage* next = source.next()) {
    const io::BagMessage& message = *next;
    first_log = result.messages_read == 0 ? message.log_time : std::min(first_log, message.log_time);
    last_log = result.messages_read == 0 ? message.log_time : std::max(last_log, message.log_time);
    if (progress && result.messages_read % 256 == 0) progress(0.5 * result.messages_read / total);
    ++result.messages_read;
    const auto found = topic_index.find(message.topic);
    if (found == topic_index.end()) continue;
    const std::size_t ti = found->second;
    TopicUse& use = result.topics[ti];
    ++use.messages;
    if (use.role == InputRole::kIgnore) continue;
    const InputConfig* input = use.from_config ? &config.inputs.at(use.topic) : nullptr;
    const auto countError = [&](const std::string& what) {
      if (use.decode_errors++ == 0) use.first_error = "topic " + use.topic + " message #" + std::to_string(message.index) + ": " + what;
    };
    try {
      Event e{message.log_time, 0, 0, message.index, ti, PoseMeasurement{}};
      if (use.role == InputRole::kScan) {
        std::string frame = source.scan(message, *use.kind, e);
        if (use.frame_id.empty()) use.frame_id = std::move(frame);
        events.push_back(std::move(e));
        continue;
      }
      const io::RosMessage decoded = io::decodeMessage(*use.kind, message.data);
      if (use.role == InputRole::kStaticTransforms) {
        // Each transform on its own: one that cannot be in the tree is counted, the others are kept.
        for (const io::TransformStamped& t : std::get<io::TFMessage>(decoded).transforms) {
          try {
            frames.add(t);
          } catch (const Error& err) {
            countError(err.what());
          }
        }
        continue;
      }
      bool fallback = false;
      switch (use.role) {
        case InputRole::kGroundTruth: {
          const PoseMeasurement p = pipeline::poseFromMessage(decoded, input, config.messages, fallback);
          result.ground_truth.push_back({p.stamp, p.pose});
          continue;
        }
        case InputRole::kRsuFix:
          e.input = pipeline::fixFromMessage(decoded, use.rsu_id);
          break;
        case InputRole::kTwist:
          e.input = pipeline::twistFromMessage(decoded, input, config.messages, fallback);
          break;
        default:
          e.input = pipeline::poseFromMessage(decoded, input, config.messages, fallback);
          break;
      }
      if (fallback) ++use.fallback_covariance;
      // The measurement's own stamp, moved back by the configured sensing delay.
      std::visit(
          [&](auto& m) {
            using M = std::decay_t<decltype(m)>;
            if constexpr (!std::is_same_v<M, ndt::PointCloud> && !std::is_same_v<M, SharedScan>) {
              if (input && input->additional_delay > 0.0) m.stamp -= fromSeconds(input->additional_delay);
              e.stamp = m.stamp;
            }
          },
          e.input);
      events.push_back(std::move(e));
    } catch (const Error& err) {
      countError(err.what());
    }
  }
  result.log_duration = toSeconds(last_log - first_log);
  return events;
}

// Stage 3: arrival times on the stamp clock, fitted when the log recorded them on another clock.
void placeOnStampClock(std::vector<Event>& events, const pipeline::Config& config, ReplayResult& result) {
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
}

// Stage 4: topics replayed through an emulated link; each message, in recorded order, is delayed or lost.
void emulateLinks(std::vector<Event>& events, const pipeline::Config& config, ReplayResult& result) {
  std::map<std::size_t, rsu_client::LinkEmulator> links;
  for (std::size_t i = 0; i < result.topics.size(); ++i)
    if (result.topics[i].from_config && config.inputs.at(result.topics[i].topic).link)
      links.emplace(i, rsu_client::LinkEmulator(*config.inputs.at(result.topics[i].topic).link));
  if (links.empty()) return;
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

void measureDelays(const std::vector<Event>& events, ReplayResult& result) {
  std::vector<std::vector<double>> delays(result.topics.size());
  for (const Event& e : events) delays[e.topic].push_back(toSeconds(e.arrival - e.stamp));
  for (std::size_t i = 0; i < delays.size(); ++i) {
    if (delays[i].empty()) continue;
    result.topics[i].delay_median = median(delays[i]);
    result.topics[i].delay_max = *std::max_element(delays[i].begin(), delays[i].end());
  }
}

// Where NDT takes the LiDAR to be on the vehicle: as configured, else where the log's /tf_static puts
// the scans' frame in the base frame, else at the vehicle's origin; the result says which, and why.
pipeline::Config placeLidar(const pipeline::Config& config, const pipeline::StaticTransforms& frames, ReplayResult& result) {
  pipeline::Config placed = config;
  const auto scans = std::find_if(result.topics.begin(), result.topics.end(), [](const TopicUse& t) { return t.role == InputRole::kScan; });
  if (scans == result.topics.end()) return placed;
  const bool have_tf = std::any_of(result.topics.begin(), result.topics.end(), [](const TopicUse& t) { return t.role == InputRole::kStaticTransforms; });
  result.lidar_pose = config.ndt.source.lidar_pose;
  const std::string& base = config.ndt.base_frame;
  const std::string& frame = scans->frame_id;
  if (config.ndt.lidar_pose_given) {
    result.lidar_pose_from = "ndt.lidar_pose (configured)";
  } else if (!have_tf) {
    result.lidar_pose_from = "the vehicle's origin: the log has no /tf_static and ndt.lidar_pose is not given";
  } else if (frame.empty()) {
    result.lidar_pose_from = "the vehicle's origin: the scans name no frame to look up in /tf_static";
  } else if (const auto pose = frames.lookup(base, frame)) {
    placed.ndt.source.lidar_pose = result.lidar_pose = pipeline::poseVector(*pose);
    result.lidar_pose_from = "/tf_static: " + frame + " in " + base;
  } else {
    result.lidar_pose_from = "the vehicle's origin: /tf_static (" + std::to_string(frames.size()) + " transforms) does not connect '" + base +
                             "' (ndt.base_frame) to the scans' frame '" + frame + "'; set ndt.base_frame or ndt.lidar_pose";
  }
  return placed;
}

// Stage 5: the inputs through the vehicle pipeline in arrival order, its clock driven by log time.
void drive(std::vector<Event>& events, const pipeline::Config& config, const ReplayOptions& options,
           std::optional<rsu_client::RsuRegistry> registry, ReplayResult& result) {
  pipeline::PipelineOptions po;
  po.registry = std::move(registry);
  bool scans = false;
  for (const TopicUse& t : result.topics) scans = scans || t.role == InputRole::kScan;
  // A map that is not there is an error whether or not the log has scans to match against it (opening
  // it checks its path; without scans it is not opened, its tiles are not read).
  if (!scans && !options.map.empty()) ndt::TileMap::checkPath(options.map);
  if (scans && !options.map.empty()) {
    po.map = options.cache ? options.cache->map(options.map, config.ndt.map_tile_size) : ndt::TileMap::open(options.map, config.ndt.map_tile_size);
    if (options.cache) po.targets = options.cache->targets();
    if (options.cache) po.alignments = options.cache->alignments();
  }
  pipeline::Pipeline pipe(config, std::move(po));
  std::vector<fusion::SourceId> source_of(result.topics.size(), -1);
  for (std::size_t i = 0; i < result.topics.size(); ++i) {
    if (result.topics[i].role == InputRole::kPose) source_of[i] = pipe.addPoseSource(result.topics[i].source);
    if (result.topics[i].role == InputRole::kTwist) source_of[i] = pipe.addTwistSource(result.topics[i].source);
  }
  const bool keep = options.keep_filter_inputs;
  pipe.onEstimate([&](const fusion::Estimate& e) {
    result.fused.push_back({e.stamp, e.pose});
    result.fused_sd.emplace_back(std::sqrt(e.pose_covariance(0, 0)), std::sqrt(e.pose_covariance(1, 1)));
    result.fused_localization.push_back(e.localization);
    if (keep) {
      result.fused_states.emplace_back(e.stamp, e.state);
      result.fused_state_covariances.push_back(e.state_covariance);
    }
  });
  pipe.onPoseSettled([&](const std::string& source, const fusion::Estimate& e) { result.settled_poses[source].push_back({e.stamp, e.pose}); });
  pipe.onPoseInput([&](const std::string& source, const PoseMeasurement& p) {
    result.pose_inputs.push_back({p.stamp, p.pose});
    result.pose_input_sources.push_back(source);
    result.pose_input_covariances.push_back(p.covariance.topLeftCorner<2, 2>());
    if (keep) result.filter_poses.emplace_back(source, p);
  });
  if (keep) pipe.onPoseWeighed([&](const std::string& source, const PoseMeasurement& p) { result.weighed_poses.emplace_back(source, p); });
  if (keep)
    pipe.onTwistInput([&](const std::string& source, const TwistMeasurement& handed, const TwistMeasurement& received) {
      result.filter_twists.emplace_back(source, handed);
      result.received_twists.emplace_back(source, received);
    });
  pipe.onRejection([&](const std::string& line) {
    if (result.rejections.size() < 20) result.rejections.push_back(line);
  });
  for (std::size_t i = 0; i < events.size(); ++i) {
    Event& e = events[i];
    const bool is_scan = std::holds_alternative<ndt::PointCloud>(e.input) || std::holds_alternative<SharedScan>(e.input);
    if (options.progress && (i % 256 == 0 || is_scan)) options.progress(0.5 + 0.5 * i / events.size());
    if (auto* scan = std::get_if<ndt::PointCloud>(&e.input)) pipe.pushScan(std::move(*scan), e.stamp, e.arrival);
    else if (auto* shared = std::get_if<SharedScan>(&e.input)) pipe.pushScan(*shared, e.stamp, e.arrival);
    else if (auto* fix = std::get_if<rsu_client::RsuFix>(&e.input)) pipe.pushFix(*fix, e.arrival);
    else if (auto* twist = std::get_if<TwistMeasurement>(&e.input)) pipe.pushTwist(source_of[e.topic], *twist, e.arrival);
    else pipe.pushPose(source_of[e.topic], std::get<PoseMeasurement>(e.input), e.arrival);
    pipe.runUntil(e.arrival);
  }
  if (options.progress) options.progress(1.0);
  const pipeline::PipelineReport report = pipe.report();
  result.pipeline_report = report;
  result.sources = report.sources;
  result.unknown_source_inputs = report.unknown_source_inputs;
  result.ndt_used = report.ndt_used;
  result.ndt = report.ndt;
  result.map = report.map;
  result.scans_without_guess = report.scans_without_guess;
  result.fixes = report.fixes;
}

}  // namespace

ReplayResult replayLog(const std::string& log_path, const ReplayOptions& options) {
  const auto wall_start = std::chrono::steady_clock::now();
  const pipeline::Config& config = options.config;
  std::optional<rsu_client::RsuRegistry> registry = options.registry;
  if (!registry && !config.rsu.registry.empty()) registry = rsu_client::RsuRegistry::load(config.rsu.registry);
  // The reference drive's places, read before the replay: a bad file stops it before it has cost anything.
  std::map<std::string, AccuratePlaces> reference_places;
  if (!config.replay.input_reference.empty())
    reference_places = AccuratePlaces::fromInputErrorCsv(config.replay.input_reference, config.replay.input_stretch_length, config.replay.input_accurate_below);
  std::optional<io::BagReader> bag;
  std::shared_ptr<const RecordedLog> recorded;
  if (options.cache) recorded = options.cache->log(log_path);
  else bag.emplace(io::BagReader::open(log_path, io::BagReadOptions{options.recover}));
  const std::vector<io::TopicInfo>& log_topics = recorded ? recorded->topics() : bag->topics();
  ReplayResult result;
  result.input_reference = config.replay.input_reference;
  if (bag) result.recovered = bag->recovered();
  result.topics = planTopics(log_topics, config, !options.map.empty(), registry ? &*registry : nullptr, result.rejections);
  const bool has_input = std::any_of(result.topics.begin(), result.topics.end(), [](const TopicUse& t) {
    return t.role == InputRole::kPose || t.role == InputRole::kTwist || t.role == InputRole::kScan || t.role == InputRole::kRsuFix;
  });
  if (!has_input) {
    std::vector<TopicUse> listed = result.topics;
    for (TopicUse& t : listed)
      for (const io::TopicInfo& info : log_topics)
        if (info.name == t.topic) t.messages = info.message_count;
    throw Error(log_path + ": nothing to fuse: no topic is a pose, twist, scan (with a map) or RSU fix input. The log holds:\n" +
                describeTopics(listed));
  }
  MessageSource source = recorded ? MessageSource(*recorded) : MessageSource(*bag);
  pipeline::StaticTransforms frames;
  std::vector<Event> events = decodeAll(source, config, result, frames, options.progress);
  placeOnStampClock(events, config, result);
  emulateLinks(events, config, result);
  measureDelays(events, result);
  std::sort(events.begin(), events.end(), [](const Event& a, const Event& b) {
    return a.arrival != b.arrival ? a.arrival < b.arrival : a.order < b.order;
  });
  if (options.until > 0) {
    const auto later = std::upper_bound(events.begin(), events.end(), options.until, [](Stamp t, const Event& e) { return t < e.arrival; });
    result.inputs_after_until = static_cast<std::uint64_t>(events.end() - later);
    events.erase(later, events.end());
  }
  drive(events, placeLidar(config, frames, result), options, std::move(registry), result);
  if (result.fused.empty()) {
    const std::string ended = result.inputs_after_until ? "; the replay ended at stamp " + formatSeconds(options.until) + " (until), before " +
                                                              std::to_string(result.inputs_after_until) + " of its inputs"
                                                        : std::string();
    throw Error(log_path + ": nothing fused: no input gave the filter a pose it could start from or accept (" +
                std::to_string(result.messages_read) + " messages read" + ended + "). The log holds:\n" + describeTopics(result.topics));
  }
  if (!result.fused.empty()) {
    result.first_stamp = result.fused.front().stamp;
    result.last_stamp = result.fused.back().stamp;
  }
  std::sort(result.ground_truth.begin(), result.ground_truth.end(),
            [](const io::TrajectoryPoint& a, const io::TrajectoryPoint& b) { return a.stamp < b.stamp; });
  const Duration max_gap = fromSeconds(config.replay.ground_truth_max_gap);
  result.errors = evaluate(result.fused, result.ground_truth, max_gap);
  if (!result.ground_truth.empty()) {
    std::map<std::string, std::vector<io::TrajectoryPoint>> by_source;
    for (std::size_t i = 0; i < result.pose_inputs.size(); ++i) by_source[result.pose_input_sources[i]].push_back(result.pose_inputs[i]);
    for (auto& [source, inputs] : by_source) {
      std::sort(inputs.begin(), inputs.end(), [](const io::TrajectoryPoint& a, const io::TrajectoryPoint& b) { return a.stamp < b.stamp; });
      result.input_errors[source] = evaluate(inputs, result.ground_truth, max_gap);
      std::vector<Stamp> stamps;
      for (const ErrorSample& e : result.input_errors[source]) stamps.push_back(e.stamp);
      result.fused_at_inputs[source] = evaluateAt(result.fused, stamps, result.ground_truth, max_gap);
      std::vector<io::TrajectoryPoint>& settled = result.settled_poses[source];
      std::sort(settled.begin(), settled.end(), [](const io::TrajectoryPoint& a, const io::TrajectoryPoint& b) { return a.stamp < b.stamp; });
      result.settled_at_inputs[source] = evaluate(settled, result.ground_truth, max_gap);
      const auto reference = reference_places.find(source);
      result.input_comparison[source] = compareWithInput(result.input_errors[source], result.fused_at_inputs[source], result.settled_at_inputs[source],
                                                         config.replay.input_stretch_length, config.replay.input_accurate_below,
                                                         reference == reference_places.end() ? nullptr : &reference->second);
    }
  }
  result.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return result;
}

}  // namespace coloc::replay
