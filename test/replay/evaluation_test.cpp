#include "coloc/replay/evaluation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "coloc/core/error.hpp"
#include "coloc/replay/accurate_places.hpp"

namespace coloc::replay {
namespace {

// A straight drive east at 10 m/s, ground truth at 100 Hz.
std::vector<io::TrajectoryPoint> truthEast(double seconds) {
  std::vector<io::TrajectoryPoint> truth;
  for (int k = 0; k <= static_cast<int>(seconds * 100); ++k) {
    io::TrajectoryPoint p;
    p.stamp = fromSeconds(0.01 * k);
    p.pose.position = Eigen::Vector3d(0.1 * k, 0.0, 0.0);
    truth.push_back(p);
  }
  return truth;
}

ErrorSample sampleAt(double t, double error) {
  ErrorSample e;
  e.stamp = fromSeconds(t);
  e.truth = Eigen::Vector2d(10.0 * t, 0.0);
  e.error = error;
  return e;
}

TEST(Evaluation, EstimatesAreInterpolatedToStampsBetweenTicksAndScoredWithTheirHeading) {
  const auto truth = truthEast(1.0);
  // Ticks at 50 Hz, 5 cm to the left and yawed 0.01 rad.
  std::vector<io::TrajectoryPoint> ticks;
  for (int k = 0; k <= 50; ++k) {
    io::TrajectoryPoint p;
    p.stamp = fromSeconds(0.02 * k);
    p.pose.position = Eigen::Vector3d(0.2 * k, 0.05, 0.0);
    p.pose.orientation = Eigen::AngleAxisd(0.01, Eigen::Vector3d::UnitZ());
    ticks.push_back(p);
  }
  const auto at = evaluateAt(ticks, {fromSeconds(0.31), fromSeconds(0.555), fromSeconds(2.0)}, truth, fromSeconds(0.2));
  ASSERT_EQ(at.size(), 2u);  // 2 s is past the estimates
  for (const ErrorSample& e : at) {
    EXPECT_NEAR(e.error, 0.05, 1e-9);   // midway between ticks the estimate moved on with them
    EXPECT_NEAR(e.across, 0.05, 1e-9);
    EXPECT_NEAR(e.heading_error, 0.01, 1e-9);
  }
}

TEST(Evaluation, InputComparisonJudgesAccuracyByStretchOfRoadNotByScan) {
  // 10 Hz input over 4 s (40 m): the first 20 m NDT errs 1 cm on average with one scan at 3 cm,
  // the last 20 m 5 cm. The fused output errs 0.8 cm everywhere, the settled estimate 0.6 cm.
  std::vector<ErrorSample> input, fused, settled;
  for (int k = 0; k < 40; ++k) {
    const double t = 0.1 * k;
    double e = k < 20 ? (k % 2 ? 0.005 : 0.015) : 0.05;
    if (k == 7) e = 0.03;
    input.push_back(sampleAt(t, e));
    input.back().heading_error = k % 2 ? 0.002 : 0.004;  // a 3 mrad mounting yaw, +-1 mrad of noise
    if (k != 39) fused.push_back(sampleAt(t, 0.008));  // one stamp without a fused estimate
    settled.push_back(sampleAt(t, 0.006));
  }
  const InputComparison c = compareWithInput(input, fused, settled, 10.0, 0.02);
  EXPECT_EQ(c.samples, 39u);
  EXPECT_NEAR(c.fused_mean, 0.008, 1e-12);
  // Stretches of 10 m: [0, 10) and [10, 20) are accurate; the scan at 3 cm stays in its stretch.
  EXPECT_EQ(c.accurate_samples, 20u);
  double in = 0.0;
  for (int k = 0; k < 20; ++k) in += input[k].error;
  EXPECT_NEAR(c.accurate_input_mean, in / 20.0, 1e-12);
  EXPECT_NEAR(c.accurate_fused_mean, 0.008, 1e-12);
  EXPECT_NEAR(c.accurate_settled_mean, 0.006, 1e-12);
  // Yaw about its mean: the mounting yaw is the pipeline's to learn, not noise.
  EXPECT_NEAR(c.yaw_mean, (20 * 0.004 + 19 * 0.002) / 39.0, 1e-12);
  EXPECT_NEAR(c.yaw_variance, 1e-6, 3e-8);
  double ms = 0.0;
  for (int k = 0; k < 39; ++k) ms += 0.5 * input[k].error * input[k].error;
  EXPECT_NEAR(c.mean_square_xy, ms / 39.0, 1e-15);
}

TEST(Evaluation, InputComparisonWithNothingInCommonIsEmpty) {
  const InputComparison c = compareWithInput({sampleAt(0.0, 0.01)}, {sampleAt(0.5, 0.01)}, {sampleAt(0.0, 0.01)}, 10.0, 0.02);
  EXPECT_EQ(c.samples, 0u);
  EXPECT_EQ(c.accurate_samples, 0u);
}


// The places come from a reference drive: on it NDT errs 1 cm over the first 20 m and 5 cm beyond. On
// the drive compared it happens to err 3 cm over the first 20 m and 1 cm beyond: its own stretches
// choose the last 20 m for that luck, the reference's places the first 20 m, where the road holds NDT.
TEST(AccuratePlaces, ChoosesThePlacesOnAReferenceDriveNotByTheComparedDrivesLuck) {
  std::vector<ErrorSample> reference, input, fused, settled;
  for (int k = 0; k < 40; ++k) {
    const double t = 0.1 * k;  // 10 m/s: a pose a metre
    reference.push_back(sampleAt(t, k < 20 ? 0.01 : 0.05));
    input.push_back(sampleAt(t, k < 20 ? 0.03 : 0.01));
    fused.push_back(sampleAt(t, 0.02));
    settled.push_back(sampleAt(t, k < 20 ? 0.025 : 0.015));
  }
  const AccuratePlaces places = AccuratePlaces::fromErrors(reference, 10.0, 0.02, 5);
  EXPECT_EQ(places.judged(), 4u);
  EXPECT_EQ(places.accurate(), 2u);
  EXPECT_TRUE(places.contains({0.0, 0.0}));
  EXPECT_TRUE(places.contains({19.9, 9.9}));  // the cell is square: beside the road too
  EXPECT_FALSE(places.contains({20.0, 0.0}));
  EXPECT_FALSE(places.contains({-0.1, 0.0}));  // never driven: not judged, not accurate
  EXPECT_FALSE(places.contains({std::nan(""), 0.0}));
  const InputComparison c = compareWithInput(input, fused, settled, 10.0, 0.02, &places);
  EXPECT_EQ(c.accurate_samples, 20u);  // its own stretches: the lucky last 20 m
  EXPECT_NEAR(c.accurate_input_mean, 0.01, 1e-12);
  EXPECT_EQ(c.place_samples, 20u);  // the reference's places: the first 20 m
  EXPECT_NEAR(c.place_input_mean, 0.03, 1e-12);
  EXPECT_NEAR(c.place_fused_mean, 0.02, 1e-12);
  EXPECT_NEAR(c.place_settled_mean, 0.025, 1e-12);
  // Without places, none.
  EXPECT_EQ(compareWithInput(input, fused, settled, 10.0, 0.02).place_samples, 0u);
}

TEST(AccuratePlaces, ACellWithTooFewPosesOrNoNumberIsNotJudgedAndBadSettingsAreNamed) {
  std::vector<ErrorSample> reference;
  for (int k = 0; k < 4; ++k) reference.push_back(sampleAt(0.1 * k, 0.01));  // 4 poses in the first cell
  ErrorSample lost = sampleAt(0.0, 0.01);
  lost.truth.x() = std::nan("");
  reference.push_back(lost);
  reference.push_back(sampleAt(0.05, std::numeric_limits<double>::infinity()));
  EXPECT_EQ(AccuratePlaces::fromErrors(reference, 10.0, 0.02, 5).judged(), 0u);
  EXPECT_EQ(AccuratePlaces::fromErrors(reference, 10.0, 0.02, 4).accurate(), 1u);
  const auto message = [&](double cell, double below) {
    try {
      AccuratePlaces::fromErrors(reference, cell, below, 5);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message(std::nan(""), 0.02).find("cell"), std::string::npos);
  EXPECT_NE(message(0.0, 0.02).find("cell"), std::string::npos);
  EXPECT_NE(message(10.0, -0.02).find("below"), std::string::npos);
  EXPECT_NE(message(10.0, std::numeric_limits<double>::infinity()).find("below"), std::string::npos);
}

}  // namespace
}  // namespace coloc::replay

#include <fstream>
#include <map>
#include <sstream>

#include "coloc/replay/log_replay.hpp"
#include "temp_dir.hpp"

namespace coloc::replay {
namespace {

// input_error.csv as `r` writes it: its header, then each row's cells.
std::vector<std::vector<std::string>> writtenInputErrorCsv(const ReplayResult& r, std::string& header) {
  testing::TempDir dir;
  const std::string path = dir / "input_error.csv";
  r.writeInputErrorCsv(path);
  std::ifstream in(path);
  std::getline(in, header);
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string cell; std::getline(ss, cell, ',');) cells.push_back(cell);
    rows.push_back(cells);
  }
  return rows;
}

// The claim columns of input_error.csv: the standard deviation each input claimed along and across
// the true heading, beside its error.
TEST(Evaluation, InputErrorCsvGivesEachInputsClaimedDeviationAlongAndAcrossTheRoad) {
  // Driving north; NDT claims 0.5 m east-west (across) and 2 cm north-south (along), then nothing east-west.
  std::vector<io::TrajectoryPoint> truth;
  for (int k = 0; k <= 100; ++k) {
    io::TrajectoryPoint p;
    p.stamp = fromSeconds(0.01 * k);
    p.pose.position = Eigen::Vector3d(0.0, 0.1 * k, 0.0);
    p.pose.orientation = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ());
    truth.push_back(p);
  }
  ReplayResult r;
  for (const double t : {0.3, 0.6}) {
    io::TrajectoryPoint p;
    p.stamp = fromSeconds(t);
    p.pose.position = Eigen::Vector3d(0.01, 10.0 * t + 0.02, 0.0);
    p.pose.orientation = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ());
    r.pose_inputs.push_back(p);
    r.pose_input_sources.push_back("ndt");
  }
  r.pose_input_covariances.push_back((Eigen::Matrix2d() << 0.25, 0.0, 0.0, 0.0004).finished());
  r.pose_input_covariances.push_back((Eigen::Matrix2d() << std::numeric_limits<double>::infinity(), 0.0, 0.0, 0.0004).finished());
  r.input_errors["ndt"] = evaluate(r.pose_inputs, truth, fromSeconds(0.05));
  ASSERT_EQ(r.input_errors["ndt"].size(), 2u);
  std::string header;
  const auto rows = writtenInputErrorCsv(r, header);
  EXPECT_NE(header.find(",sd_along_m,sd_across_m"), std::string::npos) << header;
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_NEAR(std::stod(rows[0][7]), 0.02, 1e-6);   // along: 2 cm ahead
  EXPECT_NEAR(std::stod(rows[0][8]), -0.01, 1e-6);  // across: 1 cm east is to the right
  EXPECT_NEAR(std::stod(rows[0][10]), 0.02, 1e-6);
  EXPECT_NEAR(std::stod(rows[0][11]), 0.5, 1e-6);
  EXPECT_EQ(rows[1][10], "inf");  // an axis not measured: no claim along or across
  EXPECT_EQ(rows[1][11], "inf");
}

