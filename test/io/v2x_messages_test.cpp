// coloc_msgs/msg/Cam, what the RSU node takes from connected vehicles: its wire layout, its reference
// point, and what a malformed or hostile one gets.
#include "coloc/io/v2x_messages.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "coloc/core/error.hpp"

namespace coloc::io {
namespace {

Cam sampleCam() {
  Cam c;
  c.header = {1'700'000'003'100'000'000LL, "map"};
  c.station_id = 1002;
  c.reference = {20.25, -1.5};
  c.heading = 0.5;
  c.speed = 8.0;
  c.yaw_rate = 0.01;
  c.length = 4.7;
  c.width = 1.9;
  return c;
}

std::string errorOf(const Bytes& b) {
  try {
    decodeCam(b.data(), b.size());
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(Cam, ReadsBackWhatWasWrittenWithTheLayoutOfItsMsg) {
  const Bytes b = encodeCam(sampleCam());
  // Encapsulation 4, stamp 8, frame_id "map" 4 + 4 (+ alignment 0), station id 4, then seven float64
  // aligned to 8 from the body's start.
  EXPECT_EQ(b.size(), 4u + 8 + 8 + 4 + 4 + 7 * 8);
  const Cam back = decodeCam(b.data(), b.size());
  EXPECT_EQ(back.header.stamp, sampleCam().header.stamp);
  EXPECT_EQ(back.header.frame_id, "map");
  EXPECT_EQ(back.station_id, 1002u);
  EXPECT_EQ(back.reference, sampleCam().reference);
  EXPECT_EQ(back.length, 4.7);
  EXPECT_EQ(back.width, 1.9);
}

TEST(Cam, TheReferencePointIsTheFrontCentreSoTheBodysCentreIsHalfALengthBehindIt) {
  const Cam c = sampleCam();
  const Eigen::Vector2d centre = c.centre();
  EXPECT_NEAR((c.reference - centre).norm(), 2.35, 1e-12);
  EXPECT_NEAR(std::atan2(c.reference.y() - centre.y(), c.reference.x() - centre.x()), 0.5, 1e-12);
}

TEST(Cam, ATruncatedNonFiniteOrSizelessCamIsRefusedNamingTheField) {
  Bytes b = encodeCam(sampleCam());
  EXPECT_NE(errorOf(Bytes(b.begin(), b.end() - 3)).find("coloc_msgs/msg/Cam"), std::string::npos);
  Cam nan = sampleCam();
  nan.speed = std::nan("");
  EXPECT_NE(errorOf(encodeCam(nan)).find("speed is not finite"), std::string::npos);
  Cam flat = sampleCam();
  flat.width = 0.0;
  EXPECT_NE(errorOf(encodeCam(flat)).find("length and width"), std::string::npos);
  Cam late = sampleCam();
  Bytes bad = encodeCam(late);
  const std::uint32_t nanosec = 1'500'000'000u;
  std::memcpy(&bad[8], &nanosec, 4);
  EXPECT_NE(errorOf(bad).find("nanosec"), std::string::npos);
}

}  // namespace
}  // namespace coloc::io
