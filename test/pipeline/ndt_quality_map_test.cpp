// NDT's error by place: each cell the mean square of its poses' errors, the default elsewhere, and a
// file that reads back to the same map or is refused naming the line and key.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "coloc/core/error.hpp"
#include "coloc/pipeline/ndt_quality_map.hpp"

namespace coloc::pipeline {
namespace {

std::vector<NdtQualitySample> twoPlaces() {
  std::vector<NdtQualitySample> s;
  for (int i = 0; i < 6; ++i) s.push_back({{3.0 + i, 4.0}, {0.01, -0.01}});          // cell (0, 0): 1 cm each way
  for (int i = 0; i < 6; ++i) s.push_back({{25.0, -3.0}, {i % 2 ? 0.2 : -0.2, 0.0}});  // cell (2, -1): 0.2 m along x
  for (int i = 0; i < 3; ++i) s.push_back({{55.0, 55.0}, {1.0, 1.0}});                // cell (5, 5): too few poses
  return s;
}

TEST(NdtQualityMap, EachCellHoldsTheMeanSquareOfItsPosesAndTheDefaultAnswersElsewhere) {
  const NdtQualityMap m = NdtQualityMap::fromErrors(twoPlaces(), 10.0, 5, 0.004);
  EXPECT_EQ(m.cells(), 2u);
  EXPECT_NEAR(m.varianceAt({9.9, 0.1}), 1e-4, 1e-15);   // x and y pooled: (1e-4 + 1e-4) / 2
  EXPECT_NEAR(m.varianceAt({20.0, -10.0}), 0.02, 1e-15);  // (0.04 + 0) / 2, a bias counted as error
  EXPECT_EQ(m.varianceAt({55.0, 55.0}), 0.004) << "three poses are too few: the default";
  EXPECT_EQ(m.varianceAt({-0.1, 5.0}), 0.004) << "just outside a cell";
  EXPECT_EQ(m.varianceAt({std::nan(""), 0.0}), 0.004);
  EXPECT_EQ(NdtQualityMap().varianceAt({0.0, 0.0}), 0.0) << "an empty map floors nothing";
}

TEST(NdtQualityMap, TheScanToScanNoiseIsHalfTheMeanSquareChangeBetweenNeighboursWhateverTheBias) {
  // 4000 poses 1 m apart: a bias of 10 cm along x that stays, and independent noise of 1 cm sd each way.
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::vector<NdtQualitySample> s;
  for (int i = 0; i < 4000; ++i) s.push_back({{1.0 * i, 0.0}, {0.10 + noise(rng), noise(rng)}});
  // A jump of a whole cell between two poses (the log's gap) is no neighbour, whatever their errors.
  s.push_back({{5000.0, 0.0}, {5.0, 5.0}});
  const NdtQualityMap m = NdtQualityMap::fromErrors(s, 10.0, 5, 0.0);
  EXPECT_NEAR(m.noiseVariance(), 1e-4, 0.05e-4);  // 8000 differences: 1.6 % sd
  double cells = 0.0;  // the bias in them: (bias^2 + 2 sd^2) / 2 on average
  for (int c = 0; c < 400; ++c) cells += m.varianceAt({10.0 * c + 5.0, 0.0}) / 400.0;
  EXPECT_NEAR(cells, (0.01 + 2e-4) / 2, 1e-4);
  EXPECT_EQ(NdtQualityMap::parse(m.toYaml(), "q.yaml").noiseVariance(), m.noiseVariance());
  // A file without the figure (written before it was measured) reads as not measured; a bad one is refused.
  EXPECT_EQ(NdtQualityMap::parse("cell: 10\ndefault_variance: 0.01\ncells: []\n", "q.yaml").noiseVariance(), 0.0);
  EXPECT_THROW(NdtQualityMap::parse("cell: 10\ndefault_variance: 0.01\nnoise_variance: -1\ncells: []\n", "q.yaml"), Error);
}

TEST(NdtQualityMap, TheNoiseAlongAndAcrossTheVehicleIsMeasuredWhereTheSamplesGiveTheHeading) {
  // A drive round a 300 m circle, NDT's noise 2 cm sd along the vehicle and 1 mm across it (as on the
  // twin's sites: 0.7-1.4 cm along, 0.1-0.6 cm across), a bias that stays.
  std::mt19937_64 rng(5);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::vector<NdtQualitySample> s;
  for (int i = 0; i < 4000; ++i) {
    const double heading = i * 2.0 * M_PI / 4000.0 * 3.0, radius = 300.0 / (2.0 * M_PI);
    const Eigen::Vector2d along(std::cos(heading), std::sin(heading)), across(-std::sin(heading), std::cos(heading));
    const Eigen::Vector2d error = Eigen::Vector2d(0.05, -0.02) + 0.02 * unit(rng) * along + 0.001 * unit(rng) * across;
    s.push_back({radius * Eigen::Vector2d(std::sin(heading), -std::cos(heading)), error, heading});
  }
  const NdtQualityMap m = NdtQualityMap::fromErrors(s, 10.0, 5, 0.0);
  ASSERT_TRUE(m.noiseAlongAcross());
  // 4000 differences: the variance within 2.2 % (1 sd); the heading turns 0.5 mrad between poses.
  EXPECT_NEAR(m.noiseAlongAcross()->x(), 4e-4, 0.07 * 4e-4);
  EXPECT_NEAR(m.noiseAlongAcross()->y(), 1e-6, 0.07 * 1e-6 + 1e-8);
  EXPECT_NEAR(m.noiseVariance(), 0.5 * (4e-4 + 1e-6), 0.07 * 2e-4) << "per axis, as before: the two pooled";
  // Turned to the map: heading north, the noise along is on y.
  const Eigen::Matrix2d east = *m.noiseAt(0.0), north = *m.noiseAt(M_PI / 2.0);
  EXPECT_NEAR(east(0, 0), m.noiseAlongAcross()->x(), 1e-15);
  EXPECT_NEAR(east(1, 1), m.noiseAlongAcross()->y(), 1e-15);
  EXPECT_NEAR(north(1, 1), m.noiseAlongAcross()->x(), 1e-15);
  EXPECT_NEAR(north(0, 0), m.noiseAlongAcross()->y(), 1e-15);
  EXPECT_NEAR(north(0, 1), 0.0, 1e-15);
  EXPECT_FALSE(m.noiseAt(std::nan("")));
  const NdtQualityMap read = NdtQualityMap::parse(m.toYaml(), "q.yaml");
  ASSERT_TRUE(read.noiseAlongAcross());
  EXPECT_EQ(*read.noiseAlongAcross(), *m.noiseAlongAcross());
  // Samples without a heading, and files written before it was measured: per axis only.
  for (NdtQualitySample& sample : s) sample.heading = std::nan("");
  EXPECT_FALSE(NdtQualityMap::fromErrors(s, 10.0, 5, 0.0).noiseAlongAcross());
  EXPECT_FALSE(NdtQualityMap::parse("cell: 10\ndefault_variance: 0.01\nnoise_variance: 1e-4\ncells: []\n", "q.yaml").noiseAlongAcross());
  // One without the other, or out of range, is refused naming the key.
  for (const auto& [text, key] : std::vector<std::pair<std::string, std::string>>{
           {"noise_along: 1e-4\n", "noise_along"}, {"noise_across: 1e-4\n", "noise_across"}, {"noise_along: -1\nnoise_across: 1e-4\n", "noise_along"},
           {"noise_along: 1e-4\nnoise_across: .nan\n", "noise_across"}}) {
    try {
      NdtQualityMap::parse("cell: 10\ndefault_variance: 0.01\n" + text + "cells: []\n", "q.yaml");
      ADD_FAILURE() << text << " accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
}

// Site C's noise calibration drive: in one cell ten scans matched 1 cm off and one 34 cm off. That
// scan is not the place's error (the travel check catches it as it comes): left out of the cell and of
// the scan-to-scan noise, it no longer makes the cell 7 cm. Scatter about a bias, however wide, stays.
TEST(NdtQualityMap, AScanMatchedFarOffIsLeftOutOfItsPlaceAndOfTheScanToScanNoise) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.003);
  std::vector<NdtQualitySample> clean, glitch;
  for (int i = 0; i < 11; ++i) {
    const NdtQualitySample s{{100.5 + 0.8 * i, -2.0}, {0.01 + noise(rng), noise(rng)}};
    clean.push_back(s);
    glitch.push_back(i == 5 ? NdtQualitySample{s.position, {0.34, 0.02}} : s);
  }
  const std::vector<bool> gross = NdtQualityMap::grossErrors(glitch, 10.0);
  for (int i = 0; i < 11; ++i) EXPECT_EQ(gross[static_cast<std::size_t>(i)], i == 5) << i;
  const NdtQualityMap with = NdtQualityMap::fromErrors(glitch, 10.0, 5, 0.0);
  EXPECT_EQ(with.grossErrorsLeftOut(), 1u);
  std::vector<NdtQualitySample> without = clean;
  without.erase(without.begin() + 5);
  const NdtQualityMap reference = NdtQualityMap::fromErrors(without, 10.0, 5, 0.0);
  EXPECT_DOUBLE_EQ(with.varianceAt({105.0, -2.0}), reference.varianceAt({105.0, -2.0}));
  EXPECT_LT(with.varianceAt({105.0, -2.0}), 2e-4) << "about (1 cm)^2 / 2, not the glitch's (34 cm)^2 / 22";
  // Nor in the drive's own figure, which answers where no cell is listed when no default is given.
  EXPECT_DOUBLE_EQ(NdtQualityMap::fromErrors(glitch, 10.0, 5).defaultVariance(), NdtQualityMap::fromErrors(without, 10.0, 5).defaultVariance());
  EXPECT_LT(NdtQualityMap::fromErrors(glitch, 10.0, 5).defaultVariance(), 2e-4);
  // Its two changes (into it and out of it) are left out of the noise, the rest kept.
  EXPECT_LT(with.noiseVariance(), 2e-5);
  EXPECT_NE(with.toYaml().find("1 pose(s) left out as gross errors"), std::string::npos);
  // A cell of wide scatter (3 cm each way about a 10 cm bias, 400 poses) and one of a bias alone
  // (every pose 20 cm off): nothing is gross.
  std::normal_distribution<double> wide(0.0, 0.03);
  std::vector<NdtQualitySample> scatter;
  for (int i = 0; i < 400; ++i) scatter.push_back({{5.0, 5.0}, {0.1 + wide(rng), wide(rng)}});
  for (int i = 0; i < 400; ++i) scatter.push_back({{25.0, 5.0}, {wide(rng), wide(rng)}});
  for (int i = 0; i < 6; ++i) scatter.push_back({{45.0, 5.0}, {0.2, 0.0}});
  const std::vector<bool> none = NdtQualityMap::grossErrors(scatter, 10.0);
  EXPECT_EQ(std::count(none.begin(), none.end(), true), 0);
  EXPECT_THROW(NdtQualityMap::grossErrors({{{std::nan(""), 0.0}, {0.0, 0.0}}}, 10.0), Error);
}

// NDT's noise changes with the place as much as its error does (site D's cutting: 50x its median
// cell along the road). Each cell measures its own noise along, across and in yaw, and its error
// along and across; a cell with few pairs is drawn towards the median cell, not towards the map's
// mean, which the cutting decides.
TEST(NdtQualityMap, EachCellMeasuresItsOwnNoiseAndErrorDrawnTowardsTheMedianCell) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::vector<NdtQualitySample> s;
  // Eastward, 0.1 m apart over 200 m: 20 cells of 100 pairs. NDT 5 cm ahead and 2 cm to the left
  // everywhere, its noise 1 cm along, 1 mm across and 0.3 mrad in yaw, except in cells 5 and 6 (a
  // cutting) where it is 10 cm along.
  for (int i = 0; i < 2000; ++i) {
    const double x = 0.1 * i + 0.05, along = (x >= 50.0 && x < 70.0) ? 0.10 : 0.01;
    s.push_back({{x, 5.0}, {0.05 + along * unit(rng), 0.02 + 0.001 * unit(rng)}, 0.0, 0.003 + 3e-4 * unit(rng)});
  }
  // Three pairs in a cell of their own, 100 m north, with no noise at all.
  for (int i = 0; i < 4; ++i) s.push_back({{5.0 + 0.1 * i, 105.0}, {0.05, 0.02}, 0.0, 0.003});
  const NdtQualityMap m = NdtQualityMap::fromErrors(s, 10.0, 3, 0.0);
  ASSERT_TRUE(m.noiseAlongAcross() && m.yawNoise());
  EXPECT_GT(m.noiseAlongAcross()->x(), 8e-4) << "the map's figure, a mean: the cutting decides it";
  // Heading east: along is x. 100 pairs give each cell's variance within 14 % (1 sd).
  const Eigen::Matrix2d open = *m.noiseAt({25.0, 5.0}, 0.0), cutting = *m.noiseAt({55.0, 5.0}, 0.0);
  EXPECT_NEAR(open(0, 0), 1e-4, 0.45e-4);
  EXPECT_NEAR(open(1, 1), 1e-6, 0.45e-6);
  EXPECT_NEAR(cutting(0, 0), 1e-2, 0.45e-2);
  EXPECT_NEAR(*m.yawNoiseAt({25.0, 5.0}), 9e-8, 4e-8);
  // Heading north the same cell's noise along is on y.
  EXPECT_NEAR((*m.noiseAt({25.0, 5.0}, M_PI / 2.0))(1, 1), open(0, 0), 1e-15);
  // The quiet cell's three pairs, drawn towards the median cell's 1e-4: 5 / 8 of it, where the
  // map's mean would have made it 5 / 8 of 1e-3.
  EXPECT_NEAR((*m.noiseAt({5.0, 105.0}, 0.0))(0, 0), 5.0 / 8.0 * 1e-4, 0.3e-4);
  // Its error: the mean square, the bias in it, along and across.
  const Eigen::Matrix2d error = *m.errorAt({25.0, 5.0}, 0.0);
  EXPECT_NEAR(error(0, 0), 0.0025 + 1e-4, 0.0004);
  EXPECT_NEAR(error(1, 1), 0.0004 + 1e-6, 0.00005);
  EXPECT_NEAR(*m.yawErrorAt({25.0, 5.0}), 9e-6 + 9e-8, 1e-6) << "NDT's yaw 3 mrad off and its noise";
  EXPECT_FALSE(m.yawErrorAt({500.0, 500.0}));
  // Where no cell measured: the map's figures, and no error by direction.
  EXPECT_NEAR((*m.noiseAt({500.0, 500.0}, 0.0))(0, 0), m.noiseAlongAcross()->x(), 1e-15);
  EXPECT_EQ(*m.yawNoiseAt({500.0, 500.0}), *m.yawNoise());
  EXPECT_FALSE(m.errorAt({500.0, 500.0}, 0.0));
  EXPECT_FALSE(m.errorAt({25.0, 5.0}, std::nan("")));
  // The file carries all of it.
  const NdtQualityMap read = NdtQualityMap::parse(m.toYaml(), "q.yaml");
  for (const Eigen::Vector2d& at : {Eigen::Vector2d(25.0, 5.0), Eigen::Vector2d(55.0, 5.0), Eigen::Vector2d(5.0, 105.0)}) {
    EXPECT_TRUE(read.noiseAt(at, 0.3)->isApprox(*m.noiseAt(at, 0.3), 1e-12));
    EXPECT_TRUE(read.errorAt(at, 0.3)->isApprox(*m.errorAt(at, 0.3), 1e-12));
    EXPECT_NEAR(*read.yawNoiseAt(at), *m.yawNoiseAt(at), 1e-20);
    EXPECT_NEAR(*read.yawErrorAt(at), *m.yawErrorAt(at), 1e-20);
  }
  // Samples without NDT's yaw error measure no cell's noise: the map's along and across serve.
  for (NdtQualitySample& sample : s) sample.yaw_error = std::nan("");
  const NdtQualityMap no_yaw = NdtQualityMap::fromErrors(s, 10.0, 3, 0.0);
  EXPECT_FALSE(no_yaw.yawNoise());
  EXPECT_NEAR((*no_yaw.noiseAt({55.0, 5.0}, 0.0))(0, 0), no_yaw.noiseAlongAcross()->x(), 1e-15);
}

TEST(NdtQualityMap, ACellsNoiseThatCannotBeIsRefusedNamingTheCell) {
  const std::string head = "cell: 10\ndefault_variance: 0.01\nnoise_variance: 1e-4\nnoise_along: 1e-4\nnoise_across: 1e-6\nnoise_yaw: 1e-7\ncells:\n";
  EXPECT_NO_THROW(NdtQualityMap::parse(head + "  - [0, 0, 10, 1e-3, 2e-3, 1e-5, 4e-6, 9, 1e-4, 1e-6, 1e-7]\n", "q.yaml"));
  for (const std::string row : {"[0, 0, 10, 1e-3, 2e-3, 1e-5, 4e-6, 0, 1e-4, 1e-6, 1e-7]", "[0, 0, 10, 1e-3, 2e-3, 1e-5, 4e-6, 11, 1e-4, 1e-6, 1e-7]",
                                "[0, 0, 10, 1e-3, 2e-3, 1e-5, 4e-6, 2.5, 1e-4, 1e-6, 1e-7]", "[0, 0, 10, 1e-3, -2e-3, 1e-5, 4e-6, 9, 1e-4, 1e-6, 1e-7]",
                                "[0, 0, 10, 1e-3, 2e-3, 1e-5, 4e-6, 9, 1e-4, .nan, 1e-7]", "[0, 0, 10, 1e-3, 2e-3, 1e-5, 4e-6, 9, 1e-4, 1e-6, .inf]",
                                "[0, 0, 10, 1e-3, 2e-3, 1e-5, 4e-6, 9, 1e-4]", "[0, 0, 10, 1e-3, 2e-3, 1e-5, -4e-6, 9, 1e-4, 1e-6, 1e-7]"}) {
    try {
      NdtQualityMap::parse(head + "  - " + row + "\n", "q.yaml");
      ADD_FAILURE() << row << " accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("q.yaml:8: cells[0]"), std::string::npos) << e.what();
    }
  }
  // A cell's noise without the map's to fall back on.
  EXPECT_THROW(NdtQualityMap::parse("cell: 10\ndefault_variance: 0.01\ncells:\n  - [0, 0, 10, 1e-3, 2e-3, 1e-5, 4e-6, 9, 1e-4, 1e-6, 1e-7]\n", "q.yaml"), Error);
}

TEST(NdtQualityMap, ItsFileReadsBackToTheSameMap) {
  const NdtQualityMap m = NdtQualityMap::fromErrors(twoPlaces(), 10.0, 5, 0.004);
  const NdtQualityMap back = NdtQualityMap::parse(m.toYaml(), "q.yaml");
  EXPECT_EQ(back.cells(), m.cells());
  EXPECT_EQ(back.cellSize(), m.cellSize());
  EXPECT_EQ(back.defaultVariance(), m.defaultVariance());
  for (const Eigen::Vector2d& p : {Eigen::Vector2d(5, 5), Eigen::Vector2d(21, -1), Eigen::Vector2d(55, 55)}) EXPECT_EQ(back.varianceAt(p), m.varianceAt(p));
  EXPECT_EQ(back.toYaml(), m.toYaml());
}

TEST(NdtQualityMap, AMalformedFileIsAnErrorNamingTheFileLineAndKey) {
  const auto refused = [](const std::string& text, const std::string& expected) {
    try {
      NdtQualityMap::parse(text, "q.yaml");
      ADD_FAILURE() << "taken: " << text;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("q.yaml"), std::string::npos) << e.what();
    }
  };
  const std::string head = "cell: 10\ndefault_variance: 0.01\n";
  refused(head + "cells:\n  - [0, 0, 5, -0.1]\n", "cells[0]");
  refused(head + "cells:\n  - [0, 0, 5, .nan]\n", "cells[0]");
  refused(head + "cells:\n  - [0, 0, 5, .inf]\n", "cells[0]");
  refused(head + "cells:\n  - [0.5, 0, 5, 0.1]\n", "cells[0]");
  refused(head + "cells:\n  - [0, 0, 0, 0.1]\n", "cells[0]");
  refused(head + "cells:\n  - [0, 0, 5, 0.1]\n  - [0, 0, 7, 0.2]\n", "cells[1]");
  refused(head + "cells:\n  - [0, 0, 5]\n", "cells[0]");
  refused(head + "cells: []\nsize: 3\n", "size");
  refused("cell: 0\ndefault_variance: 0.01\ncells: []\n", "cell");
  refused("cell: 10\ndefault_variance: -1\ncells: []\n", "default_variance");
  refused("cell: 10\ncells: []\n", "default_variance");
  refused("cell: 10\ndefault_variance: 0.01\ncells: [\n", "q.yaml");
  EXPECT_THROW(NdtQualityMap::load("/nonexistent/q.yaml"), Error);
  try {
    NdtQualityMap::load(std::filesystem::temp_directory_path().string());
    ADD_FAILURE() << "a folder was read as a map";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("is a folder"), std::string::npos) << e.what();
  }
  EXPECT_THROW(NdtQualityMap::fromErrors({{{std::nan(""), 0.0}, {0.0, 0.0}}}, 10.0, 1, 0.0), Error);
  EXPECT_THROW(NdtQualityMap::fromErrors({}, 0.0, 1, 0.0), Error);
}

}  // namespace
}  // namespace coloc::pipeline