// After the claims, the filter at each input's stamp: its output as given out then and its settled
// estimate, with the settled error along and across the road; "nan" where the filter has none.
TEST(Evaluation, InputErrorCsvPutsTheFiltersOutputAndSettledEstimateBesideEachInput) {
  std::vector<io::TrajectoryPoint> truth;
  for (int k = 0; k <= 100; ++k) {
    io::TrajectoryPoint p;
    p.stamp = fromSeconds(0.01 * k);
    p.pose.position = Eigen::Vector3d(0.1 * k, 0.0, 0.0);  // driving east
    truth.push_back(p);
  }
  const auto at = [](double t, double ahead, double left) {
    io::TrajectoryPoint p;
    p.stamp = fromSeconds(t);
    p.pose.position = Eigen::Vector3d(10.0 * t + ahead, left, 0.0);
    return p;
  };
  ReplayResult r;
  r.pose_inputs = {at(0.3, 0.01, 0.0), at(0.6, 0.0, -0.02)};
  r.pose_input_sources = {"ndt", "ndt"};
  r.input_errors["ndt"] = evaluate(r.pose_inputs, truth, fromSeconds(0.05));
  r.fused_at_inputs["ndt"] = evaluate({at(0.3, 0.03, 0.04)}, truth, fromSeconds(0.05));  // 5 cm off
  r.settled_at_inputs["ndt"] = evaluate({at(0.3, -0.006, 0.008)}, truth, fromSeconds(0.05));  // 1 cm off
  std::string header;
  const auto rows = writtenInputErrorCsv(r, header);
  EXPECT_NE(header.find(",sd_along_m,sd_across_m,output_error_m,settled_error_m,settled_along_m,settled_across_m"), std::string::npos) << header;
  ASSERT_EQ(rows.size(), 2u);
  ASSERT_EQ(rows[0].size(), 16u);
  EXPECT_NEAR(std::stod(rows[0][6]), 0.01, 1e-6);    // the input's own error
  EXPECT_NEAR(std::stod(rows[0][12]), 0.05, 1e-6);   // the output then
  EXPECT_NEAR(std::stod(rows[0][13]), 0.01, 1e-6);   // settled
  EXPECT_NEAR(std::stod(rows[0][14]), -0.006, 1e-6);  // 6 mm behind
  EXPECT_NEAR(std::stod(rows[0][15]), 0.008, 1e-6);   // 8 mm to the left
  for (int column = 12; column < 16; ++column) EXPECT_EQ(rows[1][column], "nan") << column;  // the filter had none at 0.6 s
}

