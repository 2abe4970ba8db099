#include "coloc/rsu_client/dds_node.hpp"

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/dds/topic/TopicDataType.hpp>

#include <atomic>
#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "coloc/core/error.hpp"
#include "dds_participant.hpp"

namespace coloc::rsu_client {

namespace dds = eprosima::fastdds::dds;
using eprosima::fastrtps::rtps::SerializedPayload_t;

std::string ddsTypeName(const std::string& ros_type) {
  // pkg/msg/Name -> pkg::msg::dds_::Name_
  const auto last = ros_type.rfind('/');
  if (last == std::string::npos) return ros_type;
  std::string prefix = ros_type.substr(0, last);
  std::string out;
  for (char c : prefix) out += c == '/' ? std::string("::") : std::string(1, c);
  return out + "::dds_::" + ros_type.substr(last + 1) + "_";
}

std::string rosTypeName(const std::string& dds_type) {
  const std::string marker = "::dds_::";
  const auto at = dds_type.find(marker);
  if (at == std::string::npos || dds_type.size() < at + marker.size() + 2 || dds_type.back() != '_') return "";
  std::string out;
  const std::string prefix = dds_type.substr(0, at);
  for (std::size_t i = 0; i < prefix.size(); ++i) {
    if (prefix.compare(i, 2, "::") == 0) {
      out += '/';
      ++i;
    } else {
      out += prefix[i];
    }
  }
  return out + "/" + dds_type.substr(at + marker.size(), dds_type.size() - at - marker.size() - 1);
}

std::string ddsRequestTypeName(const std::string& ros_srv_type) {
  const std::string t = ddsTypeName(ros_srv_type);  // pkg::srv::dds_::Name_
  return t.substr(0, t.size() - 1) + "_Request_";
}
std::string ddsResponseTypeName(const std::string& ros_srv_type) {
  const std::string t = ddsTypeName(ros_srv_type);
  return t.substr(0, t.size() - 1) + "_Response_";
}
std::string ddsRequestTopicName(const std::string& ros_service) { return "rq" + ros_service + "Request"; }
std::string ddsReplyTopicName(const std::string& ros_service) { return "rr" + ros_service + "Reply"; }

namespace {

using Bytes = std::vector<std::uint8_t>;
using eprosima::fastrtps::rtps::GUID_t;

// A type that is its own serialization: the sample is the CDR bytes, encapsulation header included.
// DDS matches endpoints by type name, so this writer and reader pair with ROS 2's of the same type.
class SerializedType : public dds::TopicDataType {
 public:
  explicit SerializedType(const std::string& name) {
    setName(name.c_str());
    m_typeSize = 64 * 1024;  // a first allocation; larger samples grow the payload
    m_isGetKeyDefined = false;
  }
  bool serialize(void* data, SerializedPayload_t* payload) override {
    const Bytes& bytes = *static_cast<const Bytes*>(data);
    if (bytes.size() < 4 || payload->max_size < bytes.size()) return false;
    std::memcpy(payload->data, bytes.data(), bytes.size());
    payload->length = static_cast<std::uint32_t>(bytes.size());
    payload->encapsulation = (bytes[1] & 1) ? CDR_LE : CDR_BE;
    return true;
  }
  bool deserialize(SerializedPayload_t* payload, void* data) override {
    Bytes& bytes = *static_cast<Bytes*>(data);
    bytes.assign(payload->data, payload->data + payload->length);
    return true;
  }
  std::function<std::uint32_t()> getSerializedSizeProvider(void* data) override {
    return [data] { return static_cast<std::uint32_t>(static_cast<const Bytes*>(data)->size()); };
  }
  void* createData() override { return new Bytes(); }
  void deleteData(void* data) override { delete static_cast<Bytes*>(data); }
  bool getKey(void*, eprosima::fastrtps::rtps::InstanceHandle_t*, bool) override { return false; }
};

template <typename Qos>
Qos applied(Qos q, const TopicQos& t) {
  q.reliability().kind = t.reliable ? dds::RELIABLE_RELIABILITY_QOS : dds::BEST_EFFORT_RELIABILITY_QOS;
  q.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  q.history().depth = t.depth;
  q.durability().kind = t.transient_local ? dds::TRANSIENT_LOCAL_DURABILITY_QOS : dds::VOLATILE_DURABILITY_QOS;
  q.endpoint().history_memory_policy = eprosima::fastrtps::rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
  return q;
}

class WriterMatches : public dds::DataWriterListener {
 public:
  void on_publication_matched(dds::DataWriter*, const dds::PublicationMatchedStatus& status) override {
    matched = status.current_count;
    std::lock_guard<std::mutex> lock(mutex);
    const GUID_t reader = eprosima::fastrtps::rtps::iHandle2GUID(status.last_subscription_handle);
    if (status.current_count_change > 0) readers.push_back(reader);
    if (status.current_count_change < 0) readers.erase(std::remove(readers.begin(), readers.end(), reader), readers.end());
    changed.notify_all();
  }
  /// Waits until the reader is matched (a service's reply to a client whose reader is still being discovered).
  bool waitForReader(const GUID_t& reader, std::chrono::milliseconds timeout) {
    std::unique_lock<std::mutex> lock(mutex);
    return changed.wait_for(lock, timeout, [&] { return std::find(readers.begin(), readers.end(), reader) != readers.end(); });
  }
  std::atomic<int> matched{0};

