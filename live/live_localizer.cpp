#include "coloc/live/live_localizer.hpp"

#include <algorithm>
#include <cmath>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <set>
#include <sstream>
#include <thread>
#include <mutex>
#include <nlohmann/json.hpp>

#include "coloc/core/error.hpp"
#include "coloc/io/ros_messages.hpp"
#include "coloc/io/ros_node_interfaces.hpp"
#include "coloc/pipeline/input_roles.hpp"
#include "coloc/pipeline/message_inputs.hpp"
#include "coloc/pipeline/report_json.hpp"
#include "coloc/rsu_client/dds_node.hpp"
#include "diagnostics.hpp"
#include "stamp_clock.hpp"

namespace coloc::live {

namespace {

using Bytes = std::vector<std::uint8_t>;

rsu_client::TopicQos inputQos(const pipeline::Config& c, int depth) {
  rsu_client::TopicQos q;
  q.reliable = c.live.reliable;
  q.depth = depth;
  return q;
}

}  // namespace

struct LiveLocalizer::Impl {
  pipeline::Config config;
  bool use_sim_time = false;
  std::atomic<Stamp> sim_now{0};
  std::atomic<bool> stopped{false};

  mutable std::mutex mutex;  // topics, trajectory
  std::vector<TopicStatus> topics;
  std::unique_ptr<io::TumWriter> trajectory;
  Stamp trajectory_first = 0, trajectory_last = 0;
  std::string trajectory_error;
  std::atomic<std::uint64_t> published{0};

  std::unique_ptr<pipeline::Pipeline> pipe;
  std::unique_ptr<rsu_client::DdsNode> node;  // after the pipeline: destroyed first, so no callback outlives it
  rsu_client::DdsNode::Writer pose_writer, odometry_writer, twist_writer, biased_pose_writer, pose_stamped_writer, ndt_pose_writer, tf_writer,
      diagnostics_writer;

  // Activation by the trigger services (Autoware's pose_initializer switches both off, aligns, gives
  // the initial pose, switches both on). A service not served counts as on.
  std::atomic<bool> ekf_active{true}, ndt_active{true};
  bool activated() const { return ekf_active.load() && ndt_active.load(); }

  // Alignment requests wait here for the worker: NDT's search takes longer than a DDS thread may be held.
  std::mutex align_mutex;
  std::condition_variable align_wake;
  std::deque<std::pair<io::StampedPose, rsu_client::DdsNode::Respond>> align_queue;
  std::thread align_worker, housekeeping;
  std::atomic<bool> quit{false};
  DiagnosticsMemory diagnostics_memory;

  Stamp now() const { return use_sim_time ? sim_now.load() : rsu_client::systemNow(); }

  // The node's time on the header stamps' clock (stamp_clock.hpp): what the pipeline runs on.
  std::unique_ptr<StampClock> stamps;
  Stamp pipelineNow() const { return stamps->toStampClock(now()); }
  /// An input stamped `stamp` that reached the node at `arrival` (node time), on the pipeline's clock;
  /// none for one sent before the clock's last jump back, which is counted against its topic: taken,
  /// it would start the filter on the old timeline.
  std::optional<Stamp> arrive(std::size_t topic, Stamp arrival, Stamp stamp) {
    if (!stamps->observe(arrival, stamp)) {
      std::lock_guard<std::mutex> lock(mutex);
      ++topics[topic].from_before_clock_jump;
      return std::nullopt;
    }
    const Stamp on_stamps = stamps->toStampClock(arrival);
    // On a clock of their own, no message arrives before it was stamped (as offline); on one clock a
    // message from the future is the filter's to refuse.
    return stamps->separate() ? std::max(on_stamps, stamp) : on_stamps;
  }

  std::set<std::string> subscribed;  // topics with a reader (setup and the housekeeping thread only)
  std::set<std::string> outputs;     // topics this node publishes: never taken as inputs
  bool have_map = false;
  std::optional<rsu_client::RsuRegistry> registry_copy;  // what the pipeline got, for planning discovered topics
  const rsu_client::RsuRegistry* registry = nullptr;

  std::size_t addTopic(const std::string& topic, const std::string& type) {
    std::lock_guard<std::mutex> lock(mutex);
    topics.push_back({topic, type, 0, 0, {}});
    return topics.size() - 1;
  }

