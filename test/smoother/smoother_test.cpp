#include "coloc/smoother/smoother.hpp"

#include "coloc/core/error.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <utility>
#include <vector>

namespace coloc::smoother {
namespace {

constexpr Stamp kStart = 1'700'000'000'000'000'000LL;
constexpr double kSpeed = 10.0;  // m/s along x

Stamp at(double t) { return kStart + fromSeconds(t); }

Vector6d truth(double t) { return (Vector6d() << kSpeed * t, 0.0, 0.0, 0.0, kSpeed, 0.0).finished(); }

PoseMeasurement fix(double t, double x, double y, double variance) {
  PoseMeasurement m;
  m.stamp = at(t);
  m.pose.position = {x, y, 0.0};
  m.covariance = Matrix6d::Zero();
  m.covariance.diagonal() << variance, variance, kInfinity, kInfinity, kInfinity, kInfinity;
  return m;
}

TwistMeasurement twist(double t) {
  TwistMeasurement m;
  m.stamp = at(t);
  m.linear = {kSpeed, 0.0, 0.0};
  m.covariance = Matrix6d::Zero();
  m.covariance.diagonal() << 0.04, kInfinity, kInfinity, kInfinity, kInfinity, 0.01;
  return m;
}

// Two seconds of driving: twists at 50 Hz, a heading from a yaw-only pose at the start, guesses 30 cm
// off the truth, and fixes every 100 ms stamped half-way between two states.
Smoother drive(double fix_variance) {
  Smoother s;
  for (int k = 0; k <= 100; ++k) {
    s.addTwist("odom", twist(k * 0.02));
    Vector6d g = truth(k * 0.02);
    g[0] += 0.3;
    s.addGuess(at(k * 0.02), g);
  }
  PoseMeasurement heading;
  heading.stamp = at(0.0);
  heading.covariance = Matrix6d::Zero();
  heading.covariance.diagonal() << kInfinity, kInfinity, kInfinity, kInfinity, kInfinity, 1e-6;
  EXPECT_TRUE(s.addPose("heading", heading));
  for (int k = 0; k < 20; ++k) {
    const double t = 0.1 * k + 0.01;
    EXPECT_TRUE(s.addPose("rsu", fix(t, kSpeed * t, 0.0, fix_variance)));
  }
  return s;
}

TEST(Smoother, AFixIsComparedWithTheStateAtItsExactStamp) {
  // Fixes 10 ms after a state: at the nearest state they would pull the track 10 cm back.
  const SmootherResult r = drive(1e-6).solve(at(0.0), at(2.0));
  ASSERT_TRUE(r.summary.usable()) << r.summary.report;
  EXPECT_EQ(r.summary.states, 101);
  for (const SmoothedState& s : r.states) {
    const double t = toSeconds(s.stamp - kStart);
    EXPECT_NEAR(s.state[0], kSpeed * t, 0.005) << "at " << t << " s";
    EXPECT_NEAR(s.state[1], 0.0, 0.005) << "at " << t << " s";
  }
}

TEST(Smoother, AProcessNoiseThatIsNotPositiveIsRefusedNamingIt) {
  // The motion is weighed by the inverse of its process noise: at zero the solver would evaluate an
  // infinite weight and give back its first guess as if solved. Refused when the options are given.
  const std::vector<std::pair<const char*, double SmootherOptions::*>> figures = {
      {"proc_stddev_yaw_c", &SmootherOptions::proc_stddev_yaw_c},         {"proc_stddev_vx_c", &SmootherOptions::proc_stddev_vx_c},
      {"proc_stddev_wz_c", &SmootherOptions::proc_stddev_wz_c},           {"proc_stddev_position_c", &SmootherOptions::proc_stddev_position_c},
      {"proc_stddev_yaw_bias_c", &SmootherOptions::proc_stddev_yaw_bias_c}};
  for (const auto& [name, field] : figures)
    for (const double bad : {0.0, -1.0, std::nan("")}) {
      SmootherOptions options;
      options.*field = bad;
      try {
        Smoother s(options);
        ADD_FAILURE() << name << " = " << bad << " taken";
      } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
      }
    }
}

TEST(Smoother, AnInfiniteVarianceLeavesItsComponentOutExactly) {
  Smoother s = drive(1e-6);
  // A measurement of x only, with a y 5 m off: y must not move at all.
  PoseMeasurement only_x = fix(1.05, kSpeed * 1.05, 5.0, 1e-6);
  only_x.covariance(1, 1) = kInfinity;
  ASSERT_TRUE(s.addPose("x only", only_x));
  const SmootherResult r = s.solve(at(0.0), at(2.0));
  for (const SmoothedState& st : r.states) EXPECT_NEAR(st.state[1], 0.0, 0.005);
  // A measurement of nothing planar is refused, not added as a big number.
  PoseMeasurement nothing = only_x;
  nothing.covariance(0, 0) = kInfinity;
  EXPECT_FALSE(s.addPose("nothing", nothing));
  // A NaN or negative variance refuses the measurement, whatever the other components say.
  PoseMeasurement bad = fix(1.05, kSpeed * 1.05, 0.0, 1e-6);
  bad.covariance(1, 1) = std::nan("");
  EXPECT_FALSE(s.addPose("bad", bad));
  bad.covariance(1, 1) = -1e-6;
  EXPECT_FALSE(s.addPose("bad", bad));
  TwistMeasurement bad_twist = twist(1.0);
  bad_twist.covariance(5, 5) = -0.01;
  EXPECT_FALSE(s.addTwist("bad", bad_twist));
}

TEST(Smoother, AGrossOutlierIsDownWeightedAndReported) {
  Smoother s = drive(1e-4);
  ASSERT_TRUE(s.addPose("rsu", fix(1.01, kSpeed * 1.01 + 3.0, 0.0, 1e-4)));  // a fix 3 m off
  const SmootherResult r = s.solve(at(0.0), at(2.0));
  ASSERT_TRUE(r.summary.usable()) << r.summary.report;
  const SmoothedState& near = r.states[50];  // t = 1.0 s
  EXPECT_NEAR(near.state[0], kSpeed * 1.0, 0.03);
  bool reported = false;
  for (const DownWeighted& d : r.summary.down_weighted)
    if (d.source == "rsu" && d.stamp == at(1.01)) reported = d.weight < 0.1;
  EXPECT_TRUE(reported);
}

TEST(Smoother, PositionsAreMostCertainWhereTheFixesAre) {
  Smoother s;
  for (int k = 0; k <= 100; ++k) {
    s.addTwist("odom", twist(k * 0.02));
    s.addGuess(at(k * 0.02), truth(k * 0.02));
  }
  ASSERT_TRUE(s.addPose("rsu", fix(0.2, kSpeed * 0.2, 0.0, 1e-4)));
  PoseMeasurement heading;  // the yaw, which no fix measures: without it the positions' covariance is not defined
  heading.stamp = at(0.0);
  heading.covariance = Matrix6d::Zero();
  heading.covariance.diagonal() << kInfinity, kInfinity, kInfinity, kInfinity, kInfinity, 1e-6;
  ASSERT_TRUE(s.addPose("heading", heading));
  const SmootherResult r = s.solve(at(0.0), at(2.0));
  ASSERT_TRUE(r.states[10].position_covariance && r.states[100].position_covariance);
  EXPECT_LT((*r.states[10].position_covariance)(0, 0), (*r.states[100].position_covariance)(0, 0));
  EXPECT_NEAR(std::sqrt((*r.states[10].position_covariance)(0, 0)), 0.01, 0.005);
}


}  // namespace
}  // namespace coloc::smoother