 private:
  std::mutex mutex;
  std::condition_variable changed;
  std::vector<GUID_t> readers;
};

class ReaderMatches : public dds::DataReaderListener {
 public:
  void on_subscription_matched(dds::DataReader*, const dds::SubscriptionMatchedStatus& status) override { matched = status.current_count; }
  std::atomic<int> matched{0};
};

template <typename Qos>
Qos serviceQos(Qos q) {
  TopicQos t;
  t.reliable = true;  // rmw_qos_profile_services_default: reliable, volatile, keep last 10
  t.depth = 10;
  return applied(q, t);
}

}  // namespace

struct DdsNode::Writer::Impl {
  dds::DataWriter* writer = nullptr;
  WriterMatches listener;
  std::mutex mutex;  // DataWriter::write is thread-safe; the staging copy of a raw buffer is not
  Bytes staging;
};

bool DdsNode::Writer::write(const std::uint8_t* data, std::size_t size) {
  if (!impl_ || !impl_->writer) return false;
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->staging.assign(data, data + size);
  return impl_->writer->write(&impl_->staging);
}

bool DdsNode::Writer::waitForAcknowledgments(double timeout_seconds) {
  if (!impl_ || !impl_->writer) return false;
  const auto whole = static_cast<std::int32_t>(timeout_seconds);
  const auto nanos = static_cast<std::uint32_t>((timeout_seconds - whole) * 1e9);
  return impl_->writer->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(whole, nanos)) == ReturnCode_t::RETCODE_OK;
}

bool DdsNode::Writer::write(const std::vector<std::uint8_t>& bytes) {
  if (!impl_ || !impl_->writer) return false;
  // DataWriter::write takes a non-const pointer but only serializes from it (SerializedType copies out).
  return impl_->writer->write(const_cast<Bytes*>(&bytes));
}

int DdsNode::Writer::matchedReaders() const { return impl_ ? impl_->listener.matched.load() : 0; }

struct DdsNode::Impl : public dds::DataReaderListener {
  // One subscribed reader: its callback and what it has seen. The counters are written on DDS threads
  // and read by readers(), under `mutex`.
  struct Reader {
    ReaderStatus status;
    Callback callback;
    // The last sequence number taken from each matched writer (by its GUID), forgotten when it unmatches.
    std::map<eprosima::fastrtps::rtps::GUID_t, std::int64_t> last_sequence;
  };
  std::map<std::string, dds::TypeSupport> types;  // by DDS type name
  std::map<dds::DataReader*, Reader> readers;
  std::vector<dds::DataReader*> order;  // subscribe() order
  std::vector<std::shared_ptr<Writer::Impl>> writers;
  dds::Publisher* publisher = nullptr;
  dds::Subscriber* subscriber = nullptr;
  // Two locks, never held together: `setup` orders the creation of entities; `mutex` guards the maps
  // and counters the listeners read. Fast DDS calls listeners while holding its own locks, and takes
  // those locks when creating entities: creating under `mutex` would deadlock with a listener.
  std::mutex setup;
  mutable std::mutex mutex;

  dds::Topic* topic(const std::string& ros_topic, const std::string& ros_type) {
    const std::string type_name = ddsTypeName(ros_type);
    auto found = types.find(type_name);
    if (found == types.end()) found = types.emplace(type_name, dds::TypeSupport(new SerializedType(type_name))).first;
    dds::Topic* t = topicFor(participant, ros_topic, found->second);
    if (t->get_type_name() != type_name)
      throw Error("DDS: topic " + ddsTopicName(ros_topic) + " is already used with type " + t->get_type_name());
    return t;
  }

