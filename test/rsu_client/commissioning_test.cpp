// Commissioning an RSU against a reference vehicle: its survey and clock error from one drive past it.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>

#include "coloc/rsu_client/commissioning.hpp"
#include "coloc/rsu_client/fix_error_model.hpp"

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

namespace coloc::rsu_client {
namespace {

// Fixes 3-50 m from an RSU with 1 cm along the line of sight and, across it, 1 cm plus 1.5 mrad of
// bearing: each 10 m band gives both back at its mean range within their sampling spread (about 5 %
// over some 800 fixes a band); a residual that is NaN is left out, not taken as 0, and a band with
// too few fixes gives no row.
TEST(FixErrorModel, EachRangeBandGivesTheErrorAlongAndAcrossTheLineOfSight) {
  std::mt19937 rng(7);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::uniform_real_distribution<double> range(3.0, 50.0), angle(-M_PI, M_PI);
  const Eigen::Vector2d rsu(100.0, -5.0);
  std::vector<Eigen::Vector2d> fixes, residuals;
  auto across_sd = [](double r) { return std::sqrt(0.01 * 0.01 + std::pow(0.0015 * r, 2)); };
  for (int i = 0; i < 4000; ++i) {
    const double r = range(rng), a = angle(rng);
    const Eigen::Vector2d u(std::cos(a), std::sin(a)), across(-u.y(), u.x());
    fixes.push_back(rsu + r * u);
    residuals.push_back(0.01 * unit(rng) * u + across_sd(r) * unit(rng) * across);
  }
  fixes.push_back(rsu + Eigen::Vector2d(0, 70));  // alone in the 70-80 m band
  residuals.push_back(Eigen::Vector2d(0.5, 0.5));
  residuals[5] = Eigen::Vector2d(std::nan(""), 0.0);
  const std::vector<RsuInfo::ErrorAtRange> table = fixErrorByRange(rsu, fixes, residuals, 10.0, 5);
  ASSERT_EQ(table.size(), 5u);  // 0-10 ... 40-50 m; 70-80 m has one fix
  for (const RsuInfo::ErrorAtRange& row : table) {
    EXPECT_NEAR(row.along_sd, 0.01, 0.0006) << row.range;
    // The band's mean square across is the mean of across_sd^2 over its ranges: at its mean range
    // to within the curvature of r^2 over 10 m (under 1 %).
    EXPECT_NEAR(row.across_sd, across_sd(row.range), 0.05 * across_sd(row.range)) << row.range;
  }
  EXPECT_NEAR(table[2].range, 25.0, 0.5);
  for (const RsuInfo::ErrorAtRange& row : table) EXPECT_EQ(row.left_mean, 0.0);  // not asked for
  // A mean error of 2 cm to the right of the vehicle and 0.5 cm behind it, the vehicle coming
  // (heading west, towards the RSU's x) or going (east) at random: across the line of sight the
  // pull has either sign, in the vehicle's frame one. Each band gives it back within three standard
  // errors of its mean, and its spread about it.
  std::uniform_int_distribution<int> way(0, 1);
  std::vector<Eigen::Vector2d> pulled = residuals;
  std::vector<double> headings;
  for (std::size_t i = 0; i < fixes.size(); ++i) {
    const double yaw = way(rng) ? 0.0 : M_PI;
    const Eigen::Vector2d forward(std::cos(yaw), std::sin(yaw)), left(-forward.y(), forward.x());
    pulled[i] += -0.02 * left - 0.005 * forward;
    headings.push_back(yaw);
  }
  headings[9] = std::nan("");  // a fix without a heading is left out of the means and spreads
  const std::vector<RsuInfo::ErrorAtRange> with_mean = fixErrorByRange(rsu, fixes, pulled, 10.0, 5, headings);
  ASSERT_EQ(with_mean.size(), 5u);
  for (const RsuInfo::ErrorAtRange& row : with_mean) {
    EXPECT_NEAR(row.forward_mean, -0.005, 3.0 * 0.05 / std::sqrt(700.0)) << row.range;
    EXPECT_NEAR(row.left_mean, -0.02, 3.0 * 0.05 / std::sqrt(700.0)) << row.range;
    EXPECT_NEAR(row.along_sd, 0.01, 0.0006) << row.range;
    EXPECT_NEAR(row.across_sd, across_sd(row.range), 0.05 * across_sd(row.range)) << row.range;
  }
  EXPECT_TRUE(fixErrorByRange(rsu, fixes, pulled, 10.0, 5, {headings.begin(), headings.begin() + 10}).empty());  // sizes differ
  EXPECT_TRUE(fixErrorByRange(rsu, {fixes.begin(), fixes.begin() + 4}, {residuals.begin(), residuals.begin() + 4}, 10.0, 5).empty());
  EXPECT_TRUE(fixErrorByRange(rsu, fixes, {residuals.begin(), residuals.begin() + 10}, 10.0, 5).empty());
}

}  // namespace
}  // namespace coloc::rsu_client
