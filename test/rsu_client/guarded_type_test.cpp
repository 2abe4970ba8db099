// A DDS sample that does not decode must be refused and counted, never thrown through the reader.
#include "guarded_type.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "PoseWithCovarianceStampedPubSubTypes.h"

namespace coloc::rsu_client {
namespace {

using Generated = geometry_msgs::msg::PoseWithCovarianceStampedPubSubType;

eprosima::fastrtps::rtps::SerializedPayload_t validPayload() {
  geometry_msgs::msg::PoseWithCovarianceStamped msg;
  msg.header().frame_id("map");
  msg.pose().pose().position().x(12.5);
  Generated type;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(&msg)());
  EXPECT_TRUE(type.serialize(&msg, &payload));
  return payload;
}

TEST(GuardedType, APlainCdrSampleDecodes) {
  AtomicSampleCounters counters;
  std::vector<std::string> lines;
  const std::function<void(const std::string&)> on_refused = [&](const std::string& l) { lines.push_back(l); };
  GuardedType<Generated> guarded("rt/rsu/a/fix", &counters, &on_refused);
  auto payload = validPayload();
  geometry_msgs::msg::PoseWithCovarianceStamped out;
  ASSERT_TRUE(guarded.deserialize(&payload, &out));
  EXPECT_EQ(out.pose().pose().position().x(), 12.5);
  EXPECT_EQ(counters.snapshot().undecodable + counters.snapshot().wrong_encapsulation, 0u);
  EXPECT_TRUE(lines.empty());
}

TEST(GuardedType, AnXcdr2SampleIsRefusedAndCountedNotThrown) {
  AtomicSampleCounters counters;
  std::vector<std::string> lines;
  const std::function<void(const std::string&)> on_refused = [&](const std::string& l) { lines.push_back(l); };
  GuardedType<Generated> guarded("rt/rsu/a/fix", &counters, &on_refused);
  auto payload = validPayload();
  payload.data[1] = 0x07;  // XCDR2 little-endian (D_CDR2_LE): Fast DDS 2.9's generated code throws on it
  geometry_msgs::msg::PoseWithCovarianceStamped out;
  EXPECT_FALSE(guarded.deserialize(&payload, &out));
  EXPECT_EQ(counters.snapshot().wrong_encapsulation, 1u);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find("rt/rsu/a/fix"), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find("0x0007"), std::string::npos) << lines[0];
}

TEST(GuardedType, TruncatedAndEmptySamplesAreRefusedAndCounted) {
  AtomicSampleCounters counters;
  GuardedType<Generated> guarded("rt/rsu/a/fix", &counters, nullptr);
  geometry_msgs::msg::PoseWithCovarianceStamped out;
  for (std::uint32_t keep : {30u, 12u, 3u, 0u}) {
    auto payload = validPayload();
    payload.length = keep;
    EXPECT_FALSE(guarded.deserialize(&payload, &out)) << keep << " bytes";
  }
  EXPECT_EQ(counters.snapshot().undecodable, 4u);
  EXPECT_FALSE(guarded.deserialize(nullptr, &out));
  EXPECT_EQ(counters.snapshot().undecodable, 5u);
}

}  // namespace
}  // namespace coloc::rsu_client
