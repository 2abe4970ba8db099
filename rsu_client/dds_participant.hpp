#pragma once
// One Fast DDS participant set up as coloc needs it (transport, discovery, security), shared by the
// publishers and subscribers of rsu_client. Fast DDS headers stay in rsu_client's .cpp files.
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include <string>

#include "coloc/rsu_client/dds_transport.hpp"

namespace coloc::rsu_client {

/// Creates a participant or throws coloc::Error with the reason.
eprosima::fastdds::dds::DomainParticipant* createParticipant(const DdsConfig& config);
/// Deletes every entity of the participant, then the participant.
void destroyParticipant(eprosima::fastdds::dds::DomainParticipant* participant);
/// Owns a participant: deletes it with its entities when destroyed, so that an owner whose constructor
/// fails half-way does not leak it (Fast DDS would delete it at exit, where its teardown can stall).
/// Declare it as the owner's last member: it then goes first, while listeners and callbacks still exist.
class OwnedParticipant {
 public:
  OwnedParticipant() = default;
  ~OwnedParticipant() { destroyParticipant(participant_); }
  OwnedParticipant(const OwnedParticipant&) = delete;
  OwnedParticipant& operator=(const OwnedParticipant&) = delete;
  OwnedParticipant& operator=(eprosima::fastdds::dds::DomainParticipant* participant) {
    destroyParticipant(participant_);
    participant_ = participant;
    return *this;
  }
  eprosima::fastdds::dds::DomainParticipant* operator->() const { return participant_; }
  operator eprosima::fastdds::dds::DomainParticipant*() const { return participant_; }

 private:
  eprosima::fastdds::dds::DomainParticipant* participant_ = nullptr;
};

/// "/rsu/a/fix" -> "rt/rsu/a/fix", as rmw_fastrtps names ROS topics.
std::string ddsTopicName(const std::string& ros_topic);
/// Finds or creates the topic of a registered type.
eprosima::fastdds::dds::Topic* topicFor(eprosima::fastdds::dds::DomainParticipant* participant, const std::string& ros_topic,
                                        eprosima::fastdds::dds::TypeSupport& type);
/// The same by DDS topic name (a service's "rq..." and "rr..." topics).
eprosima::fastdds::dds::Topic* ddsTopicFor(eprosima::fastdds::dds::DomainParticipant* participant, const std::string& dds_topic,
                                           eprosima::fastdds::dds::TypeSupport& type);

}  // namespace coloc::rsu_client