  // Decodes and pushes one sample; whatever goes wrong is counted against its topic, never thrown
  // into DDS's thread.
  template <typename Use>
  void receive(std::size_t topic, const Bytes& bytes, Use use) {
    const Stamp arrival = now();
    {
      std::lock_guard<std::mutex> lock(mutex);
      TopicStatus& t = topics[topic];
      ++t.received;
      if (t.last_arrival != 0 && arrival > t.last_arrival) t.longest_gap = std::max(t.longest_gap, toSeconds(arrival - t.last_arrival));
      t.last_arrival = arrival;
    }
    if (stopped.load()) return;
    try {
      use(bytes, arrival);
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(mutex);
      if (topics[topic].undecodable++ == 0) topics[topic].first_error = topics[topic].topic + ": " + e.what();
    }
  }

  void publish(const fusion::Estimate& e) {
    if (!activated()) return;  // Autoware's EKF publishes nothing until activated
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (trajectory) {
        try {
          trajectory->append({e.stamp, e.pose});
          if (trajectory_first == 0) trajectory_first = e.stamp;
          trajectory_last = e.stamp;
        } catch (const std::exception& error) {
          // A full disk must not stop the localizer: the file stops, and the status says why.
          trajectory_error = error.what();
          trajectory.reset();
        }
      }
    }
    if (stopped.load()) return;
    try {
      io::StampedPose pose;
      pose.header = {e.stamp, config.live.frame_id};
      pose.measurement.stamp = e.stamp;
      pose.measurement.pose = e.pose;
      pose.measurement.covariance = e.pose_covariance;
      pose_writer.write(io::encodePoseWithCovarianceStamped(pose));
      io::Odometry odom;
      odom.header = {e.stamp, config.live.frame_id};
      odom.child_frame_id = config.live.child_frame_id;
      odom.pose = pose.measurement;
      odom.twist.stamp = e.stamp;
      odom.twist.linear = e.linear_velocity;
      odom.twist.angular = e.angular_velocity;
      odom.twist.covariance = e.twist_covariance;
      odometry_writer.write(io::encodeOdometry(odom));
      if (twist_writer.matchedReaders() > 0) {
        io::StampedTwist twist;
        twist.header = {e.stamp, config.live.child_frame_id};
        twist.measurement = odom.twist;
        twist_writer.write(io::encodeTwistWithCovarianceStamped(twist));
      }
      if (pose_stamped_writer.matchedReaders() > 0) pose_stamped_writer.write(io::encodePoseStamped(pose));
      if (biased_pose_writer.matchedReaders() > 0) {
        // The yaw as the pose sources measure it, before the filter's yaw bias: what NDT starts from.
        io::StampedPose biased = pose;
        biased.measurement.pose.orientation = fusion::measuredPose(e).orientation;
        biased_pose_writer.write(io::encodePoseWithCovarianceStamped(biased));
      }
      if (tf_writer.matchedReaders() > 0) {
        io::TFMessage tf;
        io::TransformStamped t;
        t.header = {e.stamp, config.live.frame_id};
        t.child_frame_id = config.live.child_frame_id;
        t.translation = e.pose.position;
        t.rotation = e.pose.orientation;
        tf.transforms.push_back(t);
        tf_writer.write(io::encodeTFMessage(tf));
      }
      ++published;
    } catch (const std::exception&) {
      // An estimate that cannot be encoded (a stamp beyond int32 seconds) is kept in the trajectory only.
    }
  }

  void publishNdtPose(const PoseMeasurement& pose) {
    if (!activated() || ndt_pose_writer.matchedReaders() == 0) return;
    try {
      io::StampedPose out;
      out.header = {pose.stamp, config.live.frame_id};
      out.measurement = pose;
      ndt_pose_writer.write(io::encodePoseWithCovarianceStamped(out));
    } catch (const std::exception&) {
      // not encodable: the filter has it all the same
    }
  }

