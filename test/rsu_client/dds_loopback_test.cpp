// Publisher and subscriber in one process, over UDP on loopback, with the ROS 2 names and types.
#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <thread>
#include <vector>

#include "coloc/rsu_client/dds_transport.hpp"

namespace coloc::rsu_client {
namespace {

DdsConfig testConfig(int domain) {
  DdsConfig c;
  c.domain = domain;  // a domain of its own so that other tests' participants do not match
  c.reliable = true;  // one process, no loss expected: make the count exact
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
  for (int i = 0; i < 5; ++i) publisher.publish({t0 + i * 100'000'000LL, "rsu_b", 200.0 + i, 6.0, std::nullopt}, 0.00681);
  ASSERT_TRUE(waitUntil([&] { std::lock_guard<std::mutex> l(mutex); return received.size() == 5; }, std::chrono::seconds(10)));
  std::lock_guard<std::mutex> lock(mutex);
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(received[i].rsu_id, "rsu_b");  // from the topic it came on
    EXPECT_EQ(received[i].stamp, t0 + i * 100'000'000LL);
    EXPECT_EQ(received[i].x, 200.0 + i);
    EXPECT_FALSE(received[i].yaw.has_value());  // sent with +inf yaw variance: no yaw
  }
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