  Reader* find(dds::DataReader* reader) {
    const auto found = readers.find(reader);
    return found == readers.end() ? nullptr : &found->second;
  }

  void on_data_available(dds::DataReader* reader) override {
    Callback* callback = nullptr;
    Service* service = nullptr;
    {
      std::lock_guard<std::mutex> lock(mutex);
      if (Reader* r = find(reader)) callback = &r->callback;
      const auto found = services.find(reader);
      if (found != services.end()) service = &found->second;
    }
    if (service) return takeRequests(reader, *service);
    Bytes bytes;
    dds::SampleInfo info;
    while (reader->take_next_sample(&bytes, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data || !callback) continue;
      {
        std::lock_guard<std::mutex> lock(mutex);
        Reader& r = readers.at(reader);
        ++r.status.samples;
        const auto& id = info.sample_identity;
        const std::int64_t sequence = static_cast<std::int64_t>(id.sequence_number().to64long());
        auto [last, first] = r.last_sequence.emplace(id.writer_guid(), sequence);
        // Samples written before this reader matched are no loss: counting starts at the first taken.
        if (!first) {
          if (sequence > last->second + 1) r.status.sequence_gaps += static_cast<std::uint64_t>(sequence - last->second - 1);
          last->second = std::max(last->second, sequence);
        }
      }
      (*callback)(std::move(bytes), systemNow());
      bytes = Bytes();
    }
  }
  void on_subscription_matched(dds::DataReader* reader, const dds::SubscriptionMatchedStatus& status) override {
    std::lock_guard<std::mutex> lock(mutex);
    if (Reader* r = find(reader)) {
      r->status.matched_writers = status.current_count;
      if (status.current_count_change < 0) r->last_sequence.erase(eprosima::fastrtps::rtps::iHandle2GUID(status.last_publication_handle));
    }
  }
  void on_sample_lost(dds::DataReader* reader, const dds::SampleLostStatus& status) override {
    std::lock_guard<std::mutex> lock(mutex);
    if (Reader* r = find(reader)) r->status.lost += static_cast<std::uint64_t>(std::max(0, status.total_count_change));
  }
  void on_sample_rejected(dds::DataReader* reader, const dds::SampleRejectedStatus& status) override {
    std::lock_guard<std::mutex> lock(mutex);
    if (Reader* r = find(reader)) r->status.rejected += status.total_count_change;
  }
  // One served service: its request reader's handler and its reply writer.
  struct Service {
    ServiceHandler handler;
    dds::DataWriter* reply_writer = nullptr;
    std::shared_ptr<WriterMatches> reply_matches;
  };
  std::map<dds::DataReader*, Service> services;
  std::vector<std::shared_ptr<Client::Impl>> clients;

  dds::Topic* serviceTopic(const std::string& dds_topic, const std::string& type_name) {
    auto found = types.find(type_name);
    if (found == types.end()) found = types.emplace(type_name, dds::TypeSupport(new SerializedType(type_name))).first;
    dds::Topic* t = ddsTopicFor(participant, dds_topic, found->second);
    if (t->get_type_name() != type_name) throw Error("DDS: topic " + dds_topic + " is already used with type " + t->get_type_name());
    return t;
  }

