#include "coloc/io/trajectory_file.hpp"

#include <gtest/gtest.h>

#include <sstream>

#include "io_test_support.hpp"

namespace coloc::io {
namespace {

using testing::errorMessage;
using testing::ScratchDir;
using testing::writeText;

TrajectoryPoint point(Stamp stamp, double x, double y, double yaw) {
  TrajectoryPoint p;
  p.stamp = stamp;
  p.pose.position = {x, y, 0.0};
  p.pose.orientation = quaternionFromRollPitchYaw(0.0, 0.0, yaw);
  return p;
}

TEST(TrajectoryFile, TumLinesHoldEightFieldsWithNineDecimalStampsAndNoTrailingDelimiter) {
  std::ostringstream out;
  writeTumTrajectory(out, {point(1778234353'382747001LL, 4.3652, 7.5794, 0.0)}, "coloc fused\nsecond line");
  EXPECT_EQ(out.str(),
            "# coloc fused\n# second line\n"
            "1778234353.382747001 4.365200000 7.579400000 0.000000000 0.000000000 0.000000000 0.000000000 "
            "1.000000000\n");
}

TEST(TrajectoryFile, WriteThenReadKeepsStampsExactToTheNanosecond) {
  ScratchDir dir;
  const std::vector<TrajectoryPoint> points{point(1778234353'382747001LL, 4.3652, 7.5794, 0.1796),
                                            point(1778234353'999999999LL, -1.0, 2.5, -3.0),
                                            point(-1'500'000'000LL, 0.0, 0.0, 1.0), point(0, 1e6, -2e5, 3.14159)};
  writeTumTrajectory(dir / "traj.tum", points);
  const std::vector<TrajectoryPoint> read = readTumTrajectory(dir / "traj.tum");
  ASSERT_EQ(read.size(), points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(read[i].stamp, points[i].stamp);
    EXPECT_NEAR((read[i].pose.position - points[i].pose.position).norm(), 0.0, 1e-9);
    EXPECT_NEAR(read[i].pose.orientation.angularDistance(points[i].pose.orientation), 0.0, 1e-8);
  }
}

TEST(TrajectoryFile, AStreamedFileHoldsWhatWasAppendedAndIsReadableBeforeItIsClosed) {
  ScratchDir dir;
  std::vector<TrajectoryPoint> points;
  for (int i = 0; i < 7; ++i) points.push_back(point(1'700'000'000'000'000'000LL + i * 20'000'000LL, 0.5 * i, -0.1 * i, 0.01 * i));
  TumWriter writer(dir / "live.tum", "coloc fused trajectory (live)", 3);
  for (const auto& p : points) writer.append(p);
  // Flushed every third point: a reader (or a crash) sees at least the first six.
  EXPECT_GE(readTumTrajectory(dir / "live.tum").size(), 6u);
  writer.close();
  const std::vector<TrajectoryPoint> read = readTumTrajectory(dir / "live.tum");
  ASSERT_EQ(read.size(), points.size());
  EXPECT_EQ(writer.points(), points.size());
  for (std::size_t i = 0; i < points.size(); ++i) EXPECT_EQ(read[i].stamp, points[i].stamp);
  EXPECT_NE(errorMessage([&] { writer.append(points[0]); }).find("closed"), std::string::npos);
  EXPECT_NE(errorMessage([&] { TumWriter(dir / "no_such_folder/x.tum"); }).find("cannot create"), std::string::npos);
}

TEST(TrajectoryFile, ReadingAcceptsCommentsBlankLinesTabsAndWindowsLineEnds) {
  std::istringstream in(
      "# timestamp tx ty tz qx qy qz qw\n"
      "\n"
      "   # indented comment\n"
      "1.5\t1 2 3 0 0 0 1\r\n"
      "2 1 2 3 0 0 0.7071067811865476 0.7071067811865476\n"
      "3.0000000004 0 0 0 0 0 0 1\n"
      "4.0000000005 0 0 0 0 0 0 1\n"
      "1.2e1 0 0 0 0 0 0 1\n");
  const auto points = readTumTrajectory(in, "memory");
  ASSERT_EQ(points.size(), 5u);
  EXPECT_EQ(points[0].stamp, 1'500'000'000LL);
  EXPECT_EQ(points[0].pose.position, Eigen::Vector3d(1, 2, 3));
  EXPECT_NEAR(rollPitchYaw(points[1].pose.orientation).z(), M_PI / 2, 1e-12);
  EXPECT_EQ(points[2].stamp, 3'000'000'000LL);  // digits below a nanosecond round
  EXPECT_EQ(points[3].stamp, 4'000'000'001LL);
  EXPECT_EQ(points[4].stamp, 12'000'000'000LL);
}

TEST(TrajectoryFile, MalformedLinesAreRejectedWithFileAndLineNumber) {
  ScratchDir dir;
  const std::vector<std::pair<std::string, std::string>> cases{
      {"1 2 3 4 5 6 7", "expected 8 values \"t x y z qx qy qz qw\", found 7"},
      {"1 2 3 4 0 0 0 1 ", ""},  // a trailing blank is harmless when reading
      {"1 2 3 4 0 0 0 1 9", "found 9"},
      {"abc 2 3 4 0 0 0 1", "time stamp 'abc' is not a number of seconds"},
      {"1 2 nan 4 0 0 0 1", "y 'nan' is not a finite number"},
      {"1 2 3 4 0 0 0 1x", "qw '1x' is not a finite number"},
      {"1 2 3 4 0 0 0 0.5", "quaternion (qx qy qz qw) has norm 0.500000, not 1"},
      {"1,2,3,4,0,0,0,1", "found 1"},
  };
  for (const auto& [line, reason] : cases) {
    writeText(dir / "bad.tum", "# header\n0 0 0 0 0 0 0 1\n" + line + "\n");
    if (reason.empty()) {
      EXPECT_EQ(readTumTrajectory(dir / "bad.tum").size(), 2u) << line;
      continue;
    }
    const std::string message = errorMessage([&] { readTumTrajectory(dir / "bad.tum"); });
    EXPECT_EQ(message.rfind(dir / "bad.tum:3: ", 0), 0u) << line << ": " << message;
    EXPECT_NE(message.find(reason), std::string::npos) << line << ": " << message;
  }
}

TEST(TrajectoryFile, MissingFileIsReported) {
  EXPECT_NE(errorMessage([] { readTumTrajectory("/nonexistent/traj.tum"); }).find("/nonexistent/traj.tum: cannot open"),
            std::string::npos);
}

}  // namespace
}  // namespace coloc::io
