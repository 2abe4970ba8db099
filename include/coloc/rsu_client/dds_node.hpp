#pragma once
// A DDS participant that moves ROS 2 messages as serialized CDR, whatever their type, the way ROS 2
// puts them on the wire: topic "rt" + ROS name, type "pkg::msg::dds_::Name_". The bytes are exactly
// what rosbag2 records (encapsulation header first), so a recorded log can be published as it is and a
// received sample decoded by coloc's own codecs. No Fast DDS type appears in this header.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "coloc/core/time.hpp"
#include "coloc/rsu_client/dds_transport.hpp"

namespace coloc::rsu_client {

/// "sensor_msgs/msg/PointCloud2" -> "sensor_msgs::msg::dds_::PointCloud2_", as rmw_fastrtps names types.
std::string ddsTypeName(const std::string& ros_type);
/// "sensor_msgs::msg::dds_::PointCloud2_" -> "sensor_msgs/msg/PointCloud2"; empty for a name not in that form.
std::string rosTypeName(const std::string& dds_type);
/// "std_srvs/srv/SetBool" -> "std_srvs::srv::dds_::SetBool_Request_" and "..._Response_".
std::string ddsRequestTypeName(const std::string& ros_srv_type);
std::string ddsResponseTypeName(const std::string& ros_srv_type);
/// "/a/b" -> "rq/a/bRequest" and "rr/a/bReply", as rmw_fastrtps names a service's topics.
std::string ddsRequestTopicName(const std::string& ros_service);
std::string ddsReplyTopicName(const std::string& ros_service);

struct TopicQos {
  bool reliable = false;          ///< false: best effort (ROS 2 sensor data)
  int depth = 5;                  ///< keep-last depth
  bool transient_local = false;   ///< late joiners get the last samples (ROS 2 /tf_static, maps)
};

class DdsNode {
 public:
  /// Throws coloc::Error if DDS refuses the participant (bad security files, ...).
  explicit DdsNode(const DdsConfig& config);
  ~DdsNode();
  DdsNode(const DdsNode&) = delete;
  DdsNode& operator=(const DdsNode&) = delete;

  class Writer {
   public:
    /// Writes one serialized message (CDR with its 4-byte encapsulation header). False if DDS refused.
    bool write(const std::uint8_t* data, std::size_t size);
    /// The same without a copy: the vector is the sample.
    bool write(const std::vector<std::uint8_t>& bytes);
    int matchedReaders() const;
    /// Reliable writers: waits until every matched reader acknowledged what was written (or the
    /// timeout passes; false then). A writer deleted earlier takes unacknowledged samples with it.
    bool waitForAcknowledgments(double timeout_seconds);

   private:
    friend class DdsNode;
    struct Impl;
    std::shared_ptr<Impl> impl_;
  };

  /// A writer on a ROS topic of a ROS type. Throws coloc::Error if DDS refuses it.
  Writer advertise(const std::string& ros_topic, const std::string& ros_type, const TopicQos& qos);

  /// Called on a DDS thread with each sample's bytes and its arrival (systemNow()). The callback must
  /// not throw; whatever it cannot use it counts.
  using Callback = std::function<void(std::vector<std::uint8_t>&& bytes, Stamp received)>;
  /// Subscribes to a ROS topic of a ROS type. Throws coloc::Error if DDS refuses.
  void subscribe(const std::string& ros_topic, const std::string& ros_type, const TopicQos& qos, Callback callback);

  /// Remote writers currently matched with this node's readers, all topics together.
  int matchedWriters() const;

  /// What one reader has seen, counted as DDS sees it: a loss anywhere between a writer's write and
  /// this node's callback (a dropped fragment, a full socket or shared-memory buffer, a sample
  /// replaced in a keep-last history before it was taken) shows as a gap in the writer's sequence
  /// numbers.
  struct ReaderStatus {
    std::string topic, type;          ///< ROS names
    int matched_writers = 0;
    std::uint64_t samples = 0;        ///< taken with data, handed to the callback
    std::uint64_t sequence_gaps = 0;  ///< samples a matched writer sent that never arrived
    std::uint64_t lost = 0;           ///< DDS's sample-lost status
    std::uint64_t rejected = 0;       ///< DDS's sample-rejected status (resource limits)
  };
  /// One entry per subscribe(), in order.
  std::vector<ReaderStatus> readers() const;

  // ROS 2 services as rmw_fastrtps puts them on DDS: requests on "rq" + service + "Request" of type
  // "pkg::srv::dds_::Name_Request_", replies on "rr" + service + "Reply" of type "..._Response_", both
  // reliable, volatile, keep last 10. A reply names its request by the related sample identity: the
  // client's reply reader (or, from a client that sends none, its request writer) and the request's
  // sequence number. A ROS 2 client on rmw_fastrtps calls coloc's services and coloc calls its.

  /// Hands the reply to its client; callable once, from any thread, at any later time.
  using Respond = std::function<void(std::vector<std::uint8_t>&& reply)>;
  /// Called on a DDS thread with each request (CDR bytes); must not throw nor block for long: a
  /// request that takes time is answered later through `respond`.
  using ServiceHandler = std::function<void(std::vector<std::uint8_t>&& request, Respond respond)>;
  /// Serves a ROS service (e.g. "/localization/pose_estimator/trigger_node") of a ROS srv type
  /// ("std_srvs/srv/SetBool"). Throws coloc::Error if DDS refuses.
  void serve(const std::string& ros_service, const std::string& ros_srv_type, ServiceHandler handler);

  class Client {
   public:
    /// Whether a server's request reader and reply writer are both matched.
    bool serverReady() const;
    bool waitForServer(double timeout_seconds) const;
    /// Sends a request and waits for its reply; nullopt if none came in time.
    std::optional<std::vector<std::uint8_t>> call(const std::vector<std::uint8_t>& request, double timeout_seconds);

   private:
    friend class DdsNode;
    struct Impl;
    std::shared_ptr<Impl> impl_;
  };
  /// A client of a ROS service. Throws coloc::Error if DDS refuses.
  Client client(const std::string& ros_service, const std::string& ros_srv_type);

  /// A remote writer of a ROS topic ("rt/..."), as discovery reports it: its ROS name and type.
  struct DiscoveredWriter {
    std::string topic, type;
  };
  /// The remote writers discovered since the last call, each topic and type once: what the domain
  /// publishes, for a node that subscribes by type as `coloc fuse` plans a log's topics.
  std::vector<DiscoveredWriter> takeDiscoveredWriters();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace coloc::rsu_client
