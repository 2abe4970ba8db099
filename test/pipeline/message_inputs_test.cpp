// A driver's PointCloud2 as the pipeline's scan: finite points only, per-point time as seconds from the
// sweep's first point, whatever the field types, padding and row layout.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "coloc/core/error.hpp"
#include "coloc/pipeline/message_inputs.hpp"

namespace coloc::pipeline {
namespace {

struct Layout {
  std::uint8_t xyz_type, time_type;
  std::uint32_t point_step, row_padding;
};

template <typename T>
void put(std::vector<std::uint8_t>& data, std::size_t at, double v) {
  const T value = static_cast<T>(v);
  std::memcpy(&data[at], &value, sizeof value);
}

void putAs(std::vector<std::uint8_t>& data, std::size_t at, std::uint8_t type, double v) {
  switch (type) {
    case io::PointField::kFloat32: put<float>(data, at, v); break;
    case io::PointField::kFloat64: put<double>(data, at, v); break;
    case io::PointField::kUint32: put<std::uint32_t>(data, at, v); break;
    default: FAIL() << "type " << int(type);
  }
}

std::uint32_t sizeOf(std::uint8_t type) { return type == io::PointField::kFloat64 ? 8 : 4; }

// Two rows of three points; the second point of the first row is not finite. Times: 0.25 s + 10 ms per
// point (as nanoseconds for uint32).
io::PointCloud2 cloud(const Layout& l, const std::vector<Eigen::Vector3d>& points) {
  io::PointCloud2 m;
  m.height = 2;
  m.width = 3;
  const std::uint32_t s = sizeOf(l.xyz_type);
  m.fields = {{"x", 0, l.xyz_type, 1}, {"y", s, l.xyz_type, 1}, {"z", 2 * s, l.xyz_type, 1}, {"time", 3 * s, l.time_type, 1}};
  m.point_step = l.point_step;
  m.row_step = m.width * m.point_step + l.row_padding;
  m.data.assign(static_cast<std::size_t>(m.row_step) * m.height, 0xAB);  // padding bytes that are not zero
  for (std::uint32_t row = 0; row < 2; ++row)
    for (std::uint32_t col = 0; col < 3; ++col) {
      const std::size_t i = row * 3 + col, at = row * m.row_step + col * m.point_step;
      for (int a = 0; a < 3; ++a) putAs(m.data, at + a * s, l.xyz_type, points[i][a]);
      const double t = 0.25 + 0.01 * static_cast<double>(i);
      putAs(m.data, at + 3 * s, l.time_type, l.time_type == io::PointField::kUint32 ? t * 1e9 : t);
    }
  return m;
}

TEST(MessageInputs, PointCloud2GivesItsFinitePointsWithTimesFromTheFirstWhateverTheFieldTypesAndPadding) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<Eigen::Vector3d> points = {{1.5, -2.25, 0.125}, {nan, 1.0, 1.0}, {10.1, 20.2, -3.3},
                                               {-7.0, 0.1, 2.0},    {0.3, 0.7, 0.9},  {100.0, -100.0, 5.5}};
  for (const Layout& l : {Layout{io::PointField::kFloat32, io::PointField::kFloat32, 16, 0},   // the twin's and most drivers'
                          Layout{io::PointField::kFloat32, io::PointField::kFloat32, 32, 12},  // padded points and rows
                          Layout{io::PointField::kFloat32, io::PointField::kUint32, 16, 0},    // Ouster: nanoseconds
                          Layout{io::PointField::kFloat64, io::PointField::kFloat64, 32, 4}}) {
    const ndt::PointCloud c = toPointCloud(cloud(l, points));
    SCOPED_TRACE("xyz type " + std::to_string(l.xyz_type) + ", time type " + std::to_string(l.time_type) + ", step " + std::to_string(l.point_step));
    ASSERT_EQ(c.size(), 5u);
    ASSERT_EQ(c.times.size(), 5u);
    std::size_t k = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (i == 1) continue;  // not finite: left out
      EXPECT_EQ(c.points[k], points[i].cast<float>()) << "point " << i;
      // Seconds after the first point; float time fields carry float rounding (1e-7 s at 0.3 s).
      EXPECT_NEAR(c.times[k], 0.01 * static_cast<double>(i), 1e-6) << "point " << i;
      ++k;
    }
    EXPECT_EQ(c.times[0], 0.0f);
  }
}