  // Subscribes to one input topic as its plan says (the roles of `coloc fuse`): scans to NDT, twists and
  // poses to their sources, fixes to the checks. Other roles are not taken live.
  bool subscribeInput(const std::string& topic, const std::string& ros_type, const pipeline::InputPlan& plan) {
    if (!plan.kind || subscribed.count(topic)) return false;
    const io::MessageKind kind = *plan.kind;
    const pipeline::InputConfig* input = nullptr;
    if (const auto found = config.inputs.find(topic); found != config.inputs.end()) input = &found->second;
    const Duration extra_delay = input ? fromSeconds(input->additional_delay) : 0;
    rsu_client::DdsNode::Callback callback;
    std::size_t t = 0;
    switch (plan.role) {
      case pipeline::InputRole::kScan:
        if (!have_map) return false;
        t = addTopic(topic, ros_type);
        callback = [this, t](Bytes&& b, Stamp) {
          receive(t, b, [this, t](const Bytes& bytes, Stamp arrival) {
            const io::PointCloud2 cloud = io::decodePointCloud2(bytes.data(), bytes.size());
            if (const auto at = arrive(t, arrival, cloud.header.stamp)) pipe->pushScan(pipeline::toPointCloud(cloud), cloud.header.stamp, *at);
          });
        };
        break;
      case pipeline::InputRole::kTwist:
      case pipeline::InputRole::kPose: {
        // Twists and poses alike: decoded, covariance completed, taken at their arrival on the stamps'
        // clock, moved back by the input's additional delay, handed to their source.
        const bool twist = plan.role == pipeline::InputRole::kTwist;
        const std::string name = plan.source.empty() ? topic : plan.source;
        const fusion::SourceId source = twist ? pipe->addTwistSource(name) : pipe->addPoseSource(name);
        t = addTopic(topic, ros_type);
        callback = [this, t, kind, input, source, extra_delay, twist](Bytes&& b, Stamp) {
          receive(t, b, [&](const Bytes& bytes, Stamp arrival) {
            bool fallback = false;
            const io::RosMessage message = io::decodeMessage(kind, bytes);
            if (twist) {
              TwistMeasurement m = pipeline::twistFromMessage(message, input, config.messages, fallback);
              const auto at = arrive(t, arrival, m.stamp);
              m.stamp -= extra_delay;
              if (at) pipe->pushTwist(source, m, *at);
            } else {
              PoseMeasurement m = pipeline::poseFromMessage(message, input, config.messages, fallback);
              const auto at = arrive(t, arrival, m.stamp);
              m.stamp -= extra_delay;
              if (at) pipe->pushPose(source, m, *at);
            }
          });
        };
        break;
      }
      case pipeline::InputRole::kRsuFix: {
        t = addTopic(topic, ros_type);
        callback = [this, t, kind, id = plan.rsu_id](Bytes&& b, Stamp) {
          receive(t, b, [&](const Bytes& bytes, Stamp arrival) {
            const rsu_client::RsuFix fix = pipeline::fixFromMessage(io::decodeMessage(kind, bytes), id);
            if (const auto at = arrive(t, arrival, fix.stamp)) pipe->pushFix(fix, *at);
          });
        };
        break;
      }
      default:
        return false;
    }
    // Scans: a few in flight (NDT takes the newest); twists come at 50-100 Hz.
    const int depth = plan.role == pipeline::InputRole::kTwist ? 50 : 5;
    node->subscribe(topic, ros_type, inputQos(config, depth), std::move(callback));
    subscribed.insert(topic);
    return true;
  }

  // Writers discovered on the domain: a topic the configuration names (inputs:) is subscribed with the
  // type its writer has; with live.discover_inputs, any topic is planned by its type as `coloc fuse`
  // plans a log's. The node's own outputs, the initial pose, /clock and ground truth never are.
  void takeDiscovered() {
    for (const auto& w : node->takeDiscoveredWriters()) {
      if (subscribed.count(w.topic) || outputs.count(w.topic) || w.type.empty()) continue;
      if (w.topic == config.live.initial_pose_topic || w.topic == io::kClockTopic) continue;
      const bool named = config.inputs.count(w.topic) > 0;
      if (!named && !config.live.discover_inputs) continue;
      try {
        const pipeline::InputPlan plan = pipeline::planInput(w.topic, w.type, config, have_map, registry);
        if (subscribeInput(w.topic, w.type, plan))
          event("subscribed to " + w.topic + " (" + w.type + ") as " + pipeline::toString(plan.role) + (named ? " (inputs:)" : " (by its type)"));
      } catch (const std::exception& e) {
        event("not subscribed to " + w.topic + ": " + e.what());
      }
    }
  }

