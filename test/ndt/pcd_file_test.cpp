#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>

#include "coloc/core/error.hpp"
#include "coloc/ndt/pcd_file.hpp"
#include "real_data.hpp"
#include "temp_dir.hpp"

namespace coloc::ndt {
namespace {

void expectLoadError(const std::string& path, const std::string& phrase) {
  try {
    loadPcd(path);
    FAIL() << "expected an error for " << path;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(phrase), std::string::npos) << e.what();
  }
}

void writeText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

TEST(PcdFile, ReadsTheRealScanWithAllItsPoints) {
  PcdLoadReport report;
  const PointCloud cloud = loadPcd(testing::realData("hdl32e_pair/target.pcd"), &report);
  EXPECT_EQ(cloud.size(), 69088u);
  EXPECT_EQ(report.points_in_file, 69088u);
  EXPECT_FALSE(cloud.hasTimes());
}

TEST(PcdFile, SaveThenLoadGivesTheSamePoints) {
  testing::TempDir dir;
  PointCloud cloud;
  for (int i = 0; i < 100; ++i) cloud.points.emplace_back(0.5f * i, -0.25f * i, 1.0f);
  savePcd(dir / "c.pcd", cloud);
  EXPECT_EQ(loadPcd(dir / "c.pcd").points, cloud.points);
}

TEST(PcdFile, NonFinitePointsAreDroppedAndCounted) {
  testing::TempDir dir;
  writeText(dir / "nan.pcd",
            "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\n"
            "DATA ascii\n1 2 3\nnan 0 0\n4 5 6\n");
  PcdLoadReport report;
  const PointCloud cloud = loadPcd(dir / "nan.pcd", &report);
  EXPECT_EQ(cloud.size(), 2u);
  EXPECT_EQ(report.non_finite_dropped, 1u);
}

TEST(PcdFile, ReadsAPerPointTimeField) {
  testing::TempDir dir;
  writeText(dir / "t.pcd",
            "VERSION .7\nFIELDS x y z time\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
            "POINTS 2\nDATA ascii\n1 2 3 0.0\n4 5 6 0.05\n");
  const PointCloud cloud = loadPcd(dir / "t.pcd");
  ASSERT_TRUE(cloud.hasTimes());
  EXPECT_FLOAT_EQ(cloud.times[1], 0.05f);
}

TEST(PcdFile, BadFilesGiveErrorsNamingTheFileAndTheReason) {
  testing::TempDir dir;
  expectLoadError(dir / "missing.pcd", "no such PCD file");
  writeText(dir / "empty.pcd", "");
  expectLoadError(dir / "empty.pcd", "empty");
  writeText(dir / "garbage.pcd", "this is not a point cloud\x01\x02\x03");
  expectLoadError(dir / "garbage.pcd", "not a readable PCD file");
  writeText(dir / "allnan.pcd",
            "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\n"
            "DATA ascii\nnan nan nan\nnan 1 2\n");
  expectLoadError(dir / "allnan.pcd", "no finite point");
  writeText(dir / "noxyz.pcd",
            "VERSION .7\nFIELDS a b\nSIZE 4 4\nTYPE F F\nCOUNT 1 1\nWIDTH 1\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1\nDATA ascii\n1 2\n");
  expectLoadError(dir / "noxyz.pcd", "no x, y and z");
}

// Found by fuzzing (pcd_fuzzer): a file whose last line is "DATA ascii" with no newline after it put
// the data one byte past the end, and reading it threw std::out_of_range past every caller.
TEST(PcdFile, AFileEndingOnItsDataLineIsAnErrorNotACrash) {
  testing::TempDir dir;
  writeText(dir / "ends.pcd", "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii");
  expectLoadError(dir / "ends.pcd", "ascii data ends after 0 of 1 points");
  expectLoadError(COLOC_SOURCE_DIR "/test/support/fuzz_findings/pcd_data_line_ends_the_file.pcd", "not a readable PCD file");
}

// Found by fuzzing (pcd_fuzzer): WIDTH 4 x HEIGHT 1555555555555555 made the reader reserve room for
// every claimed point before reading any, and the allocation failed.
TEST(PcdFile, AHeaderClaimingMorePointsThanTheDataHoldsIsAnErrorNotAnAllocation) {
  expectLoadError(COLOC_SOURCE_DIR "/test/support/fuzz_findings/pcd_header_claims_six_quadrillion_points.pcd", "ascii data ends after");
  testing::TempDir dir;
  const std::string header = "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nVIEWPOINT 0 0 0 1 0 0 0\n";
  // A count whose bytes (x 12) wrap around 2^64 to fewer than the data holds.
  const std::string wraps = "1537228672809129302";  // 12 x this = 2^64 + 8
  writeText(dir / "wraps.pcd", header + "WIDTH " + wraps + "\nHEIGHT 1\nPOINTS " + wraps + "\nDATA binary\n" + std::string(24, '\0'));
  expectLoadError(dir / "wraps.pcd", "binary data is shorter than its header says");
  writeText(dir / "product.pcd", header + "WIDTH 4294967296\nHEIGHT 4294967297\nDATA ascii\n1 2 3\n");
  expectLoadError(dir / "product.pcd", "WIDTH x HEIGHT is out of range");
}

TEST(PcdFile, TruncatedBinaryFileIsAnErrorNotACrash) {
  testing::TempDir dir;
  std::ifstream in(testing::realData("hdl32e_pair/target.pcd"), std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (std::size_t cut : {std::size_t{40}, std::size_t{200}, bytes.size() / 2, bytes.size() - 7}) {
    const std::string path = dir / ("cut" + std::to_string(cut) + ".pcd");
    std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(cut));
    EXPECT_THROW(loadPcd(path), Error) << "cut at " << cut;
  }
}

}  // namespace
}  // namespace coloc::ndt
