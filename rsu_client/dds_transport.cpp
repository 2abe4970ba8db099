#include "coloc/rsu_client/dds_transport.hpp"

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>

#include <array>
#include <atomic>
#include <cmath>
#include <limits>
#include <thread>

#include "OdometryPubSubTypes.h"
#include "PoseWithCovarianceStampedPubSubTypes.h"
#include "VehicleDimensionsPubSubTypes.h"
#include "guarded_type.hpp"
#include "coloc/core/error.hpp"
#include "coloc/core/types.hpp"
#include "dds_participant.hpp"
#include "fix_sample.hpp"

namespace coloc::rsu_client {

namespace dds = eprosima::fastdds::dds;
using RosPose = geometry_msgs::msg::PoseWithCovarianceStamped;
using RosOdometry = nav_msgs::msg::Odometry;
using RosDimensions = coloc_msgs::msg::VehicleDimensions;

std::string fixTopic(const std::string& rsu_id) { return "/rsu/" + rsu_id + "/fix"; }
std::string addressedFixTopic(const std::string& rsu_id) { return "/rsu/" + rsu_id + "/addressed_fix"; }
std::string roadsidePointsTopic(const std::string& rsu_id) { return "/rsu/" + rsu_id + "/points"; }

Stamp systemNow() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
}

namespace {

// Readers and writers get the same QoS: ROS 2 sensor data by default (best effort, keep last 5,
// volatile), reliable on request.
template <typename Qos>
Qos withConfig(Qos q, const DdsConfig& c) {
  q.reliability().kind = c.reliable ? dds::RELIABLE_RELIABILITY_QOS : dds::BEST_EFFORT_RELIABILITY_QOS;
  q.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  q.history().depth = c.depth;
  q.durability().kind = dds::VOLATILE_DURABILITY_QOS;
  return q;
}

dds::DataReaderQos readerQos(const DdsConfig& c) { return withConfig(dds::DATAREADER_QOS_DEFAULT, c); }
dds::DataWriterQos writerQos(const DdsConfig& c) { return withConfig(dds::DATAWRITER_QOS_DEFAULT, c); }

void setStamp(std_msgs::msg::Header& header, Stamp stamp, const std::string& frame) {
  const RosTime time = toRosTime(stamp);
  if (!time.fits) throw Error("DDS: stamp " + formatSeconds(stamp) + " s does not fit builtin_interfaces/Time (int32 seconds)");
  header.stamp().sec(time.sec);
  header.stamp().nanosec(time.nanosec);
  header.frame_id(frame);
}

Stamp stampOf(const std_msgs::msg::Header& header) { return fromRosTime(header.stamp().sec(), header.stamp().nanosec()); }

// Counts matched remote endpoints so that callers can wait for discovery.
class MatchCounter : public dds::DataWriterListener {
 public:
  void on_publication_matched(dds::DataWriter*, const dds::PublicationMatchedStatus& status) override {
    matched = status.current_count;
  }
  std::atomic<int> matched{0};
};

bool waitFor(const std::atomic<int>& matched, int count, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (matched.load() < count) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

}  // namespace

// ---- fixes -------------------------------------------------------------------------------------

struct FixSubscriber::Impl : public dds::DataReaderListener {
  AtomicSampleCounters counters;
  std::function<void(const std::string&)> on_refused;
  dds::TypeSupport type{new GuardedType<geometry_msgs::msg::PoseWithCovarianceStampedPubSubType>("an RSU fix topic", &counters, &on_refused)};
  dds::TypeSupport addressed_type{new GuardedType<nav_msgs::msg::OdometryPubSubType>("an RSU addressed fix topic", &counters, &on_refused)};
  struct Reader {
    dds::DataReader* reader;
    std::string rsu_id;
    bool addressed;
  };
  std::vector<Reader> readers;
  Callback callback;
  std::atomic<int> matched{0};