// NDT's error by place from its poses on a drive: each at NDT's own position with its x/y error; a
// pose that is not finite places nothing and is left out, and the drive's own mean square answers
// where no cell has enough poses.
// The reference drive's places from the input_error.csv a replay writes: each source its own, the
// same as from its errors in memory; a file that is not such a file is refused by line and column.
TEST(AccuratePlaces, TheReferenceDrivesInputErrorCsvGivesEachSourceItsPlaces) {
  ReplayResult r;
  for (int k = 0; k < 40; ++k) {  // ndt 1 cm off over the first 20 m, 5 cm beyond; a fix 1 cm everywhere
    r.input_errors["ndt"].push_back(sampleAt(0.1 * k, k < 20 ? 0.01 : 0.05));
    r.input_errors["/rsu/a/fix"].push_back(sampleAt(0.1 * k, 0.01));
  }
  testing::TempDir dir;
  r.writeInputErrorCsv(dir / "input_error.csv");
  const std::map<std::string, AccuratePlaces> read = AccuratePlaces::fromInputErrorCsv(dir / "input_error.csv", 10.0, 0.02);
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read.at("ndt").accurate(), 2u);
  EXPECT_EQ(read.at("ndt").judged(), 4u);
  EXPECT_EQ(read.at("/rsu/a/fix").accurate(), 4u);
  const AccuratePlaces memory = AccuratePlaces::fromErrors(r.input_errors["ndt"], 10.0, 0.02, AccuratePlaces::kMinPoses);
  for (double x = 0.5; x < 40.0; x += 1.0) EXPECT_EQ(read.at("ndt").contains({x, 0.0}), memory.contains({x, 0.0})) << x;
  // Not such a file.
  const auto refusal = [&](const std::string& text) {
    std::ofstream(dir / "bad.csv") << text;
    try {
      AccuratePlaces::fromInputErrorCsv(dir / "bad.csv", 10.0, 0.02);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("taken");
  };
  EXPECT_NE(refusal("").find("empty"), std::string::npos);
  EXPECT_NE(refusal("source,truth_x,error_m\n").find("no column truth_y"), std::string::npos);
  EXPECT_NE(refusal("source,truth_x,truth_y,error_m\nndt,1,2\n").find("bad.csv:2: 3 fields"), std::string::npos);
  EXPECT_NE(refusal("source,truth_x,truth_y,error_m\nndt,1,2,0.01\nndt,1,nan,0.01\n").find("bad.csv:3: truth_y: 'nan' is not a finite number"), std::string::npos);
  EXPECT_NE(refusal("source,truth_x,truth_y,error_m\nndt,1,2,-0.01\n").find("bad.csv:2: error_m: -0.01 is negative"), std::string::npos);
  EXPECT_EQ(refusal("source,truth_x,truth_y,error_m\r\nndt,1,2,0.01\r\n"), "taken") << "a file with CRLF line ends";
  EXPECT_NE(refusal("x").find("no column source"), std::string::npos);
  EXPECT_THROW(AccuratePlaces::fromInputErrorCsv(dir / "none.csv", 10.0, 0.02), Error);
  EXPECT_THROW(AccuratePlaces::fromInputErrorCsv(dir / "input_error.csv", 0.0, 0.02), Error) << "the cell checked before the file";
}

