// Publisher and subscriber in one process, over UDP on loopback, with the ROS 2 names and types.
#include <gtest/gtest.h>

#include <atomic>
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
  publisher.publish({systemNow(), "rsu_a", 12.0, 3.0, std::nullopt, std::nullopt}, 0.00681);
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
  publisher.publish({systemNow(), "rsu_a", 12.0, 3.0, std::nullopt, std::nullopt}, 0.00681);
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

TEST(DdsTopics, FollowTheRos2NamingRules) {
  EXPECT_EQ(fixTopic("rsu_a"), "/rsu/rsu_a/fix");
  EXPECT_STREQ(kVehicleDimensionsTopic, "/vehicle/dimensions");
}

}  // namespace
}  // namespace coloc::rsu_client
