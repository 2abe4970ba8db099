// Commissioning an RSU against a reference vehicle: its survey and clock error from one drive past it.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>

#include "coloc/rsu_client/commissioning.hpp"

namespace coloc::rsu_client {
namespace {

constexpr double kDeg = M_PI / 180.0;

// A drive past an RSU whose true position is `truth` and whose registry lists truth + survey (dx, dy)
// turned by dyaw; the RSU stamps its fixes `clock` late. `speed(t)` and `yaw_rate` shape the drive.
std::vector<CommissioningSample> drive(const Eigen::Vector2d& truth, const Eigen::Vector3d& survey, double clock, double noise,
                                       double (*speed)(double), double yaw_rate, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, noise);
  std::vector<CommissioningSample> out;
  Eigen::Vector2d p(truth.x() - 30.0, truth.y() + 6.0);
  double yaw = 0.0;
  const Eigen::Vector2d surveyed = truth + survey.head<2>();
  for (double t = 0.0; t < 6.0; t += 0.01) {
    const Eigen::Vector2d v = speed(t) * Eigen::Vector2d(std::cos(yaw), std::sin(yaw));
    if (std::fmod(t + 1e-9, 0.1) < 0.01 && (p - truth).norm() < 35.0) {
      // What the RSU measures (true frame, with noise), reported through its surveyed pose; the
      // reference at the fix's stamp, which is `clock` after the capture.
      const Eigen::Vector2d seen = p + Eigen::Vector2d(n(rng), n(rng));
      const Eigen::Vector2d fix = surveyed + Eigen::Rotation2Dd(survey.z()) * (seen - truth);
      out.push_back({fix, p + v * clock, v});
    }
    p += v * 0.01;
    yaw += yaw_rate * 0.01;
  }
  return out;
}

double steady(double) { return 10.0; }
double accelerating(double t) { return 4.0 + 2.0 * t; }

TEST(Commissioning, RecoversSurveyAndClockFromADriveThatChangesSpeed) {
  const Eigen::Vector3d survey(0.03, -0.02, 0.1 * kDeg);
  const auto samples = drive({100, 0}, survey, 0.004, 0.02, accelerating, 0.0, 1);
  const CommissioningResult r = commissionRsu(Eigen::Vector2d(100, 0) + survey.head<2>(), samples);
  ASSERT_TRUE(r.determined) << r.note;
  ASSERT_TRUE(r.clock_observable);
  EXPECT_NEAR(r.calibration.dx, survey.x(), 3 * r.sd[0] + 1e-3);
  EXPECT_NEAR(r.calibration.dy, survey.y(), 3 * r.sd[1] + 1e-3);
  EXPECT_NEAR(r.calibration.dyaw, survey.z(), 3 * r.sd[2] + 1e-5);
  EXPECT_NEAR(r.calibration.clock_offset, 0.004, 3 * r.sd[3] + 1e-4);
  EXPECT_LT(r.sd[3], 0.002);  // ms-level from one accelerating drive
  EXPECT_NEAR(r.residual_sd, 0.02, 0.005);  // the fixes' own noise is what remains
}

TEST(Commissioning, AtOneSpeedOnAStraightRoadTheClockIsHeldAndTheShiftAlongTheRoadAbsorbsIt) {
  const Eigen::Vector3d survey(0.03, -0.02, 0.1 * kDeg);
  const auto samples = drive({100, 0}, survey, 0.004, 0.02, steady, 0.0, 2);
  const CommissioningResult r = commissionRsu(Eigen::Vector2d(100, 0) + survey.head<2>(), samples);
  ASSERT_TRUE(r.determined) << r.note;
  EXPECT_FALSE(r.clock_observable);
  EXPECT_EQ(r.calibration.clock_offset, 0.0);
  // 4 ms at 10 m/s along +x: the corrected fix must land where the reference was at the stamp.
  EXPECT_NEAR(r.calibration.dx, survey.x() - 0.04, 3 * r.sd[0] + 1e-3);
  EXPECT_NEAR(r.calibration.dy, survey.y(), 3 * r.sd[1] + 1e-3);
}

TEST(Commissioning, FixesFarOffAreLeftOutNotFitted) {
  const Eigen::Vector3d survey(0.0, 0.05, 0.0);
  auto samples = drive({100, 0}, survey, 0.0, 0.01, accelerating, 0.0, 3);
  for (std::size_t i = 3; i < samples.size(); i += 15) samples[i].fix += Eigen::Vector2d(0.8, -0.5);  // the wrong corner
  const CommissioningResult r = commissionRsu(Eigen::Vector2d(100, 0) + survey.head<2>(), samples);
  ASSERT_TRUE(r.determined) << r.note;
  EXPECT_GE(r.outliers, samples.size() / 15);
  EXPECT_NEAR(r.calibration.dy, 0.05, 0.005);
}

TEST(Commissioning, SamplesWithNaNOrInfiniteValuesAreCountedAndLeftOut) {
  const Eigen::Vector3d survey(0.02, 0.01, 0.0);
  auto samples = drive({100, 0}, survey, 0.0, 0.01, accelerating, 0.0, 5);
  samples[2].fix.x() = std::nan("");
  samples[7].velocity.y() = std::numeric_limits<double>::infinity();
  const CommissioningResult r = commissionRsu(Eigen::Vector2d(100, 0) + survey.head<2>(), samples);
  EXPECT_EQ(r.not_finite, 2u);
  ASSERT_TRUE(r.determined) << r.note;
  EXPECT_NEAR(r.calibration.dx, 0.02, 0.005);
  EXPECT_FALSE(commissionRsu({std::nan(""), 0}, samples).determined);
}

TEST(Commissioning, TooFewFixesDetermineNothing) {
  const auto samples = drive({100, 0}, Eigen::Vector3d::Zero(), 0.0, 0.02, steady, 0.0, 4);
  const CommissioningResult r = commissionRsu({100, 0}, std::vector<CommissioningSample>(samples.begin(), samples.begin() + 5));
  EXPECT_FALSE(r.determined);
  EXPECT_NE(r.note.find("fewer than"), std::string::npos);
}

}  // namespace
}  // namespace coloc::rsu_client
