// Whatever arrives over DDS, the live localizer keeps running: samples it cannot decode are counted
// against their topic with the reason, decodable but invalid ones are refused by the checks, and a
// good fix still gets through after the bad ones. Loopback only (127.0.0.1), a domain of its own.
#include "coloc/live/live_localizer.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <thread>
#include <vector>
#include <mutex>

#include "coloc/io/ros_messages.hpp"
#include "coloc/io/ros_node_interfaces.hpp"
#include "coloc/rsu_client/dds_node.hpp"

namespace coloc::live {
namespace {

const TopicStatus& topicOf(const LiveStatus& s, const std::string& name) {
  for (const TopicStatus& t : s.topics)
    if (t.topic == name) return t;
  throw std::runtime_error("no topic " + name);
}

io::Bytes fixMessage(Stamp stamp, double x, double y) {
  io::StampedPose m;
  m.header = {stamp, "map"};
  m.measurement.pose.position = {x, y, 0.0};
  m.measurement.covariance = Matrix6d::Zero();
  m.measurement.covariance.diagonal() << 0.00681, 0.00681, kInfinity, kInfinity, kInfinity, kInfinity;
  return io::encodePoseWithCovarianceStamped(m);
}

TEST(LiveLocalizer, MalformedAndInvalidSamplesAreCountedAndTheNodeKeepsRunning) {
  LiveOptions options;
  options.registry = rsu_client::RsuRegistry::parse("rsus:\n  - {id: rsu_a, position: [0, 0], lidar_model: VLP-32C}\n", "test");
  options.config.live.reliable = true;  // on loopback every loss would be coloc's
  options.config.rsu.checks.accept_unaddressed = true;  // the intruder writes on the unaddressed topic
  options.dds.domain = 79;
  options.dds.loopback_only = true;  // a unit test talks to nothing beyond 127.0.0.1
  LiveLocalizer localizer(options);

  rsu_client::DdsConfig dds;
  dds.domain = 79;
  dds.loopback_only = true;
  dds.participant_name = "intruder";
  rsu_client::DdsNode node(dds);
  rsu_client::TopicQos qos;
  qos.reliable = true;
  qos.depth = 50;
  auto fixes = node.advertise("/rsu/rsu_a/fix", "geometry_msgs/msg/PoseWithCovarianceStamped", qos);
  for (int i = 0; i < 500 && fixes.matchedReaders() < 1; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ASSERT_GE(fixes.matchedReaders(), 1) << "the localizer never matched on loopback";

  const Stamp now = rsu_client::systemNow();
  const io::Bytes good = fixMessage(now, 5.0, 1.0);
  io::Bytes xcdr2 = good;
  xcdr2[1] = 0x07;  // the encapsulation of XCDR2, which Fast DDS 2.9's generated code aborts on
  const io::Bytes truncated(good.begin(), good.begin() + 20);
  io::Bytes garbage(1024);
  for (std::size_t i = 0; i < garbage.size(); ++i) garbage[i] = static_cast<std::uint8_t>(i * 37 + 11);
  garbage[0] = 0x00, garbage[1] = 0x01;
  ASSERT_TRUE(fixes.write(xcdr2));
  ASSERT_TRUE(fixes.write(truncated));
  ASSERT_TRUE(fixes.write(garbage));
  ASSERT_TRUE(fixes.write(fixMessage(now, 500.0, 0.0)));  // decodes, but 500 m from the RSU
  ASSERT_TRUE(fixes.write(good));
  ASSERT_TRUE(fixes.waitForAcknowledgments(5.0));

  LiveStatus s;
  for (int i = 0; i < 500; ++i) {
    s = localizer.status();
    if (topicOf(s, "/rsu/rsu_a/fix").received >= 5 && s.report.fixes.count("rsu_a") && s.report.fixes.at("rsu_a").received >= 2) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const TopicStatus& t = topicOf(s, "/rsu/rsu_a/fix");
  EXPECT_EQ(t.received, 5u);
  EXPECT_EQ(t.undecodable, 3u);
  EXPECT_FALSE(t.first_error.empty());
  ASSERT_TRUE(s.report.fixes.count("rsu_a"));
  EXPECT_EQ(s.report.fixes.at("rsu_a").out_of_coverage, 1u);
  EXPECT_EQ(s.report.fixes.at("rsu_a").passed_checks, 1u);
  localizer.stop();
}

// Whoever calls the node's services may send anything: a truncated request, a pose of NaN, a flag that
// is not a boolean. Each gets a refusal as its reply, and the node goes on serving.
TEST(LiveLocalizer, MalformedServiceRequestsAreRefusedAndTheNodeGoesOnServing) {
  LiveOptions options;
  options.config.live.align_service = "/test/ndt_align_srv";
  options.config.live.ekf_trigger_service = "/test/trigger_node";
  options.dds.domain = 78;
  options.dds.loopback_only = true;
  std::vector<std::string> events;
  std::mutex mutex;
  options.on_event = [&](const std::string& line) {
    std::lock_guard<std::mutex> lock(mutex);
    events.push_back(line);
  };
  LiveLocalizer localizer(options);
  rsu_client::DdsConfig dds;
  dds.domain = 78;
  dds.loopback_only = true;
  dds.participant_name = "caller";
  rsu_client::DdsNode node(dds);
  auto align = node.client("/test/ndt_align_srv", io::kPoseAlignServiceType);
  auto trigger = node.client("/test/trigger_node", io::kSetBoolType);
  ASSERT_TRUE(align.waitForServer(10.0) && trigger.waitForServer(10.0));

  io::StampedPose nan;
  nan.header = {rsu_client::systemNow(), "map"};
  nan.measurement.pose.position = {std::nan(""), 0.0, 0.0};
  const io::Bytes whole = io::encodePoseAlignRequest(nan);
  for (const io::Bytes& request : {whole, io::Bytes(whole.begin(), whole.begin() + 30)}) {
    const auto reply = align.call(request, 10.0);
    ASSERT_TRUE(reply.has_value());
    EXPECT_FALSE(io::decodePoseAlignResponse(reply->data(), reply->size()).success);
  }
  const auto refused = trigger.call({0, 1, 0, 0, 7}, 10.0);
  ASSERT_TRUE(refused.has_value());
  EXPECT_FALSE(io::decodeSetBoolResponse(refused->data(), refused->size()).success);
  // A good request still gets its answer: without a map NDT cannot align, and says so.
  nan.measurement.pose.position.x() = 1.0;
  const auto reply = align.call(io::encodePoseAlignRequest(nan), 10.0);
  ASSERT_TRUE(reply.has_value());
  EXPECT_FALSE(io::decodePoseAlignResponse(reply->data(), reply->size()).success);
  const auto on = trigger.call(io::encodeSetBoolRequest(true), 10.0);
  ASSERT_TRUE(on.has_value());
  EXPECT_TRUE(io::decodeSetBoolResponse(on->data(), on->size()).success);
  localizer.stop();
  std::lock_guard<std::mutex> lock(mutex);
  int refusals = 0;
  for (const auto& e : events) refusals += e.find("request refused") != std::string::npos ? 1 : 0;
  EXPECT_EQ(refusals, 3) << "the NaN pose, the truncated request, the flag that is not a boolean";
}

}  // namespace
}  // namespace coloc::live