TEST(Evaluation, NdtQualityMapTakesEachPoseAtNdtsPositionAndLeavesOutWhatCannotBePlaced) {
  std::vector<ErrorSample> ndt;
  for (int i = 0; i < 6; ++i) {
    ErrorSample e{};
    e.estimate = Eigen::Vector2d(2.0 + i, 3.0);
    e.truth = e.estimate - Eigen::Vector2d(0.02, 0.0);
    ndt.push_back(e);
  }
  ErrorSample lost{};
  lost.estimate = Eigen::Vector2d(std::nan(""), 3.0);
  lost.truth = Eigen::Vector2d(5.0, 3.0);
  ndt.push_back(lost);
  ErrorSample far{};
  far.estimate = Eigen::Vector2d(5e9, 0.0);
  far.truth = far.estimate;
  ndt.push_back(far);
  const pipeline::NdtQualityMap m = ndtQualityMap(ndt, 10.0, 5);
  EXPECT_EQ(m.cells(), 1u);
  EXPECT_NEAR(m.varianceAt({5.0, 5.0}), 0.5 * 0.02 * 0.02, 1e-15);
  EXPECT_NEAR(m.defaultVariance(), 0.5 * 0.02 * 0.02, 1e-15) << "the six poses that could be placed";
}

}  // namespace
}  // namespace coloc::replay
