// Publisher and subscriber in one process, over UDP on loopback, with the ROS 2 names and types.
#include <fastrtps/xmlparser/XMLProfileManager.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cstring>
#include <mutex>
#include <thread>
#include <vector>

#include "coloc/rsu_client/dds_node.hpp"
#include "coloc/rsu_client/dds_transport.hpp"

namespace coloc::rsu_client {
namespace {

DdsConfig testConfig(int domain) {
  DdsConfig c;
  c.domain = domain;  // a domain of its own so that other tests' participants do not match
  c.reliable = true;  // one process, no loss expected: make the count exact
  c.loopback_only = true;  // a unit test talks to nothing beyond 127.0.0.1
  return c;
}

template <typename Predicate>
bool waitUntil(Predicate p, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!p()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

TEST(DdsLoopback, FixesArriveOnTheirRsuTopicWithStampAndPosition) {
  std::mutex mutex;
  std::vector<RsuFix> received;
  FixSubscriber subscriber(testConfig(71), {"rsu_a", "rsu_b"}, [&](const RsuFix& fix, Stamp) {
    std::lock_guard<std::mutex> lock(mutex);
    received.push_back(fix);
  });
  FixPublisher publisher(testConfig(71), "rsu_b");
  ASSERT_TRUE(publisher.waitForSubscribers(1, std::chrono::seconds(10)));
  const Stamp t0 = systemNow();
  for (int i = 0; i < 5; ++i) publisher.publish({t0 + i * 100'000'000LL, "rsu_b", 200.0 + i, 6.0, std::nullopt, std::nullopt, 1000u + i}, 0.00681);
  ASSERT_TRUE(waitUntil([&] { std::lock_guard<std::mutex> l(mutex); return received.size() == 5; }, std::chrono::seconds(10)));
  std::lock_guard<std::mutex> lock(mutex);
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(received[i].rsu_id, "rsu_b");  // from the topic it came on
    EXPECT_EQ(received[i].stamp, t0 + i * 100'000'000LL);
    EXPECT_EQ(received[i].x, 200.0 + i);
    EXPECT_FALSE(received[i].yaw.has_value());  // sent with +inf yaw variance: no yaw
    ASSERT_TRUE(received[i].sent && received[i].sent->child_frame_id);  // on the addressed topic
    EXPECT_EQ(*received[i].sent->child_frame_id, std::to_string(1000 + i));
    EXPECT_EQ(received[i].station_id, 1000u + i);  // to the vehicle it names
  }
}

TEST(DdsLoopback, UnaddressedFixesArriveOnTheirOwnTopicNamingNoVehicle) {
  std::mutex mutex;
  std::vector<RsuFix> received;
  FixSubscriber subscriber(testConfig(72), {"rsu_a"}, [&](const RsuFix& fix, Stamp) {
    std::lock_guard<std::mutex> lock(mutex);
    received.push_back(fix);
  });
  FixPublisher publisher(testConfig(72), "rsu_a", false);
  ASSERT_TRUE(publisher.waitForSubscribers(1, std::chrono::seconds(10)));
  publisher.publish({systemNow(), "rsu_a", 12.0, 3.0, std::nullopt, std::nullopt, std::nullopt}, 0.00681);
  ASSERT_TRUE(waitUntil([&] { std::lock_guard<std::mutex> l(mutex); return received.size() == 1; }, std::chrono::seconds(10)));
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_FALSE(received[0].station_id.has_value());
  EXPECT_FALSE(received[0].sent->child_frame_id.has_value());
}

TEST(DdsLoopback, AnUndecodableFixSampleIsCountedAndTheListenerGoesOn) {
  // Any participant may write on the topic: an XCDR2 sample (Fast DDS 2.9's generated code throws on
  // it) and a truncated one, then a good fix.
  std::mutex mutex;
  std::vector<RsuFix> received;
  std::vector<std::string> refused;
  FixSubscriber subscriber(
      testConfig(73), {"rsu_a"},
      [&](const RsuFix& fix, Stamp) {
        std::lock_guard<std::mutex> lock(mutex);
        received.push_back(fix);
      },
      [&](const std::string& line) {
        std::lock_guard<std::mutex> lock(mutex);
        refused.push_back(line);
      });
  DdsNode intruder(testConfig(73));
  TopicQos qos;
  qos.reliable = true;
  DdsNode::Writer raw = intruder.advertise(fixTopic("rsu_a"), "geometry_msgs/msg/PoseWithCovarianceStamped", qos);
  ASSERT_TRUE(waitUntil([&] { return raw.matchedReaders() >= 1; }, std::chrono::seconds(10)));
  std::vector<std::uint8_t> xcdr2(64, 0);
  xcdr2[1] = 0x07;
  ASSERT_TRUE(raw.write(xcdr2));
  ASSERT_TRUE(raw.write(std::vector<std::uint8_t>{0x00, 0x01, 0x00, 0x00, 0x10, 0x00}));
  ASSERT_TRUE(waitUntil([&] { const SampleCounters c = subscriber.sampleCounters(); return c.wrong_encapsulation + c.undecodable >= 2; },
                        std::chrono::seconds(10)));
  FixPublisher publisher(testConfig(73), "rsu_a", false);
  ASSERT_TRUE(publisher.waitForSubscribers(1, std::chrono::seconds(10)));
  publisher.publish({systemNow(), "rsu_a", 12.0, 3.0, std::nullopt, std::nullopt, std::nullopt}, 0.00681);
  ASSERT_TRUE(waitUntil([&] { std::lock_guard<std::mutex> l(mutex); return received.size() == 1; }, std::chrono::seconds(10)));
  const SampleCounters c = subscriber.sampleCounters();
  EXPECT_EQ(c.wrong_encapsulation, 1u);
  EXPECT_EQ(c.undecodable, 1u);
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_EQ(received[0].x, 12.0);
  ASSERT_EQ(refused.size(), 2u);
  EXPECT_NE(refused[0].find("encapsulation 0x0007"), std::string::npos) << refused[0];
}

TEST(DdsLoopback, VehicleDimensionsReachTheRsu) {
  std::atomic<bool> got{false};
  VehicleDimensions seen;
  DimensionsSubscriber subscriber(testConfig(72), [&](const VehicleDimensions& d) {
    seen = d;
    got = true;
  });
  DimensionsPublisher publisher(testConfig(72));
  ASSERT_TRUE(publisher.waitForSubscribers(1, std::chrono::seconds(10)));
  publisher.publish({systemNow(), 42, 4.8, 1.9, 1.2, 0.0});
  ASSERT_TRUE(waitUntil([&] { return got.load(); }, std::chrono::seconds(10)));
  EXPECT_EQ(seen.station_id, 42u);
  EXPECT_EQ(seen.length, 4.8);
  EXPECT_EQ(seen.width, 1.9);
  EXPECT_EQ(seen.reference_x, 1.2);
}

// Large best-effort samples through UDP with small socket buffers and no shared memory: fragments are
// dropped. Whatever did not arrive between the first and the last sample taken must be counted as a
// gap in the writer's sequence numbers, exactly.
TEST(DdsLoopback, EverySampleLostBetweenTwoTakenIsCountedAsASequenceGap) {
  // Two participants of one process would otherwise hand samples over in memory, losing none.
  using eprosima::fastrtps::xmlparser::XMLProfileManager;
  const eprosima::fastrtps::LibrarySettingsAttributes before = XMLProfileManager::library_settings();
  eprosima::fastrtps::LibrarySettingsAttributes off = before;
  off.intraprocess_delivery = eprosima::fastrtps::INTRAPROCESS_OFF;
  XMLProfileManager::library_settings(off);
  struct Restore {
    eprosima::fastrtps::LibrarySettingsAttributes settings;
    ~Restore() { eprosima::fastrtps::xmlparser::XMLProfileManager::library_settings(settings); }
  } restore{before};
  DdsConfig config = testConfig(74);
  config.shared_memory = false;
  config.socket_buffer_bytes = 128 * 1024;
  DdsNode reader_node(config), writer_node(config);
  TopicQos qos;
  qos.reliable = false;
  qos.depth = 5;
  std::mutex mutex;
  std::vector<std::uint32_t> indices;  // of the samples taken, from their payload
  reader_node.subscribe("/big", "sensor_msgs/msg/PointCloud2", qos, [&](std::vector<std::uint8_t>&& bytes, Stamp) {
    std::uint32_t index = 0;
    std::memcpy(&index, bytes.data() + 4, sizeof index);
    std::lock_guard<std::mutex> lock(mutex);
    indices.push_back(index);
  });
  DdsNode::Writer writer = writer_node.advertise("/big", "sensor_msgs/msg/PointCloud2", qos);
  ASSERT_TRUE(waitUntil([&] { return writer.matchedReaders() == 1 && reader_node.readers()[0].matched_writers == 1; },
                        std::chrono::seconds(10)));
  const int kSamples = 60;
  std::vector<std::uint8_t> sample(1 << 20, 0x5a);
  sample[0] = 0, sample[1] = 1, sample[2] = 0, sample[3] = 0;
  for (std::uint32_t i = 0; i < kSamples; ++i) {
    std::memcpy(sample.data() + 4, &i, sizeof i);
    writer.write(sample);
  }
  // The last sample is small and sent after a pause: it arrives, so every loss lies between two taken.
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  std::vector<std::uint8_t> last(64, 0);
  last[1] = 1;
  const std::uint32_t final_index = kSamples;
  std::memcpy(last.data() + 4, &final_index, sizeof final_index);
  writer.write(last);
  ASSERT_TRUE(waitUntil([&] { std::lock_guard<std::mutex> l(mutex); return !indices.empty() && indices.back() == final_index; },
                        std::chrono::seconds(10)));
  const DdsNode::ReaderStatus status = reader_node.readers()[0];
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_EQ(status.topic, "/big");
  EXPECT_EQ(status.samples, indices.size());
  const std::uint64_t span = indices.back() - indices.front() + 1;
  EXPECT_EQ(status.sequence_gaps, span - indices.size()) << indices.size() << " of " << span << " samples taken";
  EXPECT_LT(indices.size(), static_cast<std::size_t>(kSamples)) << "nothing was lost: the test no longer forces a loss";
}

// A service as rmw_fastrtps puts it on DDS: the client's request, the server's reply tied to it by the
// related sample identity; two requests get their own replies, in the order asked.
TEST(DdsLoopback, AServiceAnswersEachRequestOfItsClient) {
  DdsNode server(testConfig(75)), caller(testConfig(75));
  server.serve("/test/echo", "std_srvs/srv/SetBool", [](std::vector<std::uint8_t>&& request, DdsNode::Respond respond) {
    std::vector<std::uint8_t> reply = request;
    reply.push_back(0x2a);
    respond(std::move(reply));
  });
  DdsNode::Client client = caller.client("/test/echo", "std_srvs/srv/SetBool");
  ASSERT_TRUE(client.waitForServer(10.0));
  const auto first = client.call({0, 1, 0, 0, 1}, 10.0);
  const auto second = client.call({0, 1, 0, 0, 0}, 10.0);
  ASSERT_TRUE(first && second);
  EXPECT_EQ(*first, (std::vector<std::uint8_t>{0, 1, 0, 0, 1, 0x2a}));
  EXPECT_EQ(*second, (std::vector<std::uint8_t>{0, 1, 0, 0, 0, 0x2a}));
  // A service nobody serves: no reply, within the time given.
  DdsNode::Client nobody = caller.client("/test/nobody", "std_srvs/srv/SetBool");
  EXPECT_FALSE(nobody.waitForServer(0.3));
  EXPECT_FALSE(nobody.call({0, 1, 0, 0, 1}, 0.3).has_value());
}

TEST(DdsTopics, FollowTheRos2NamingRules) {
  EXPECT_EQ(fixTopic("rsu_a"), "/rsu/rsu_a/fix");
  EXPECT_STREQ(kVehicleDimensionsTopic, "/vehicle/dimensions");
  EXPECT_EQ(rosTypeName("sensor_msgs::msg::dds_::PointCloud2_"), "sensor_msgs/msg/PointCloud2");
  EXPECT_EQ(rosTypeName("KeyedSeq"), "");
  EXPECT_EQ(ddsRequestTypeName("std_srvs/srv/SetBool"), "std_srvs::srv::dds_::SetBool_Request_");
  EXPECT_EQ(ddsResponseTypeName("std_srvs/srv/SetBool"), "std_srvs::srv::dds_::SetBool_Response_");
  EXPECT_EQ(ddsRequestTopicName("/localization/pose_estimator/trigger_node"), "rq/localization/pose_estimator/trigger_nodeRequest");
  EXPECT_EQ(ddsReplyTopicName("/localization/pose_estimator/trigger_node"), "rr/localization/pose_estimator/trigger_nodeReply");
}

}  // namespace
}  // namespace coloc::rsu_client