  // std_srvs/SetBool on a trigger service: true activates, false deactivates. The filter keeps running
  // meanwhile, so that it is ready when activated; the initial pose that follows restarts it.
  void serveTrigger(const std::string& service, std::atomic<bool>& flag) {
    flag = config.live.start_activated;
    node->serve(service, io::kSetBoolType, [this, &flag, service](Bytes&& request, rsu_client::DdsNode::Respond respond) {
      io::SetBoolResponse response;
      try {
        const bool on = io::decodeSetBoolRequest(request.data(), request.size());
        flag = on;
        response.success = true;
        response.message = on ? "activated" : "deactivated";
        event(service + ": " + response.message);
      } catch (const std::exception& e) {
        response.message = e.what();
        event(service + ": request refused: " + response.message);
      }
      respond(io::encodeSetBoolResponse(response));
    });
  }

  void event(const std::string& line) {
    if (on_event) on_event(line);
  }
  std::function<void(const std::string&)> on_event;

  void alignLoop() {
    for (;;) {
      std::pair<io::StampedPose, rsu_client::DdsNode::Respond> job;
      {
        std::unique_lock<std::mutex> lock(align_mutex);
        align_wake.wait(lock, [this] { return quit.load() || !align_queue.empty(); });
        if (quit.load()) return;
        job = std::move(align_queue.front());
        align_queue.pop_front();
      }
      io::PoseAlignResponse response;
      response.pose = job.first;
      const pipeline::AlignOutcome outcome = pipe->align(job.first.measurement.pose);
      if (outcome.success) {
        response.success = true;
        response.reliable = outcome.reliable;
        response.pose.measurement.pose = outcome.pose.pose;  // the request's covariance stays, as Autoware's NDT answers
      }
      std::ostringstream line;
      line.precision(3);
      line << config.live.align_service << ": " << (outcome.success ? "aligned" : "failed: " + outcome.why) << " from " << outcome.starts
           << " starts";
      if (outcome.success)
        line << ", " << (outcome.pose.pose.position - job.first.measurement.pose.position).head<2>().norm() << " m from the request, NVTL "
             << outcome.nvtl << (outcome.reliable ? " (reliable)" : " (not reliable)");
      event(line.str());
      try {
        job.second(io::encodePoseAlignResponse(response));
      } catch (const std::exception&) {
        // a request stamped beyond int32 seconds: nothing can be answered
      }
    }
  }

  void housekeepingLoop(LiveLocalizer& self) {
    const auto period = std::chrono::duration<double>(1.0 / config.live.diagnostics_frequency);
    while (!quit.load()) {
      std::this_thread::sleep_for(period);
      if (quit.load()) return;
      try {
        takeDiscovered();
      } catch (const std::exception& e) {
        event(std::string("subscribing to a discovered topic failed: ") + e.what());
      }
      if (diagnostics_writer.matchedReaders() == 0) continue;
      try {
        const io::DiagnosticArray d =
            diagnosticsOf(self.status(), activated(), now(), 1.0 / config.fusion.predict_frequency, diagnostics_memory);
        diagnostics_writer.write(io::encodeDiagnosticArray(d));
      } catch (const std::exception&) {
        // a clock before the epoch: no diagnostics until it is sensible
      }
    }
  }
};