namespace coloc::smoother {
namespace {

// A drive past an RSU along x, speeding up from 4 to 12 m/s, so that a clock offset (a shift growing
// with speed) and an along-track survey offset (constant) differ; on a circle at constant speed they
// would not, nor would a rotation about the RSU. `anchored`: NDT-like poses (2 cm, 0.2 deg) every
// 100 ms. The RSU at (40, -8) has its survey off by (0.15 m, -0.05 m, 0.5 deg) and its clock 20 ms ahead.
struct BendDrive {
  static constexpr double kV0 = 4.0, kA = 0.7;
  static Vector6d at(double t, double a = kA) { return (Vector6d() << kV0 * t + 0.5 * a * t * t, 0.0, 0.0, 0.0, kV0 + a * t, 0.0).finished(); }
};

Smoother bendDrive(bool anchored, const Eigen::Vector3d& survey_error, double clock_offset, double acceleration = BendDrive::kA) {
  Smoother s;
  const Eigen::Vector2d rsu_true(40.0, -8.0);
  const Eigen::Vector2d rsu_surveyed = rsu_true + survey_error.head<2>();
  for (int k = 0; k <= 600; ++k) {
    const double t = k * 0.02;
    const Vector6d x = BendDrive::at(t, acceleration);
    TwistMeasurement tw;
    tw.stamp = at(t);
    tw.linear = {x[4], 0.0, 0.0};
    tw.angular = {0.0, 0.0, x[5]};
    tw.covariance = Matrix6d::Zero();
    tw.covariance.diagonal() << 0.0004, kInfinity, kInfinity, kInfinity, kInfinity, 0.0001;
    s.addTwist("odom", tw);
    s.addGuess(at(t), x);
    if (k % 5 == 0 && anchored) {
      PoseMeasurement ndt;
      ndt.stamp = at(t);
      ndt.pose.position = {x[0], x[1], 0.0};
      ndt.pose.orientation = quaternionFromRollPitchYaw(0.0, 0.0, x[2]);
      ndt.covariance = Matrix6d::Zero();
      ndt.covariance.diagonal() << 4e-4, 4e-4, kInfinity, kInfinity, kInfinity, 1.2e-5;
      s.addPose("ndt", ndt);
    }
    if (k % 5 == 2) {  // the RSU's fix of where the vehicle is at t, through its surveyed pose, on its clock
      const Eigen::Vector2d local = Eigen::Rotation2Dd(0.0).inverse() * (x.head<2>() - rsu_true);
      const Eigen::Vector2d reported = rsu_surveyed + Eigen::Rotation2Dd(survey_error.z()) * local;
      EXPECT_TRUE(s.addPose("/rsu/a/fix", fix(t + clock_offset, reported.x(), reported.y(), 1e-5)));
    }
  }
  s.calibrateRsu("/rsu/a/fix", rsu_surveyed);
  return s;
}

TEST(RsuCalibration, RecoversASurveyAndClockErrorFromOneDriveAnchoredByNdt) {
  const Eigen::Vector3d error(0.15, -0.05, 0.5 * M_PI / 180.0);
  const SmootherResult r = bendDrive(true, error, 0.020).solve(at(0.0), at(12.0));
  ASSERT_TRUE(r.summary.usable()) << r.summary.report;

  ASSERT_EQ(r.calibrations.size(), 1u);
  const RsuCalibration& c = r.calibrations[0];
  EXPECT_TRUE(c.observable) << c.note;
  EXPECT_NEAR(c.dx, 0.15, 0.01);
  EXPECT_NEAR(c.dy, -0.05, 0.01);
  EXPECT_NEAR(c.dyaw * 180.0 / M_PI, 0.5, 0.05);
  EXPECT_NEAR(c.clock_offset, 0.020, 0.002);
  EXPECT_GT(c.sd_dx, 0.0);
  EXPECT_LT(c.sd_dx, 0.01);
}

TEST(RsuCalibration, AtOneSpeedTheClockIsHeldAndTheSurveyAbsorbsItsAlongRoadShift) {
  // At 4 m/s throughout, a clock 20 ms ahead stamps every fix 20 ms late, where the vehicle is 8 cm
  // farther on: the fixes lag 8 cm, as a survey offset of -8 cm would make them. The clock is reported
  // as not separable, and the survey offset found is 0.15 - 0.08 m.
  const Eigen::Vector3d error(0.15, -0.05, 0.5 * M_PI / 180.0);
  const SmootherResult r = bendDrive(true, error, 0.020, 0.0).solve(at(0.0), at(12.0));
  ASSERT_TRUE(r.summary.usable()) << r.summary.report;
  ASSERT_EQ(r.calibrations.size(), 1u);
  const RsuCalibration& c = r.calibrations[0];
  EXPECT_TRUE(c.observable) << c.note;
  EXPECT_FALSE(c.clock_observable);
  EXPECT_EQ(c.clock_offset, 0.0);
  EXPECT_NEAR(c.dx, 0.15 - BendDrive::kV0 * 0.020, 0.01);
  EXPECT_NEAR(c.dy, -0.05, 0.01);
  EXPECT_NEAR(c.dyaw * 180.0 / M_PI, 0.5, 0.05);
}

TEST(RsuCalibration, WithoutAnAnchoringSourceItIsReportedUnobservableNotInvented) {
  const SmootherResult r = bendDrive(false, Eigen::Vector3d(0.15, -0.05, 0.01), 0.020).solve(at(0.0), at(12.0));
  ASSERT_EQ(r.calibrations.size(), 1u);
  EXPECT_FALSE(r.calibrations[0].observable);
  EXPECT_FALSE(r.calibrations[0].note.empty());
}

}  // namespace
}  // namespace coloc::smoother