  template <typename Message>
  void takeAll(dds::DataReader* reader, const std::string& rsu_id) {
    Message msg;
    dds::SampleInfo info;
    while (reader->take_next_sample(&msg, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      const Stamp received = systemNow();
      callback(fixFromSample(msg, rsu_id), received);
    }
  }
  void on_data_available(dds::DataReader* reader) override {
    for (const Reader& r : readers)
      if (r.reader == reader) return r.addressed ? takeAll<RosOdometry>(reader, r.rsu_id) : takeAll<RosPose>(reader, r.rsu_id);
  }
  void on_subscription_matched(dds::DataReader*, const dds::SubscriptionMatchedStatus& status) override {
    matched += status.current_count_change;
  }
  OwnedParticipant participant;  // last member: deleted first
};

FixSubscriber::FixSubscriber(const DdsConfig& config, const std::vector<std::string>& rsu_ids, Callback callback,
                             std::function<void(const std::string&)> on_refused)
    : impl_(std::make_unique<Impl>()) {
  impl_->callback = std::move(callback);
  impl_->on_refused = std::move(on_refused);
  impl_->participant = createParticipant(config);
  dds::Subscriber* subscriber = impl_->participant->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  if (!subscriber) throw Error("DDS: cannot create a subscriber");
  impl_->readers.reserve(2 * rsu_ids.size());
  for (const std::string& id : rsu_ids)
    for (const bool addressed : {true, false}) {
      const std::string name = addressed ? addressedFixTopic(id) : fixTopic(id);
      dds::Topic* topic = topicFor(impl_->participant, name, addressed ? impl_->addressed_type : impl_->type);
      // Readers are listed before they exist so that the listener never sees an unknown one.
      impl_->readers.push_back({nullptr, id, addressed});
      dds::DataReader* reader = subscriber->create_datareader(topic, readerQos(config), impl_.get());
      if (!reader) throw Error("DDS: cannot subscribe to " + ddsTopicName(name));
      impl_->readers.back().reader = reader;
    }
}

FixSubscriber::~FixSubscriber() = default;
int FixSubscriber::matchedPublishers() const { return impl_->matched.load(); }
SampleCounters FixSubscriber::sampleCounters() const { return impl_->counters.snapshot(); }

struct FixPublisher::Impl {
  dds::TypeSupport type{new geometry_msgs::msg::PoseWithCovarianceStampedPubSubType()};
  dds::TypeSupport addressed_type{new nav_msgs::msg::OdometryPubSubType()};
  dds::DataWriter* writer = nullptr;  ///< unaddressed fixes
  dds::DataWriter* addressed_writer = nullptr;
  MatchCounter listener, addressed_listener;
  OwnedParticipant participant;  // last member: deleted first
};

FixPublisher::FixPublisher(const DdsConfig& config, const std::string& rsu_id, bool addressed) : impl_(std::make_unique<Impl>()) {
  impl_->participant = createParticipant(config);
  dds::Publisher* publisher = impl_->participant->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  if (!publisher) throw Error("DDS: cannot create a publisher");
  const std::string name = addressed ? addressedFixTopic(rsu_id) : fixTopic(rsu_id);
  dds::Topic* topic = topicFor(impl_->participant, name, addressed ? impl_->addressed_type : impl_->type);
  dds::DataWriter*& writer = addressed ? impl_->addressed_writer : impl_->writer;
  writer = publisher->create_datawriter(topic, writerQos(config), addressed ? &impl_->addressed_listener : &impl_->listener);
  if (!writer) throw Error("DDS: cannot publish on " + ddsTopicName(name) + " (not permitted?)");
}

FixPublisher::~FixPublisher() = default;

void FixPublisher::publish(const RsuFix& fix, double variance) {
  geometry_msgs::msg::PoseWithCovariance pose;
  pose.pose().position().x(fix.x);
  pose.pose().position().y(fix.y);
  pose.pose().position().z(0.0);
  const double yaw = fix.yaw.value_or(0.0);
  pose.pose().orientation().z(std::sin(0.5 * yaw));
  pose.pose().orientation().w(std::cos(0.5 * yaw));
  std::array<double, 36> covariance{};
  covariance[0] = covariance[7] = variance;
  covariance[14] = covariance[21] = covariance[28] = covariance[35] = std::numeric_limits<double>::infinity();
  pose.covariance(covariance);
  if (impl_->addressed_writer) {
    if (!fix.station_id) throw Error("RSU fix: an addressed publisher needs the fix's station id");
    RosOdometry msg;
    setStamp(msg.header(), fix.stamp, "map");
    msg.child_frame_id(std::to_string(*fix.station_id));
    msg.pose(pose);
    // The twist is not part of a fix: zero, and its covariance says it is not measured.
    std::array<double, 36> unknown{};
    for (int i = 0; i < 6; ++i) unknown[7 * i] = -1.0;
    msg.twist().covariance(unknown);
    impl_->addressed_writer->write(&msg);
    return;
  }
  RosPose msg;
  setStamp(msg.header(), fix.stamp, "map");
  msg.pose(pose);
  impl_->writer->write(&msg);
}

bool FixPublisher::waitForSubscribers(int count, std::chrono::milliseconds timeout) {
  return waitFor(impl_->addressed_writer ? impl_->addressed_listener.matched : impl_->listener.matched, count, timeout);
}

// ---- vehicle dimensions ------------------------------------------------------------------------

struct DimensionsPublisher::Impl {
  dds::TypeSupport type{new coloc_msgs::msg::VehicleDimensionsPubSubType()};
  dds::DataWriter* writer = nullptr;
  MatchCounter listener;
  OwnedParticipant participant;  // last member: deleted first
};

DimensionsPublisher::DimensionsPublisher(const DdsConfig& config) : impl_(std::make_unique<Impl>()) {
  impl_->participant = createParticipant(config);
  dds::Publisher* publisher = impl_->participant->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  dds::Topic* topic = topicFor(impl_->participant, kVehicleDimensionsTopic, impl_->type);
  impl_->writer = publisher ? publisher->create_datawriter(topic, writerQos(config), &impl_->listener) : nullptr;
  if (!impl_->writer) throw Error(std::string("DDS: cannot publish on ") + ddsTopicName(kVehicleDimensionsTopic));
}

DimensionsPublisher::~DimensionsPublisher() = default;

void DimensionsPublisher::publish(const VehicleDimensions& d) {
  RosDimensions msg;
  setStamp(msg.header(), d.stamp, "base_link");
  msg.station_id(d.station_id);
  msg.length(d.length);
  msg.width(d.width);
  msg.reference_x(d.reference_x);
  msg.reference_y(d.reference_y);
  impl_->writer->write(&msg);
}

bool DimensionsPublisher::waitForSubscribers(int count, std::chrono::milliseconds timeout) {
  return waitFor(impl_->listener.matched, count, timeout);
}

struct DimensionsSubscriber::Impl : public dds::DataReaderListener {
  AtomicSampleCounters counters;
  std::function<void(const std::string&)> on_refused;
  dds::TypeSupport type{new GuardedType<coloc_msgs::msg::VehicleDimensionsPubSubType>(ddsTopicName(kVehicleDimensionsTopic), &counters, &on_refused)};
  Callback callback;
  std::atomic<int> matched{0};