// The time field rewritten: point i at `origin + 0.01 i` seconds, counted in `unit`s.
io::PointCloud2 timedIn(std::uint8_t time_type, double origin, double unit, const std::string& name = "time") {
  io::PointCloud2 m = cloud({io::PointField::kFloat32, time_type, 24, 0}, std::vector<Eigen::Vector3d>(6, Eigen::Vector3d(1, 2, 3)));
  m.fields.back().name = name;
  for (std::uint32_t i = 0; i < 6; ++i) putAs(m.data, i * m.point_step + 12, time_type, (origin + 0.01 * i) / unit);
  return m;
}

TEST(MessageInputs, PointCloud2TimesInNanosecondsOrMicrosecondsAreToldFromTheirSpanAndBecomeSeconds) {
  struct Case {
    const char* what;
    std::uint8_t type;
    double origin, unit;
    const char* name;
  };
  for (const Case& k : {Case{"absolute seconds, float64 (Hesai, RoboSense)", io::PointField::kFloat64, 1.7e9, 1.0, "timestamp"},
                        Case{"absolute nanoseconds, float64 (Livox)", io::PointField::kFloat64, 1.7e9, 1e-9, "timestamp"},
                        Case{"microseconds from the sweep's start, float32", io::PointField::kFloat32, 0.0, 1e-6, "time"},
                        Case{"nanoseconds from the sweep's start, uint32 (Livox)", io::PointField::kUint32, 0.0, 1e-9, "offset_time"}}) {
    const ndt::PointCloud c = toPointCloud(timedIn(k.type, k.origin, k.unit, k.name));
    ASSERT_EQ(c.times.size(), 6u) << k.what;
    for (std::size_t i = 0; i < 6; ++i) EXPECT_NEAR(c.times[i], 0.01 * static_cast<double>(i), 1e-6) << k.what << ", point " << i;
  }
}

TEST(MessageInputs, PointCloud2TimesSpanningMoreThanASweepInAnyUnitAreRefusedNamingTheField) {
  // 0.01 s apart in units of 1e-12 s: 5e10 units, more than a second even as nanoseconds.
  try {
    toPointCloud(timedIn(io::PointField::kFloat64, 0.0, 1e-12));
    FAIL() << "a cloud whose times span 50 s was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("field time spans"), std::string::npos) << e.what();
  }
}

TEST(MessageInputs, PointCloud2WithoutATimeFieldGivesPointsWithoutTimes) {
  io::PointCloud2 m = cloud({io::PointField::kFloat32, io::PointField::kFloat32, 16, 0}, std::vector<Eigen::Vector3d>(6, Eigen::Vector3d(1, 2, 3)));
  m.fields.pop_back();
  const ndt::PointCloud c = toPointCloud(m);
  EXPECT_EQ(c.size(), 6u);
  EXPECT_FALSE(c.hasTimes());
}

TEST(MessageInputs, PointCloud2WithDataShorterThanItsLayoutIsRefusedNamingTheReason) {
  io::PointCloud2 m = cloud({io::PointField::kFloat32, io::PointField::kFloat32, 16, 0}, std::vector<Eigen::Vector3d>(6, Eigen::Vector3d(1, 2, 3)));
  m.data.resize(m.data.size() - 1);
  try {
    toPointCloud(m);
    FAIL() << "a truncated cloud was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("shorter"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace coloc::pipeline