  // A request taken: the reply goes to the client's reply reader named in the request (rmw_fastrtps's
  // clients name it), else to its request writer, with the request's sequence number.
  void takeRequests(dds::DataReader* reader, Service& service) {
    Bytes bytes;
    dds::SampleInfo info;
    while (reader->take_next_sample(&bytes, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      eprosima::fastrtps::rtps::SampleIdentity to = info.sample_identity;
      if (info.related_sample_identity.writer_guid() != GUID_t::unknown()) to.writer_guid(info.related_sample_identity.writer_guid());
      dds::DataWriter* writer = service.reply_writer;
      std::shared_ptr<WriterMatches> matches = service.reply_matches;
      Respond respond = [writer, matches, to](Bytes&& reply) {
        // A client's reply reader may not be matched yet when its first request arrives: a volatile
        // reply written before would be lost. rmw_fastrtps waits the same way (its writer's blocking time).
        const bool to_reader = (to.writer_guid().entityId.value[3] & 0x04) != 0;
        if (to_reader) matches->waitForReader(to.writer_guid(), std::chrono::seconds(2));
        eprosima::fastrtps::rtps::WriteParams params;
        params.related_sample_identity(to);
        writer->write(&reply, params);
      };
      service.handler(std::move(bytes), std::move(respond));
      bytes = Bytes();
    }
  }

  // Discovery of remote writers, reported on a DDS thread and kept until taken.
  struct Discovery : public dds::DomainParticipantListener {
    void on_publisher_discovery(dds::DomainParticipant*, eprosima::fastrtps::rtps::WriterDiscoveryInfo&& info) override {
      if (info.status != eprosima::fastrtps::rtps::WriterDiscoveryInfo::DISCOVERED_WRITER) return;
      const std::string topic = info.info.topicName().to_string(), type = info.info.typeName().to_string();
      if (topic.rfind("rt/", 0) != 0) return;  // services and non-ROS topics
      std::lock_guard<std::mutex> lock(mutex);
      if (seen.insert(topic + "\n" + type).second) fresh.push_back({topic.substr(2), rosTypeName(type)});
    }
    std::mutex mutex;
    std::set<std::string> seen;
    std::vector<DiscoveredWriter> fresh;
  };
  Discovery discovery;

  OwnedParticipant participant;  // last member: deleted first, while listeners still exist
};

std::vector<DdsNode::DiscoveredWriter> DdsNode::takeDiscoveredWriters() {
  std::lock_guard<std::mutex> lock(impl_->discovery.mutex);
  std::vector<DiscoveredWriter> out;
  out.swap(impl_->discovery.fresh);
  return out;
}

DdsNode::DdsNode(const DdsConfig& config) : impl_(std::make_unique<Impl>()) {
  impl_->participant = createParticipant(config);
  // Discovery only: every status stays with the entities' own listeners.
  impl_->participant->set_listener(&impl_->discovery, dds::StatusMask::none());
  impl_->publisher = impl_->participant->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  impl_->subscriber = impl_->participant->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  if (!impl_->publisher || !impl_->subscriber) throw Error("DDS: cannot create a publisher and a subscriber");
}

DdsNode::~DdsNode() = default;

DdsNode::Writer DdsNode::advertise(const std::string& ros_topic, const std::string& ros_type, const TopicQos& qos) {
  std::lock_guard<std::mutex> setup(impl_->setup);
  auto w = std::make_shared<Writer::Impl>();
  w->writer = impl_->publisher->create_datawriter(impl_->topic(ros_topic, ros_type), applied(dds::DATAWRITER_QOS_DEFAULT, qos), &w->listener);
  if (!w->writer) throw Error("DDS: cannot publish on " + ddsTopicName(ros_topic) + " (not permitted?)");
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    impl_->writers.push_back(w);
  }
  Writer writer;
  writer.impl_ = w;
  return writer;
}

void DdsNode::subscribe(const std::string& ros_topic, const std::string& ros_type, const TopicQos& qos, Callback callback) {
  std::lock_guard<std::mutex> setup(impl_->setup);
  dds::Topic* topic = impl_->topic(ros_topic, ros_type);
  // Created without a listener, registered, then given one: no sample can reach an unknown reader.
  dds::DataReader* reader = impl_->subscriber->create_datareader(topic, applied(dds::DATAREADER_QOS_DEFAULT, qos), nullptr);
  if (!reader) throw Error("DDS: cannot subscribe to " + ddsTopicName(ros_topic));
  Impl::Reader r;
  r.status.topic = ros_topic;
  r.status.type = ros_type;
  r.callback = std::move(callback);
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    impl_->readers.emplace(reader, std::move(r));
    impl_->order.push_back(reader);
  }
  reader->set_listener(impl_.get());
  // A writer may have matched before the listener was set: take the count as it stands.
  dds::SubscriptionMatchedStatus matched;
  if (reader->get_subscription_matched_status(matched) == ReturnCode_t::RETCODE_OK && matched.current_count > 0) {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    impl_->readers.at(reader).status.matched_writers = std::max(impl_->readers.at(reader).status.matched_writers, matched.current_count);
  }
}

int DdsNode::matchedWriters() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  int n = 0;
  for (const auto& [reader, r] : impl_->readers) n += r.status.matched_writers;
  return n;
}

