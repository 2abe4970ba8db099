// On a linear-Gaussian problem the smoother's last state is the Kalman filter's: both are the mean of
// the same posterior given every measurement up to then. Checked against coloc's own filter, configured
// so that the two share a model: the forward step, each measurement applied whole at its own tick, no
// gates; a straight drive keeps the motion model linear to second order.
#include <gtest/gtest.h>

#include <random>

#include "coloc/fusion/localizer.hpp"
#include "coloc/smoother/smoother.hpp"
#include "measurements.hpp"

namespace coloc::smoother {
namespace {

using testing::kStart;
using testing::kTick;
using testing::planarPose;

TEST(SmootherAndFilter, OnALinearGaussianDriveTheSmoothersLastStateIsTheFilters) {
  fusion::EkfConfig c;
  c.auto_initialize = false;
  c.pose_smoothing_steps = 1;
  c.twist_smoothing_steps = 1;
  c.pose_gate_alpha = 0.0;
  c.twist_gate_alpha = 0.0;
  fusion::Localizer filter(c);
  const fusion::SourceId ndt = filter.addPoseSource("ndt"), rsu = filter.addPoseSource("rsu"), odom = filter.addTwistSource("odom");
  filter.initialize(planarPose(kStart, 0.0, 0.0, 0.0, 0.01, 1e-4));
  const fusion::Estimate start = *filter.estimate();

  SmootherOptions o;
  o.trapezoid = false;
  o.robust = false;
  o.estimate_noise = false;  // the filter takes the covariances as given
  o.calibrate_odometry = false;  // and the odometry as it reads
  o.proc_stddev_position_c = 1e-4;  // the filter's are 0; a batch problem needs a finite weight
  o.proc_stddev_yaw_bias_c = 1e-6;
  Smoother smoother(o);
  ASSERT_TRUE(smoother.addPrior(start.stamp, start.state, start.state_covariance));

  std::mt19937 rng(3);
  std::normal_distribution<double> n01;
  const double speed = 10.0;
  const int ticks = 250;  // 5 s
  std::vector<double> sd_x;
  // The speed is measured before the first step: the filter then linearises its motion at about the
  // right speed from the start, as the smoother does (from 0 m/s, its first step would not be linear).
  for (int k = 0; k <= ticks; ++k) {
    const Stamp t = kStart + k * kTick;
    const double x = speed * k * 0.02;
    if (k > 0) {
      ASSERT_TRUE(!filter.advanceTo(t).rejected());
    }
    TwistMeasurement tw;
    tw.stamp = t;
    tw.linear = {speed + 0.1 * n01(rng), 0.0, 0.0};
    tw.angular = {0.0, 0.0, 0.001 * n01(rng)};
    tw.covariance = Matrix6d::Zero();
    tw.covariance.diagonal() << 0.01, kInfinity, kInfinity, kInfinity, kInfinity, 1e-6;
    ASSERT_TRUE(filter.feedTwist(odom, tw).applied());
    ASSERT_TRUE(smoother.addTwist("odom", tw));
    if (k % 5 == 0 && k > 0) {
      const PoseMeasurement p = planarPose(t, x + 0.1 * n01(rng), 0.1 * n01(rng), 0.005 * n01(rng), 0.01, 2.5e-5);
      ASSERT_TRUE(filter.feedPose(ndt, p).applied());
      ASSERT_TRUE(smoother.addPose("ndt", p));
    }
    if (k % 5 == 2 && k > 100 && k < 150) {  // a second of roadside fixes, x and y only
      PoseMeasurement f = planarPose(t, x + 0.01 * n01(rng), 0.01 * n01(rng), 0.0, 1e-4, 1.0);
      f.covariance(5, 5) = kInfinity;
      ASSERT_TRUE(filter.feedPose(rsu, f).applied());
      ASSERT_TRUE(smoother.addPose("rsu", f));
    }
    const fusion::Estimate e = *filter.estimate();
    smoother.addGuess(t, e.state);
    sd_x.push_back(std::sqrt(e.state_covariance(0, 0)));
  }
  const fusion::Estimate last = *filter.estimate();
  const SmootherResult r = smoother.solve(start.stamp, last.stamp);
  ASSERT_TRUE(r.summary.usable()) << r.summary.report;
  ASSERT_EQ(r.states.back().stamp, last.stamp);

  // The same mean, to within 2 % of its standard deviation in every component (measured: at most 0.9 %,
  // the EKF linearising at its estimates of the time, the smoother at the final ones).
  const Vector6d& s = r.states.back().state;
  for (int i = 0; i < 6; ++i) {
    const double sd = std::sqrt(last.state_covariance(i, i));
    EXPECT_LT(std::abs(s[i] - last.state[i]), 0.02 * sd) << "state " << i << ": smoother " << s[i] << ", filter " << last.state[i];
  }
  // The same uncertainty of the position, to 1 %.
  ASSERT_TRUE(r.states.back().position_covariance);
  const Eigen::Matrix2d& P = *r.states.back().position_covariance;
  EXPECT_NEAR(P(0, 0), last.state_covariance(0, 0), 0.01 * last.state_covariance(0, 0));
  EXPECT_NEAR(P(1, 1), last.state_covariance(1, 1), 0.01 * last.state_covariance(1, 1));
  // Where the future helps, it is not the filter: before the fixes the smoother is surer of x.
  const std::size_t before = 90;  // 1.8 s, 0.2 s before the first fix
  ASSERT_TRUE(r.states[before].position_covariance);
  EXPECT_LT(std::sqrt((*r.states[before].position_covariance)(0, 0)), 0.5 * sd_x[before]);
}

}  // namespace
}  // namespace coloc::smoother