LiveLocalizer::LiveLocalizer(LiveOptions options) : impl_(std::make_unique<Impl>()) {
  Impl& d = *impl_;
  d.config = options.config;
  d.use_sim_time = options.use_sim_time;
  if (!options.trajectory_file.empty())
    d.trajectory = std::make_unique<io::TumWriter>(options.trajectory_file, "coloc fused trajectory (live)\nt x y z qx qy qz qw (t: header-stamp clock, s)");
  if (!options.registry && !d.config.rsu.registry.empty()) options.registry = rsu_client::RsuRegistry::load(d.config.rsu.registry);

  pipeline::PipelineOptions po;
  if (!options.map.empty()) po.map = ndt::TileMap::open(options.map, d.config.ndt.map_tile_size);
  d.have_map = po.map.has_value();
  d.registry_copy = options.registry;
  if (d.registry_copy) d.registry = &*d.registry_copy;
  po.registry = std::move(options.registry);
  po.ndt_thread = true;
  d.stamps = std::make_unique<StampClock>(d.config.replay.clock, d.config.fusion.future_tolerance);
  po.clock = [&d] { return d.pipelineNow(); };
  d.pipe = std::make_unique<pipeline::Pipeline>(d.config, std::move(po));
  d.pipe->onEstimate([&d](const fusion::Estimate& e) { d.publish(e); });
  d.on_event = options.on_event;
  if (options.on_event) d.pipe->onEvent(options.on_event);
  d.pipe->onPoseInput([&d](const std::string& source, const PoseMeasurement& pose) {
    if (source == pipeline::kNdtSource) d.publishNdtPose(pose);
  });
  d.node = std::make_unique<rsu_client::DdsNode>(options.dds);
  rsu_client::TopicQos out_qos;
  out_qos.reliable = true;  // as Autoware's EKF publishes: reliable readers and best-effort ones both match
  out_qos.depth = 10;
  auto advertise = [&](const std::string& topic, const char* type, const rsu_client::TopicQos& qos) {
    return topic.empty() ? rsu_client::DdsNode::Writer() : d.node->advertise(topic, type, qos);
  };
  d.pose_writer = advertise(d.config.live.pose_topic, "geometry_msgs/msg/PoseWithCovarianceStamped", out_qos);
  d.odometry_writer = advertise(d.config.live.odometry_topic, "nav_msgs/msg/Odometry", out_qos);
  d.twist_writer = advertise(d.config.live.twist_out_topic, "geometry_msgs/msg/TwistWithCovarianceStamped", out_qos);
  d.biased_pose_writer = advertise(d.config.live.biased_pose_topic, "geometry_msgs/msg/PoseWithCovarianceStamped", out_qos);
  d.pose_stamped_writer = advertise(d.config.live.pose_stamped_topic, "geometry_msgs/msg/PoseStamped", out_qos);
  if (d.have_map) d.ndt_pose_writer = advertise(d.config.live.ndt_pose_topic, "geometry_msgs/msg/PoseWithCovarianceStamped", out_qos);
  if (d.config.live.tf) {
    rsu_client::TopicQos tf_qos = out_qos;
    tf_qos.depth = 100;  // tf2_ros's broadcaster: reliable, volatile, keep last 100
    d.tf_writer = d.node->advertise("/tf", "tf2_msgs/msg/TFMessage", tf_qos);
  }
  if (d.config.live.diagnostics) d.diagnostics_writer = d.node->advertise("/diagnostics", io::kDiagnosticArrayType, out_qos);
  if (!d.config.live.ekf_trigger_service.empty()) d.serveTrigger(d.config.live.ekf_trigger_service, d.ekf_active);
  if (!d.config.live.ndt_trigger_service.empty()) d.serveTrigger(d.config.live.ndt_trigger_service, d.ndt_active);
  if (!d.config.live.align_service.empty()) {
    d.node->serve(d.config.live.align_service, io::kPoseAlignServiceType, [&d](Bytes&& request, rsu_client::DdsNode::Respond respond) {
      io::PoseAlignResponse refused;
      try {
        io::StampedPose pose = io::decodePoseAlignRequest(request.data(), request.size());
        // Whoever calls may send anything: NDT is started only from a finite pose with a usable rotation.
        const Pose& p = pose.measurement.pose;
        if (!p.position.allFinite() || !p.orientation.coeffs().allFinite() || std::abs(p.orientation.norm() - 1.0) > 1e-3)
          throw Error("the pose is not finite or its quaternion is not of norm 1");
        pose.measurement.pose.orientation.normalize();
        std::lock_guard<std::mutex> lock(d.align_mutex);
        // A search takes about a second: a caller that floods the service gets refusals, not a queue.
        if (d.align_queue.size() >= 4) throw Error("four alignments are already waiting");
        d.align_queue.emplace_back(std::move(pose), std::move(respond));
        d.align_wake.notify_one();
        return;
      } catch (const std::exception& e) {
        d.event(d.config.live.align_service + ": request refused: " + e.what());
      }
      respond(io::encodePoseAlignResponse(refused));
    });
    d.align_worker = std::thread([&d] { d.alignLoop(); });
  }

  for (const std::string& topic : {d.config.live.pose_topic, d.config.live.odometry_topic, d.config.live.twist_out_topic, d.config.live.biased_pose_topic,
                                   d.config.live.pose_stamped_topic, d.config.live.ndt_pose_topic, std::string("/tf"), std::string("/diagnostics")})
    if (!topic.empty()) d.outputs.insert(topic);

  if (d.use_sim_time) {
    const std::size_t t = d.addTopic(io::kClockTopic, io::kClockType);
    rsu_client::TopicQos clock_qos;
    clock_qos.depth = 1;
    d.node->subscribe(io::kClockTopic, io::kClockType, clock_qos, [&d, t](Bytes&& b, Stamp) {
      d.receive(t, b, [&d](const Bytes& bytes, Stamp) {
        // The node's time is the last /clock received, back in time too (a player that loops or
        // restarts): the stamps' clock is related afresh, and the pipeline sees the jump and starts the
        // filter again.
        const Stamp clock = io::decodeClock(bytes.data(), bytes.size());
        const Stamp before = d.sim_now.load();
        if (clock + fromSeconds(1.0 / d.config.fusion.predict_frequency) < before) d.stamps->reset(before, clock);
        d.sim_now.store(clock);
      });
    });
    d.subscribed.insert(io::kClockTopic);
  }
  // The live: section's inputs, then each registered RSU's addressed fixes (the protocol) and its
  // unaddressed ones, which the checks refuse unless rsu.accept_unaddressed: both are subscribed so
  // that what arrives on either is counted.
  if (!d.config.live.scan_topic.empty()) {
    pipeline::InputPlan scan;
    scan.role = pipeline::InputRole::kScan;
    scan.kind = io::MessageKind::kPointCloud2;
    scan.source = pipeline::kNdtSource;
    d.subscribeInput(d.config.live.scan_topic, "sensor_msgs/msg/PointCloud2", scan);
  }
  if (!d.config.live.twist_topic.empty()) {
    pipeline::InputPlan twist;
    twist.role = pipeline::InputRole::kTwist;
    twist.kind = io::messageKindOf(d.config.live.twist_type);
    if (!twist.kind) throw Error("live.twist_type: coloc cannot decode " + d.config.live.twist_type);
    twist.source = d.config.live.twist_topic;
    d.subscribeInput(d.config.live.twist_topic, d.config.live.twist_type, twist);
  }
  if (!d.config.live.initial_pose_topic.empty()) {
    const std::size_t t = d.addTopic(d.config.live.initial_pose_topic, "geometry_msgs/msg/PoseWithCovarianceStamped");
    d.node->subscribe(d.config.live.initial_pose_topic, "geometry_msgs/msg/PoseWithCovarianceStamped", inputQos(d.config, 1),
                      [&d, t](Bytes&& b, Stamp) {
                        d.receive(t, b, [&d, t](const Bytes& bytes, Stamp arrival) {
                          bool fallback = false;
                          const PoseMeasurement pose = pipeline::poseFromMessage(
                              io::decodeMessage(io::MessageKind::kPoseWithCovarianceStamped, bytes), nullptr, d.config.messages, fallback);
                          if (const auto at = d.arrive(t, arrival, pose.stamp)) d.pipe->pushInitialPose(pose, *at);
                        });
                      });
    d.subscribed.insert(d.config.live.initial_pose_topic);
  }
  if (d.registry)
    for (const auto& rsu : d.registry->rsus())
      for (const auto& [topic, kind] : {std::make_pair(rsu_client::addressedFixTopic(rsu.id), io::MessageKind::kOdometry),
                                        std::make_pair(rsu_client::fixTopic(rsu.id), io::MessageKind::kPoseWithCovarianceStamped)}) {
        pipeline::InputPlan fix;
        fix.role = pipeline::InputRole::kRsuFix;
        fix.kind = kind;
        fix.rsu_id = rsu.id;
        d.subscribeInput(topic, std::string(io::rosTypeName(kind)), fix);
      }
  d.pipe->start();
  d.housekeeping = std::thread([&d, this] { d.housekeepingLoop(*this); });
}