std::vector<DdsNode::ReaderStatus> DdsNode::readers() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  std::vector<ReaderStatus> out;
  for (dds::DataReader* r : impl_->order) out.push_back(impl_->readers.at(r).status);
  return out;
}

void DdsNode::serve(const std::string& ros_service, const std::string& ros_srv_type, ServiceHandler handler) {
  std::lock_guard<std::mutex> setup(impl_->setup);
  dds::Topic* request_topic = impl_->serviceTopic(ddsRequestTopicName(ros_service), ddsRequestTypeName(ros_srv_type));
  dds::Topic* reply_topic = impl_->serviceTopic(ddsReplyTopicName(ros_service), ddsResponseTypeName(ros_srv_type));
  Impl::Service service;
  service.handler = std::move(handler);
  service.reply_matches = std::make_shared<WriterMatches>();
  service.reply_writer = impl_->publisher->create_datawriter(reply_topic, serviceQos(dds::DATAWRITER_QOS_DEFAULT), service.reply_matches.get());
  if (!service.reply_writer) throw Error("DDS: cannot serve " + ros_service + " (no reply writer; not permitted?)");
  dds::DataReader* reader = impl_->subscriber->create_datareader(request_topic, serviceQos(dds::DATAREADER_QOS_DEFAULT), nullptr);
  if (!reader) throw Error("DDS: cannot serve " + ros_service + " (no request reader; not permitted?)");
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    impl_->services.emplace(reader, std::move(service));
  }
  reader->set_listener(impl_.get());
}

struct DdsNode::Client::Impl {
  dds::DataWriter* request_writer = nullptr;
  dds::DataReader* reply_reader = nullptr;
  WriterMatches writer_matches;
  ReaderMatches reader_matches;
  std::mutex mutex;  // one call at a time
};

bool DdsNode::Client::serverReady() const {
  return impl_ && impl_->writer_matches.matched.load() > 0 && impl_->reader_matches.matched.load() > 0;
}

bool DdsNode::Client::waitForServer(double timeout_seconds) const {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_seconds);
  while (!serverReady()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return true;
}

std::optional<std::vector<std::uint8_t>> DdsNode::Client::call(const std::vector<std::uint8_t>& request, double timeout_seconds) {
  if (!impl_) return std::nullopt;
  std::lock_guard<std::mutex> lock(impl_->mutex);
  eprosima::fastrtps::rtps::WriteParams params;
  params.related_sample_identity().writer_guid(impl_->reply_reader->guid());  // where the server replies, as rmw_fastrtps's clients say
  if (!impl_->request_writer->write(const_cast<Bytes*>(&request), params)) return std::nullopt;
  const auto sequence = params.sample_identity().sequence_number();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_seconds);
  Bytes bytes;
  dds::SampleInfo info;
  while (std::chrono::steady_clock::now() < deadline) {
    while (impl_->reply_reader->take_next_sample(&bytes, &info) == ReturnCode_t::RETCODE_OK) {
      const auto& related = info.related_sample_identity;
      const bool ours = related.writer_guid() == impl_->reply_reader->guid() || related.writer_guid() == impl_->request_writer->guid();
      if (info.valid_data && ours && related.sequence_number() == sequence) return bytes;
    }
    impl_->reply_reader->wait_for_unread_message(eprosima::fastrtps::Duration_t(0, 50'000'000));
  }
  return std::nullopt;
}

DdsNode::Client DdsNode::client(const std::string& ros_service, const std::string& ros_srv_type) {
  std::lock_guard<std::mutex> setup(impl_->setup);
  dds::Topic* request_topic = impl_->serviceTopic(ddsRequestTopicName(ros_service), ddsRequestTypeName(ros_srv_type));
  dds::Topic* reply_topic = impl_->serviceTopic(ddsReplyTopicName(ros_service), ddsResponseTypeName(ros_srv_type));
  auto c = std::make_shared<Client::Impl>();
  c->request_writer = impl_->publisher->create_datawriter(request_topic, serviceQos(dds::DATAWRITER_QOS_DEFAULT), &c->writer_matches);
  c->reply_reader = impl_->subscriber->create_datareader(reply_topic, serviceQos(dds::DATAREADER_QOS_DEFAULT), &c->reader_matches);
  if (!c->request_writer || !c->reply_reader) throw Error("DDS: cannot call " + ros_service + " (not permitted?)");
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    impl_->clients.push_back(c);
  }
  Client client;
  client.impl_ = c;
  return client;
}

}  // namespace coloc::rsu_client