  void on_data_available(dds::DataReader* reader) override {
    RosDimensions msg;
    dds::SampleInfo info;
    while (reader->take_next_sample(&msg, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      callback({stampOf(msg.header()), msg.station_id(), msg.length(), msg.width(), msg.reference_x(), msg.reference_y()});
    }
  }
  void on_subscription_matched(dds::DataReader*, const dds::SubscriptionMatchedStatus& status) override {
    matched += status.current_count_change;
  }
  OwnedParticipant participant;  // last member: deleted first
};

DimensionsSubscriber::DimensionsSubscriber(const DdsConfig& config, Callback callback, std::function<void(const std::string&)> on_refused)
    : impl_(std::make_unique<Impl>()) {
  impl_->callback = std::move(callback);
  impl_->on_refused = std::move(on_refused);
  impl_->participant = createParticipant(config);
  dds::Subscriber* subscriber = impl_->participant->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  dds::Topic* topic = topicFor(impl_->participant, kVehicleDimensionsTopic, impl_->type);
  if (!subscriber || !subscriber->create_datareader(topic, readerQos(config), impl_.get()))
    throw Error(std::string("DDS: cannot subscribe to ") + ddsTopicName(kVehicleDimensionsTopic));
}

DimensionsSubscriber::~DimensionsSubscriber() = default;
int DimensionsSubscriber::matchedPublishers() const { return impl_->matched.load(); }
SampleCounters DimensionsSubscriber::sampleCounters() const { return impl_->counters.snapshot(); }

}  // namespace coloc::rsu_client
