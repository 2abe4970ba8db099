#pragma once
// The vehicle pipeline live over DDS, without ROS: it subscribes to the scans, the twist, the initial
// pose and every registered RSU's fixes with ROS 2 names, types and QoS, runs the pipeline on its own
// thread, and publishes the fused pose (PoseWithCovarianceStamped) and odometry at every filter tick.
// A ROS 2 system on the same DDS domain sees it as a node.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "coloc/io/trajectory_file.hpp"
#include "coloc/pipeline/config.hpp"
#include "coloc/pipeline/pipeline.hpp"
#include "coloc/rsu_client/dds_transport.hpp"
#include "coloc/rsu_client/rsu_registry.hpp"

namespace coloc::live {

struct LiveOptions {
  pipeline::Config config;
  std::string map;  ///< PCD file or folder of tiles; without it scans are not subscribed to
  std::optional<rsu_client::RsuRegistry> registry;  ///< unset: the one config.rsu.registry names, if any
  rsu_client::DdsConfig dds;
  /// Run on the time received on /clock (rosgraph_msgs/Clock), as ROS 2 nodes with use_sim_time do
  /// when a recorded log is played; off: the system clock.
  bool use_sim_time = false;
  /// Starts, recoveries, state changes and clock resets, one line each, on the pipeline's thread.
  std::function<void(const std::string& line)> on_event;
  /// Every published estimate is appended to this TUM file as it comes, so that hours of driving take
  /// no memory; empty: none is written.
  std::string trajectory_file;
};

/// What one subscribed topic brought, and what it lost on the way as far as DDS can see.
struct TopicStatus {
  std::string topic, type;
  std::uint64_t received = 0, undecodable = 0;
  std::string first_error;
  int matched_writers = 0;
  /// Samples its writers sent that never reached the node (gaps in each writer's sequence numbers),
  /// and DDS's own sample-lost and sample-rejected counts.
  std::uint64_t sequence_gaps = 0, lost = 0, rejected = 0;
  /// Sent before /clock's last jump back and arriving after it: dropped (StampClock::reset).
  std::uint64_t from_before_clock_jump = 0;
  Stamp last_arrival = 0;     ///< on the node's clock; 0: nothing yet
  double longest_gap = 0.0;   ///< s, the longest time between two arrivals
};

struct LiveStatus {
  pipeline::PipelineReport report;
  std::vector<TopicStatus> topics;
  std::optional<fusion::Estimate> estimate;
  std::uint64_t published = 0;  ///< estimates published
  Stamp clock = 0;              ///< the node's time now
  int matched_writers = 0;      ///< remote writers matched with the node's readers
  bool activated = true;        ///< outputs flow (live.start_activated, the trigger services)
  /// The fused trajectory as written so far (LiveOptions::trajectory_file).
  std::uint64_t trajectory_points = 0;
  Stamp trajectory_first = 0, trajectory_last = 0;
  std::string trajectory_error;  ///< why writing it stopped, if it did
};

class LiveLocalizer {
 public:
  /// Subscribes, advertises and starts. Throws coloc::Error for a bad map, registry or DDS setup.
  explicit LiveLocalizer(LiveOptions options);
  ~LiveLocalizer();
  LiveLocalizer(const LiveLocalizer&) = delete;
  LiveLocalizer& operator=(const LiveLocalizer&) = delete;

  /// Stops the pipeline (what arrived still counts); nothing is published afterwards.
  void stop();
  LiveStatus status() const;
  /// summary.json in the shape `coloc fuse` writes: topics, sources, NDT, fixes, rejections.
  std::string summaryJson() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace coloc::live
