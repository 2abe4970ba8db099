#include <gtest/gtest.h>

#include <cmath>

#include "coloc/core/types.hpp"

namespace coloc {
namespace {

TEST(Time, FormatSecondsKeepsAllNineDecimalsOfEpochStamps) {
  EXPECT_EQ(formatSeconds(1778234353'380000001LL), "1778234353.380000001");
  EXPECT_EQ(formatSeconds(-1'500'000'000LL), "-1.500000000");
  EXPECT_EQ(formatSeconds(0), "0.000000000");
}

TEST(Time, RosTimeAndSecondsConvertExactly) {
  EXPECT_EQ(fromRosTime(924, 102000000u), 924'102'000'000LL);
  EXPECT_EQ(fromSeconds(0.02), 20'000'000LL);
  EXPECT_DOUBLE_EQ(toSeconds(1'500'000'000LL), 1.5);
}

TEST(Angles, WrapAngleMapsIntoHalfOpenInterval) {
  EXPECT_DOUBLE_EQ(wrapAngle(M_PI), M_PI);
  EXPECT_DOUBLE_EQ(wrapAngle(-M_PI), M_PI);
  EXPECT_NEAR(wrapAngle(3 * M_PI + 0.1), -M_PI + 0.1, 1e-12);
  EXPECT_NEAR(wrapAngle(-7.0), -7.0 + 2 * M_PI, 1e-12);
  EXPECT_EQ(wrapAngle(0.3), 0.3);
}

TEST(Angles, RollPitchYawRoundTripsThroughQuaternion) {
  for (double roll : {-0.4, 0.0, 0.3})
    for (double pitch : {-1.2, 0.0, 0.5})
      for (double yaw : {-3.0, -0.2, 0.0, 1.7, 3.1}) {
        const Eigen::Vector3d rpy = rollPitchYaw(quaternionFromRollPitchYaw(roll, pitch, yaw));
        EXPECT_NEAR(rpy.x(), roll, 1e-12);
        EXPECT_NEAR(rpy.y(), pitch, 1e-12);
        EXPECT_NEAR(rpy.z(), yaw, 1e-12);
      }
}

}  // namespace
}  // namespace coloc