LiveLocalizer::~LiveLocalizer() {
  stop();
  impl_->node.reset();  // DDS first: no callback may reach a pipeline that is gone
}

void LiveLocalizer::stop() {
  {
    std::lock_guard<std::mutex> lock(impl_->align_mutex);
    impl_->quit = true;
    impl_->align_wake.notify_all();
  }
  if (impl_->align_worker.joinable()) impl_->align_worker.join();
  if (impl_->housekeeping.joinable()) impl_->housekeeping.join();
  impl_->pipe->stop();
  impl_->stopped = true;
  std::lock_guard<std::mutex> lock(impl_->mutex);
  if (impl_->trajectory) {
    try {
      impl_->trajectory->close();
    } catch (const std::exception& error) {
      impl_->trajectory_error = error.what();
    }
  }
}

LiveStatus LiveLocalizer::status() const {
  LiveStatus s;
  s.report = impl_->pipe->report();
  s.estimate = impl_->pipe->estimate();
  s.published = impl_->published.load();
  s.clock = impl_->now();
  s.activated = impl_->activated();
  std::vector<rsu_client::DdsNode::ReaderStatus> readers;
  if (impl_->node) readers = impl_->node->readers();
  std::lock_guard<std::mutex> lock(impl_->mutex);
  s.topics = impl_->topics;
  // One reader per topic.
  for (const auto& r : readers)
    for (TopicStatus& t : s.topics)
      if (t.topic == r.topic) {
        t.matched_writers = r.matched_writers;
        t.sequence_gaps = r.sequence_gaps;
        t.lost = r.lost;
        t.rejected = r.rejected;
        s.matched_writers += r.matched_writers;
      }
  s.trajectory_points = impl_->trajectory ? impl_->trajectory->points() : 0;
  s.trajectory_first = impl_->trajectory_first;
  s.trajectory_last = impl_->trajectory_last;
  s.trajectory_error = impl_->trajectory_error;
  return s;
}