namespace coloc::smoother {
namespace {

// A noisy drive past an RSU at (40, -8), speeding up from 4 to 12 m/s: odometry 1 % fast with a
// 0.002 rad/s gyro bias and 0.05 m/s / 0.005 rad/s noise, whose messages claim 0.2 m/s / 0.1 rad/s
// as the twin's do; NDT every 100 ms with 1 cm noise plus `ndt_bias` (a slowly varying error of
// 1.5 cm, the same in x and y, period 20 s) claiming 15 cm; within 20 m of the miscalibrated RSU,
// its fixes (2 mm).
Smoother noisyDrive(const SmootherOptions& options, bool ndt_bias, std::uint32_t seed, bool map_matching = true) {
  Smoother s(options);
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01;
  const Eigen::Vector2d rsu_true(40.0, -8.0);
  const Eigen::Vector3d error(0.15, -0.05, 0.5 * M_PI / 180.0);
  const Eigen::Vector2d rsu_surveyed = rsu_true + error.head<2>();
  for (int k = 0; k <= 600; ++k) {
    const double t = k * 0.02;
    const Vector6d x = BendDrive::at(t);
    TwistMeasurement tw;
    tw.stamp = at(t);
    tw.linear = {1.01 * x[4] + 0.05 * n01(rng), 0.0, 0.0};
    tw.angular = {0.0, 0.0, x[5] + 0.002 + 0.005 * n01(rng)};
    tw.covariance = Matrix6d::Zero();
    tw.covariance.diagonal() << 0.04, kInfinity, kInfinity, kInfinity, kInfinity, 0.01;
    s.addTwist("odom", tw);
    s.addGuess(at(t), x);
    if (k % 5 == 0) {
      const double b = ndt_bias ? 0.015 * std::sin(2.0 * M_PI * t / 20.0 + seed) : 0.0;
      PoseMeasurement ndt;
      ndt.stamp = at(t);
      ndt.pose.position = {x[0] + b + 0.01 * n01(rng), x[1] + b + 0.01 * n01(rng), 0.0};
      ndt.pose.orientation = quaternionFromRollPitchYaw(0.0, 0.0, x[2] + 0.002 * n01(rng));
      ndt.covariance = Matrix6d::Zero();
      ndt.covariance.diagonal() << 0.0225, 0.0225, kInfinity, kInfinity, kInfinity, 0.000625;
      s.addPose("ndt", ndt);
      if (map_matching) s.setPoseBias("ndt");
    }
    if (k % 5 == 2 && (x.head<2>() - rsu_true).norm() < 20.0) {
      const Eigen::Vector2d reported = rsu_surveyed + Eigen::Rotation2Dd(error.z()) * (x.head<2>() - rsu_true);
      s.addPose("/rsu/a/fix", fix(t, reported.x() + 0.002 * n01(rng), reported.y() + 0.002 * n01(rng), 4e-6));
    }
  }
  s.calibrateRsu("/rsu/a/fix", rsu_surveyed, false);
  return s;
}

const NoiseScale* noiseOf(const SmootherResult& r, const std::string& source) {
  for (const NoiseScale& n : r.summary.noise)
    if (n.source == source) return &n;
  return nullptr;
}

TEST(NoiseEstimation, ASourcesNoiseIsMeasuredOnTheDriveNotTakenFromItsMessages) {
  // The 1 cm poses as a source of independent poses (not map matching, whose error is shared from
  // pose to pose: see the next test).
  const SmootherResult r = noisyDrive(SmootherOptions{}, false, 11, false).solve(at(0.0), at(12.0));
  ASSERT_TRUE(r.summary.usable()) << r.summary.report;
  const NoiseScale* odom = noiseOf(r, "odom");
  const NoiseScale* ndt = noiseOf(r, "ndt");
  ASSERT_TRUE(odom && ndt);
  // Claimed 0.2 m/s and 0.1 rad/s, are 0.05 m/s and 0.005 rad/s: one factor for both, between them.
  EXPECT_GT(odom->scale, 0.05);
  EXPECT_LT(odom->scale, 0.25 * 1.3);
  // Claimed 15 cm, is 1 cm (x, y) and 0.002 rad against 0.025: about 1/15 and 1/12.
  EXPECT_NEAR(ndt->scale, 1.0 / 15.0, 0.5 / 15.0);
}

TEST(NoiseEstimation, MapMatchingPosesThatRepeatTheirGuessAlongACorridorDoNotOutvoteTheFixes) {
  // A corridor at 10 m/s: along the road NDT's poses repeat the dead reckoning they started from
  // (odometry 0.3 % fast, so 3 mm per metre ahead of the truth), across it they are 1 cm good; both
  // claim 15 cm. Their scatter is a centimetre, their error along the road 20-30 cm where an RSU's
  // 2 cm fixes come in (70-100 m). Taken at their scatter, they would outvote the fixes.
  Smoother s;
  std::mt19937 rng(5);
  std::normal_distribution<double> n01;
  for (int k = 0; k <= 600; ++k) {
    const double t = k * 0.02, v = 10.0;
    const Vector6d x = (Vector6d() << v * t, 0.0, 0.0, 0.0, v, 0.0).finished();
    TwistMeasurement tw;
    tw.stamp = at(t);
    tw.linear = {1.003 * v + 0.05 * n01(rng), 0.0, 0.0};
    tw.angular = {0.0, 0.0, 0.005 * n01(rng)};
    tw.covariance = Matrix6d::Zero();
    tw.covariance.diagonal() << 0.04, kInfinity, kInfinity, kInfinity, kInfinity, 0.01;
    s.addTwist("odom", tw);
    s.addGuess(at(t), x);
    if (k % 5 == 0) {
      PoseMeasurement ndt;
      ndt.stamp = at(t);
      ndt.pose.position = {1.003 * x[0] + 0.002 * n01(rng), 0.01 * n01(rng), 0.0};
      ndt.pose.orientation = quaternionFromRollPitchYaw(0.0, 0.0, 0.002 * n01(rng));
      ndt.covariance = Matrix6d::Zero();
      ndt.covariance.diagonal() << 0.0225, 0.0225, kInfinity, kInfinity, kInfinity, 0.000625;
      s.addPose("ndt", ndt);
      s.setPoseBias("ndt");
    }
    if (k % 5 == 2 && t >= 7.0 && t <= 10.0) s.addPose("/rsu/a/fix", fix(t, x[0] + 0.02 * n01(rng), x[1] + 0.02 * n01(rng), 4e-4));
  }
  const SmootherResult r = s.solve(at(0.0), at(12.0));
  ASSERT_TRUE(r.summary.usable()) << r.summary.report;
  double along = 0.0;
  int samples = 0;
  for (const SmoothedState& st : r.states) {
    const double t = toSeconds(st.stamp - at(0.0));
    if (t < 7.0 || t > 10.0) continue;
    along += std::abs(st.state[0] - 10.0 * t);
    ++samples;
  }
  ASSERT_GT(samples, 100);
  // NDT there is 21-30 cm ahead; the fixes, averaged over a few, a centimetre or less.
  EXPECT_LT(along / samples, 0.03);
  const NoiseScale* ndt = noiseOf(r, "ndt");
  ASSERT_TRUE(ndt);
  EXPECT_GE(ndt->scale, 1.0);  // never taken as better than it says while its shared error is not modelled
}

TEST(OdometryCalibration, RecoversTheSpeedScaleAndGyroBiasFromAnAnchoredDrive) {
  const SmootherResult r = noisyDrive(SmootherOptions{}, false, 12).solve(at(0.0), at(12.0));
  ASSERT_TRUE(r.summary.usable()) << r.summary.report;
  ASSERT_EQ(r.odometry.size(), 1u);
  const OdometryCalibration& o = r.odometry[0];
  EXPECT_NEAR(o.speed_scale, 1.01, 0.001);
  EXPECT_NEAR(o.yaw_rate_bias, 0.002, 0.0005);
  EXPECT_GT(o.sd_speed_scale, 0.0);
  EXPECT_LT(std::abs(o.speed_scale - 1.01), 4.0 * o.sd_speed_scale + 1e-4);
}

TEST(PoseBias, AwayFromTheFixesTheBiasIsHeldAndTheTrackFollowsNdtNotTheOdometrysSlowErrors) {
  // 12 s at 10 m/s on a straight; NDT 1 cm good and claiming it, no bias; the odometry 1 % fast with a
  // 0.002 rad/s gyro bias; a roadside fix (2 mm) only in the first 2 s. Loose everywhere, the bias
  // would take NDT's moves that the odometry does not make, and the track would follow the odometry's
  // slow errors; held beyond the fixes' reach, it stays NDT's.
  SmootherOptions options;
  options.pose_bias = true;
  options.calibrate_odometry = false;  // the odometry's errors stay in its twists
  Smoother s(options);
  std::mt19937 rng(8);
  std::normal_distribution<double> n01;
  const double v = 10.0;
  for (int k = 0; k <= 600; ++k) {
    const double t = k * 0.02;
    const Vector6d x = (Vector6d() << v * t, 0.0, 0.0, 0.0, v, 0.0).finished();
    TwistMeasurement tw;
    tw.stamp = at(t);
    tw.linear = {1.01 * v + 0.05 * n01(rng), 0.0, 0.0};
    tw.angular = {0.0, 0.0, 0.002 + 0.005 * n01(rng)};
    tw.covariance = Matrix6d::Zero();
    tw.covariance.diagonal() << 0.0025, kInfinity, kInfinity, kInfinity, kInfinity, 2.5e-5;
    s.addTwist("odom", tw);
    s.addGuess(at(t), x);
    if (k % 5 == 0) {
      PoseMeasurement ndt;
      ndt.stamp = at(t);
      ndt.pose.position = {x[0] + 0.01 * n01(rng), x[1] + 0.01 * n01(rng), 0.0};
      ndt.pose.orientation = quaternionFromRollPitchYaw(0.0, 0.0, 0.002 * n01(rng));
      ndt.covariance = Matrix6d::Zero();
      ndt.covariance.diagonal() << 1e-4, 1e-4, kInfinity, kInfinity, kInfinity, 4e-6;
      s.addPose("ndt", ndt);
      s.setPoseBias("ndt");
    }
    if (k % 5 == 2 && t < 2.0) s.addPose("/rsu/a/fix", fix(t, x[0] + 0.002 * n01(rng), x[1] + 0.002 * n01(rng), 4e-6));
  }
  const SmootherResult r = s.solve(at(0.0), at(12.0));
  ASSERT_TRUE(r.summary.usable()) << r.summary.report;
  double error = 0.0, bias = 0.0;
  int count = 0;
  for (const SmoothedState& st : r.states) {
    const double t = toSeconds(st.stamp - at(0.0));
    if (t < 6.0) continue;
    error += std::hypot(st.state[0] - v * t, st.state[1]);
    bias = std::max(bias, st.pose_bias.norm());
    ++count;
  }
  EXPECT_LT(error / count, 0.008);  // NDT's 1 cm per axis, averaged over the neighbouring scans
  EXPECT_LT(bias, 0.003);
}

TEST(PoseBias, WithABiasedAnchorTheCalibrationsUncertaintyCoversItsError) {
  // NDT 1.5 cm off for seconds at a time anchors the RSU's calibration: without the bias modelled NDT
  // is taken at its claimed 15 cm (never better: see above), so the calibration is uncertain but
  // its error larger; modelled, the uncertainty includes NDT's bias and the estimate is better.
  int covered_without = 0, covered_with = 0;
  double error_with = 0.0, error_without = 0.0;  // mean over the seeds, m
  for (std::uint32_t seed = 21; seed < 26; ++seed) {
    SmootherOptions plain, biased;
    biased.pose_bias = true;
    for (const auto& [options, covered] : {std::pair{plain, &covered_without}, std::pair{biased, &covered_with}}) {
      const SmootherResult r = noisyDrive(options, true, seed).solve(at(0.0), at(12.0));
      ASSERT_TRUE(r.summary.usable()) << r.summary.report;
      const RsuCalibration& c = r.calibrations[0];
      ASSERT_TRUE(c.observable) << c.note;
      const double e = std::hypot(c.dx - 0.15, c.dy + 0.05), sd = std::hypot(c.sd_dx, c.sd_dy);
      if (e < 3.0 * sd) ++*covered;
      (options.pose_bias ? error_with : error_without) += e / 5.0;
      if (options.pose_bias) {
        EXPECT_LT(sd, 0.05);  // still an estimate worth having
      }
    }
  }
  EXPECT_GE(covered_with, 4);
  // And the estimate itself is better: the bias is no longer read as the RSU's survey error.
  EXPECT_LT(error_with, 0.7 * error_without);
}

}  // namespace
}  // namespace coloc::smoother
