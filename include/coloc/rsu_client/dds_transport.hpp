#pragma once
// Roadside fixes and vehicle dimensions over Fast DDS, exactly as ROS 2 puts them on the wire: topic
// "rt/rsu/<id>/fix" of type geometry_msgs::msg::dds_::PoseWithCovarianceStamped_ and
// "rt/vehicle/dimensions" of type coloc_msgs::msg::dds_::VehicleDimensions_, XCDR1, no keys. A ROS 2
// node publishing geometry_msgs/msg/PoseWithCovarianceStamped on /rsu/<id>/fix reaches coloc with no
// bridge. No Fast DDS type appears in this header.
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "coloc/core/time.hpp"
#include "coloc/rsu_client/rsu_fix.hpp"

namespace coloc::rsu_client {

/// DDS Security (PKI-DH authentication, access control, AES-GCM). Off must be said, never assumed.
struct SecurityConfig {
  bool enabled = false;
  std::string identity_ca;           ///< PEM of the CA that signs participant certificates
  std::string identity_certificate;  ///< this participant's certificate (PEM)
  std::string private_key;           ///< its key (PEM)
  std::string permissions_ca;        ///< PEM of the CA that signs governance and permissions
  std::string governance;            ///< signed governance document (S/MIME .p7s)
  std::string permissions;           ///< signed permissions document (S/MIME .p7s)
};

struct DdsConfig {
  int domain = 0;           ///< ROS_DOMAIN_ID
  bool reliable = false;    ///< false: ROS 2 sensor-data QoS (best effort)
  int depth = 5;            ///< keep-last depth
  /// false (default): Fast DDS's default transports, those a ROS 2 node on rmw_fastrtps uses:
  /// discovery by multicast (239.255.0.1, port 7400 + 250 x domain) and unicast on every interface,
  /// shared memory between processes of one host. A default-configured ROS 2 node (rmw_fastrtps or
  /// rmw_cyclonedds) finds coloc on the same host and across the vehicle network.
  /// true: UDP on 127.0.0.1 only, discovery by unicast to the peers there (ROS_LOCALHOST_ONLY=1):
  /// nothing leaves the machine, and it works in containers without shared memory.
  bool loopback_only = false;
  /// Shared memory between processes of one host, beside UDP, in both modes above (rmw_fastrtps adds it
  /// with ROS_LOCALHOST_ONLY too). Off for containers that share a network but not /dev/shm: Fast DDS
  /// would then find its peer on "the same host" and send it data it can never read.
  bool shared_memory = true;
  /// Each participant's shared-memory segment. Fast DDS's default (512 kB) is smaller than one scan of
  /// a 16-beam LiDAR (about 0.8 MB as PointCloud2): best-effort scans were dropped by the writer, 56 %
  /// of them at 1x. 32 MB holds about forty such scans in flight. Memory is taken only as it is used.
  std::uint32_t shm_segment_bytes = 32u << 20;
  /// UDP send and receive buffers of each socket: a scan arrives as about 13 fragments of 64 kB at once,
  /// which the kernel's default receive buffer (208 kB) cannot hold. The kernel caps the size at
  /// net.core.rmem_max / wmem_max (README: "No scan lost").
  std::uint32_t socket_buffer_bytes = 8u << 20;
  std::string participant_name = "coloc";
  SecurityConfig security;
};

/// The defaults a ROS 2 node takes from its environment: the domain from ROS_DOMAIN_ID (0-232; unset
/// or empty: 0) and loopback only when ROS_LOCALHOST_ONLY is 1. Throws coloc::Error naming the
/// variable and its value when it is malformed.
DdsConfig ddsConfigFromRosEnvironment();

/// The ROS topic an unaddressed fix of this RSU travels on (geometry_msgs/msg/PoseWithCovarianceStamped);
/// DDS adds the "rt" prefix. A vehicle refuses these unless rsu.accept_unaddressed says otherwise.
std::string fixTopic(const std::string& rsu_id);
/// The ROS topic of this RSU's fixes addressed to one vehicle each (nav_msgs/msg/Odometry, the
/// vehicle's station id in decimal as child_frame_id): see README, "The RSU fix protocol".
std::string addressedFixTopic(const std::string& rsu_id);
/// The RSU's own LiDAR frames (sensor_msgs/msg/PointCloud2, its sensor frame): what `coloc rsu-node`
/// takes in, "/rsu/<id>/points". A vehicle's pipeline never takes them for its own scans.
std::string roadsidePointsTopic(const std::string& rsu_id);
/// Where connected vehicles' CAMs come (coloc_msgs/msg/Cam, io/v2x_messages.hpp), as a V2X bridge
/// publishes them: "/v2x/cam".
inline constexpr const char* kCamTopic = "/v2x/cam";
inline constexpr const char* kVehicleDimensionsTopic = "/vehicle/dimensions";

struct VehicleDimensions {
  Stamp stamp = 0;
  std::uint32_t station_id = 0;
  double length = 0.0, width = 0.0;
  double reference_x = 0.0, reference_y = 0.0;
};

/// Nanoseconds since the Unix epoch on the system clock: the vehicle's "now" for received messages.
Stamp systemNow();

/// Samples a subscriber refused before they reached its callback, by reason. A bad sample is consumed
/// and counted; the subscriber goes on.
struct SampleCounters {
  std::uint64_t wrong_encapsulation = 0;  ///< not plain CDR (XCDR2 and others)
  std::uint64_t undecodable = 0;          ///< truncated, or not the topic's type
};

class FixSubscriber {
 public:
  /// Called on a DDS thread for every sample: the fix and its arrival time (systemNow()).
  using Callback = std::function<void(const RsuFix& fix, Stamp received)>;
  /// Subscribes to both fix topics (addressed and unaddressed) of each RSU id. Throws coloc::Error if DDS refuses (bad security
  /// files, ...), naming the reason.
  /// `on_refused` (optional) is called on a DDS thread with one line naming the topic and the reason
  /// for every sample refused before decoding (wrong encapsulation, undecodable).
  FixSubscriber(const DdsConfig& config, const std::vector<std::string>& rsu_ids, Callback callback,
                std::function<void(const std::string& line)> on_refused = {});
  ~FixSubscriber();
  /// Writers currently matched, over all RSU topics.
  int matchedPublishers() const;
  /// Samples refused before the callback (counted; `on_refused` of the constructor got a line each).
  SampleCounters sampleCounters() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

class FixPublisher {
 public:
  /// `addressed`: fixes go to one vehicle each (addressedFixTopic; every fix must carry its station
  /// id); otherwise the unaddressed topic of a setup with one connected vehicle.
  FixPublisher(const DdsConfig& config, const std::string& rsu_id, bool addressed = true);
  ~FixPublisher();
  /// Publishes with frame "map", the fix's x and y, its variance on x and y and +inf elsewhere (and,
  /// addressed, the station id as child_frame_id). Throws coloc::Error for an addressed publisher
  /// given a fix without a station id.
  void publish(const RsuFix& fix, double variance);
  /// Waits until at least `count` readers are matched; false on timeout.
  bool waitForSubscribers(int count, std::chrono::milliseconds timeout);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

class DimensionsPublisher {
 public:
  explicit DimensionsPublisher(const DdsConfig& config);
  ~DimensionsPublisher();
  void publish(const VehicleDimensions& dimensions);
  bool waitForSubscribers(int count, std::chrono::milliseconds timeout);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

class DimensionsSubscriber {
 public:
  using Callback = std::function<void(const VehicleDimensions&)>;
  DimensionsSubscriber(const DdsConfig& config, Callback callback, std::function<void(const std::string& line)> on_refused = {});
  ~DimensionsSubscriber();
  int matchedPublishers() const;
  SampleCounters sampleCounters() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace coloc::rsu_client