std::string LiveLocalizer::summaryJson() const {
  const LiveStatus s = status();
  nlohmann::ordered_json j;
  j["mode"] = "live";
  j["clock"] = impl_->use_sim_time ? "/clock (simulation time)" : "system";
  // How the header stamps were related to that clock at the end (stamp_clock.hpp).
  j["stamps"] = impl_->stamps->separate() ? "on a clock of their own, offset " + formatSeconds(impl_->stamps->offset()) + " s" : "on the node's clock";
  auto& topics = j["topics"] = nlohmann::ordered_json::array();
  for (const TopicStatus& t : s.topics) {
    nlohmann::ordered_json o = {{"topic", t.topic},
                                {"type", t.type},
                                {"messages", t.received},
                                {"decode_errors", t.undecodable},
                                {"matched_writers", t.matched_writers},
                                {"sequence_gaps", t.sequence_gaps},
                                {"dds_lost", t.lost},
                                {"dds_rejected", t.rejected},
                                {"from_before_clock_jump", t.from_before_clock_jump},
                                {"longest_gap_s", t.longest_gap}};
    if (!t.first_error.empty()) o["first_error"] = t.first_error;
    topics.push_back(o);
  }
  j["sources"] = nlohmann::ordered_json::parse(pipeline::sourcesJson(s.report.sources));
  j["fused"] = {{"file", "fused.tum"},
                {"poses", s.trajectory_points},
                {"published", s.published},
                {"first_stamp", formatSeconds(s.trajectory_first)},
                {"last_stamp", formatSeconds(s.trajectory_last)}};
  if (!s.trajectory_error.empty()) j["fused"]["error"] = s.trajectory_error;
  if (s.report.ndt_used) {
    j["ndt"] = nlohmann::ordered_json::parse(pipeline::ndtJson(s.report.ndt, s.report.map, s.report.scans_without_guess));
    j["ndt"]["scans_superseded"] = s.report.scans_superseded;
    j.update(nlohmann::ordered_json::parse(pipeline::learnedJson(s.report)));
  }
  if (!s.report.fixes.empty()) j["rsu_fixes"] = nlohmann::ordered_json::parse(pipeline::fixesJson(s.report.fixes, s.report.filter_of_fixes));
  j["localization"] = nlohmann::ordered_json::parse(pipeline::localizationJson(s.report));
  j["rejections"] = s.report.rejections;
  j["rejections_first"] = s.report.first_rejections;
  return j.dump(2) + "\n";
}

}  // namespace coloc::live
