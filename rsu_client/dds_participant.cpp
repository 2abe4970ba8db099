#include "dds_participant.hpp"

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>

#include <filesystem>

#include "coloc/core/error.hpp"

namespace coloc::rsu_client {

namespace dds = eprosima::fastdds::dds;

namespace {

std::string fileUri(const std::string& path, const char* what) {
  std::error_code ec;
  if (path.empty() || !std::filesystem::is_regular_file(path, ec))
    throw Error(std::string("DDS security: ") + what + " '" + path + "' is not a readable file");
  return "file://" + std::filesystem::absolute(path).string();
}

void addSecurity(dds::DomainParticipantQos& qos, const SecurityConfig& s) {
  auto& p = qos.properties().properties();
  p.emplace_back("dds.sec.auth.plugin", "builtin.PKI-DH");
  p.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_ca", fileUri(s.identity_ca, "identity CA"));
  p.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_certificate", fileUri(s.identity_certificate, "identity certificate"));
  p.emplace_back("dds.sec.auth.builtin.PKI-DH.private_key", fileUri(s.private_key, "private key"));
  p.emplace_back("dds.sec.access.plugin", "builtin.Access-Permissions");
  p.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions_ca", fileUri(s.permissions_ca, "permissions CA"));
  p.emplace_back("dds.sec.access.builtin.Access-Permissions.governance", fileUri(s.governance, "governance"));
  p.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions", fileUri(s.permissions, "permissions"));
  p.emplace_back("dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC");
}

}  // namespace

std::string ddsTopicName(const std::string& ros_topic) { return "rt" + ros_topic; }

dds::DomainParticipant* createParticipant(const DdsConfig& config) {
  dds::DomainParticipantQos qos = dds::PARTICIPANT_QOS_DEFAULT;
  qos.name(config.participant_name);
  // ROS 2 announces its enclave in the participant's user data; tools such as `ros2 node list` read it.
  const std::string enclave = "enclave=/;";
  qos.user_data().data_vec(std::vector<eprosima::fastrtps::rtps::octet>(enclave.begin(), enclave.end()));
  // The transports are given explicitly rather than Fast DDS's built-in ones, so that their buffers fit
  // point clouds (DdsConfig); they are the same kinds: shared memory on the host, UDP beyond it.
  qos.transport().use_builtin_transports = false;
  if (config.shared_memory) {
    auto shm = std::make_shared<eprosima::fastdds::rtps::SharedMemTransportDescriptor>();
    shm->segment_size(config.shm_segment_bytes);
    qos.transport().user_transports.push_back(shm);
  }
  auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  udp->sendBufferSize = config.socket_buffer_bytes;
  udp->receiveBufferSize = config.socket_buffer_bytes;
  qos.transport().user_transports.push_back(udp);
  if (config.loopback_only) {
    // Only loopback, and discovery by unicast to the peers on it: nothing leaves the machine, and it
    // works where multicast does not.
    udp->interfaceWhiteList.push_back("127.0.0.1");
    udp->maxInitialPeersRange = 32;  // Fast DDS reaches only 4 participants per peer by default
    eprosima::fastrtps::rtps::Locator_t peer;
    eprosima::fastrtps::rtps::IPLocator::setIPv4(peer, 127, 0, 0, 1);
    qos.wire_protocol().builtin.initialPeersList.push_back(peer);
    qos.wire_protocol().builtin.metatrafficMulticastLocatorList.clear();
    eprosima::fastrtps::rtps::Locator_t unicast;
    eprosima::fastrtps::rtps::IPLocator::setIPv4(unicast, 127, 0, 0, 1);
    qos.wire_protocol().builtin.metatrafficUnicastLocatorList.push_back(unicast);
    qos.wire_protocol().default_unicast_locator_list.push_back(unicast);
  }
  if (config.security.enabled) addSecurity(qos, config.security);
  dds::DomainParticipant* participant =
      dds::DomainParticipantFactory::get_instance()->create_participant(static_cast<dds::DomainId_t>(config.domain), qos);
  if (!participant)
    throw Error(std::string("DDS: cannot create the participant on domain ") + std::to_string(config.domain) +
                (config.security.enabled ? " (security on: check the certificates, key and signed documents)" : ""));
  return participant;
}

void destroyParticipant(dds::DomainParticipant* participant) {
  if (!participant) return;
  participant->delete_contained_entities();
  dds::DomainParticipantFactory::get_instance()->delete_participant(participant);
}

dds::Topic* topicFor(dds::DomainParticipant* participant, const std::string& ros_topic, dds::TypeSupport& type) {
  return ddsTopicFor(participant, ddsTopicName(ros_topic), type);
}

dds::Topic* ddsTopicFor(dds::DomainParticipant* participant, const std::string& name, dds::TypeSupport& type) {
  if (participant->find_type(type.get_type_name()) == nullptr) type.register_type(participant);
  if (dds::TopicDescription* existing = participant->lookup_topicdescription(name)) return static_cast<dds::Topic*>(existing);
  dds::Topic* topic = participant->create_topic(name, type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
  if (!topic) throw Error("DDS: cannot create topic " + name);
  return topic;
}

}  // namespace coloc::rsu_client
