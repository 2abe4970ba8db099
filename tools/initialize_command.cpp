// `coloc initialize`: Autoware's pose_initializer sequence from the outside, for a node that stands
// where ekf_localizer and ndt_scan_matcher stand (`coloc localize --config config/autoware.yaml`) or for
// Autoware's own: both trigger services off, NDT's alignment around the given pose, the result on the
// initial-pose topic, both triggers on. Each step is printed; any that fails ends it with status 1.
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>

#include "coloc/core/error.hpp"
#include "coloc/io/ros_messages.hpp"
#include "coloc/io/ros_node_interfaces.hpp"
#include "coloc/pipeline/config.hpp"
#include "coloc/rsu_client/dds_node.hpp"
#include "commands.hpp"
#include "dds_options.hpp"
#include "number_checks.hpp"

namespace coloc::tools {

namespace {

void step(const char* format, const std::string& what) {
  std::printf(format, what.c_str());
  std::fflush(stdout);
}

void trigger(rsu_client::DdsNode& node, const std::string& service, bool on, double timeout) {
  if (service.empty()) return;
  rsu_client::DdsNode::Client client = node.client(service, io::kSetBoolType);
  if (!client.waitForServer(timeout)) throw Error(service + ": no server answered within " + std::to_string(timeout) + " s");
  const auto reply = client.call(io::encodeSetBoolRequest(on), timeout);
  if (!reply) throw Error(service + ": no reply within " + std::to_string(timeout) + " s");
  const io::SetBoolResponse r = io::decodeSetBoolResponse(reply->data(), reply->size());
  if (!r.success) throw Error(service + ": refused (" + r.message + ")");
  step("  %s\n", service + (on ? " -> on" : " -> off") + (r.message.empty() ? "" : " (" + r.message + ")"));
}

}  // namespace

void addInitializeCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("initialize",
                                 "Initialize a running localizer as Autoware's pose_initializer does: triggers off, NDT alignment around "
                                 "a pose, the initial pose, triggers on (names from the config's live: section)");
  static std::string config_path;
  static std::vector<double> pose;
  static double z = 0.0, sd = 1.0, yaw_sd_deg = 10.0, timeout = 20.0;
  static bool direct = false, sim_time = false;
  static DdsOptions dds;
  cmd->add_option("--pose", pose, "x,y,yaw (m, m, rad) in the map frame")->required()->expected(3)->delimiter(',')->check(finiteNumber(-1e9));
  cmd->add_option("--z", z, "height of the pose, m")->check(finiteNumber(-1e9))->capture_default_str();
  cmd->add_option("--config", config_path, "the localizer's configuration (config/autoware.yaml for Autoware's names)")->check(CLI::ExistingFile);
  cmd->add_option("--position-sd", sd, "standard deviation of the published initial pose's x and y, m")->check(finiteNumber(1e-3))->capture_default_str();
  cmd->add_option("--yaw-sd", yaw_sd_deg, "its yaw's, deg")->check(finiteNumber(1e-3))->capture_default_str();
  cmd->add_flag("--direct", direct, "publish the pose as given, without NDT's alignment (pose_initializer's DIRECT method)");
  cmd->add_flag("--use-sim-time", sim_time, "stamp the pose with the time on /clock (a localizer run with --use-sim-time)");
  cmd->add_option("--timeout", timeout, "s to wait for each service")->check(finiteNumber(0.1))->capture_default_str();
  addDdsOptions(cmd, dds);
  cmd->callback([] {
    const pipeline::Config config = config_path.empty() ? pipeline::Config{} : pipeline::loadConfig(config_path);
    const pipeline::LiveSection& live = config.live;
    if (live.initial_pose_topic.empty()) throw Error("live.initial_pose_topic is empty: there is nowhere to send the pose");
    rsu_client::DdsNode node(ddsConfig(dds, "coloc_initializer"));
    rsu_client::TopicQos qos;
    qos.reliable = true;  // pose_initializer publishes its pose reliable, keep last 1
    qos.depth = 1;
    rsu_client::DdsNode::Writer initial = node.advertise(live.initial_pose_topic, "geometry_msgs/msg/PoseWithCovarianceStamped", qos);

    // The pose is stamped now on the localizer's clock: the system's, or /clock's when it runs on a log.
    std::atomic<Stamp> clock{0};
    if (sim_time) {
      rsu_client::TopicQos clock_qos;
      clock_qos.depth = 1;
      node.subscribe(io::kClockTopic, io::kClockType, clock_qos, [&clock](std::vector<std::uint8_t>&& b, Stamp) {
        try {
          clock = io::decodeClock(b.data(), b.size());
        } catch (const std::exception&) {
          // not a clock: wait for one
        }
      });
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout);
      while (clock.load() == 0) {
        if (std::chrono::steady_clock::now() > deadline) throw Error("/clock: nothing received within " + std::to_string(timeout) + " s");
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
    }
    const auto now = [&] { return sim_time ? clock.load() : rsu_client::systemNow(); };
    io::StampedPose request;
    request.header = {now(), live.frame_id};
    request.measurement.stamp = request.header.stamp;
    request.measurement.pose.position = {pose[0], pose[1], z};
    request.measurement.pose.orientation = quaternionFromRollPitchYaw(0.0, 0.0, pose[2]);
    request.measurement.covariance = Matrix6d::Zero();
    const double yaw_sd = yaw_sd_deg * M_PI / 180.0;
    request.measurement.covariance.diagonal() << sd * sd, sd * sd, 0.01, 0.01, 0.01, yaw_sd * yaw_sd;

    std::printf("initializing at x=%.3f y=%.3f yaw=%.3f rad\n", pose[0], pose[1], pose[2]);
    std::fflush(stdout);
    trigger(node, live.ekf_trigger_service, false, timeout);
    trigger(node, live.ndt_trigger_service, false, timeout);
    if (!direct) {
      if (live.align_service.empty()) throw Error("live.align_service is empty: use --direct, or a configuration that serves NDT's alignment");
      rsu_client::DdsNode::Client align = node.client(live.align_service, io::kPoseAlignServiceType);
      if (!align.waitForServer(timeout)) throw Error(live.align_service + ": no server answered within " + std::to_string(timeout) + " s");
      const auto reply = align.call(io::encodePoseAlignRequest(request), timeout);
      if (!reply) throw Error(live.align_service + ": no reply within " + std::to_string(timeout) + " s");
      const io::PoseAlignResponse r = io::decodePoseAlignResponse(reply->data(), reply->size());
      if (!r.success) throw Error(live.align_service + ": NDT could not align around the pose");
      const Pose& p = r.pose.measurement.pose;
      std::printf("  %s: x=%.3f y=%.3f yaw=%.3f rad, %.3f m from the pose given%s\n", live.align_service.c_str(), p.position.x(), p.position.y(),
                  rollPitchYaw(p.orientation)[2], (p.position - request.measurement.pose.position).head<2>().norm(),
                  r.reliable ? "" : " (NOT reliable: its score is below ndt.nvtl_threshold)");
      std::fflush(stdout);
      request.measurement.pose = p;
    }
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout);
    while (initial.matchedReaders() == 0) {
      if (std::chrono::steady_clock::now() > deadline) throw Error(live.initial_pose_topic + ": no subscriber within " + std::to_string(timeout) + " s");
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    request.header.stamp = request.measurement.stamp = now();
    initial.write(io::encodePoseWithCovarianceStamped(request));
    initial.waitForAcknowledgments(timeout);
    step("  initial pose published on %s\n", live.initial_pose_topic);
    trigger(node, live.ekf_trigger_service, true, timeout);
    trigger(node, live.ndt_trigger_service, true, timeout);
    std::printf("initialized\n");
    std::fflush(stdout);
  });
}

}  // namespace coloc::tools
