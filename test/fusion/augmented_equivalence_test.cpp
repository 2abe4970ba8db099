// coloc's history-replay filter against an independent implementation of Autoware's augmented-state
// filter, fed the same measurements with the same delays and smoothing schedule.
#include <gtest/gtest.h>

#include "augmented_state_ekf.hpp"
#include "measurement_record.hpp"
#include "drive.hpp"

namespace coloc::fusion {
namespace {

using namespace coloc::testing;

struct Use {
  int first_tick;  // tick of the first use
  int delay;       // ticks back at the first use
  int uses_left;
  int uses_total;
  UpdateRecord record;
};

// Mirrors Localizer's schedule: first use at once, the others on the following ticks, in acceptance order.
class ReferenceDriver {
 public:
  explicit ReferenceDriver(AugmentedStateEkf& ekf) : ekf_(ekf) {}

  void tick(int k) {
    ekf_.predict();
    for (auto it = active_.begin(); it != active_.end();) {
      apply(it->record, it->delay + (k - it->first_tick), it->uses_total);
      it = --it->uses_left == 0 ? active_.erase(it) : it + 1;
    }
  }

  void feed(const UpdateRecord& record, int k, int delay, int steps) {
    apply(record, delay, steps);
    if (steps > 1) active_.push_back({k, delay, steps - 1, steps, record});
  }

 private:
  void apply(const UpdateRecord& r, int delay, int scale) {
    std::vector<int> index(r.index.begin(), r.index.begin() + r.m);
    Eigen::VectorXd y(r.m);
    for (int i = 0; i < r.m; ++i) y[i] = r.value[i];
    ASSERT_TRUE(ekf_.update(delay, index, y, scale * r.R.topLeftCorner(r.m, r.m)));
  }

  AugmentedStateEkf& ekf_;
  std::vector<Use> active_;
};

EkfConfig frozenConfig() {
  EkfConfig c = quietConfig();
  c.relinearize_on_replay = false;
  c.pose_gate_alpha = c.twist_gate_alpha = 0.0;  // the reference has no gate
  return c;
}

TEST(AugmentedEquivalence, FrozenLinearizationReproducesAutowaresAugmentedStateFilter) {
  const EkfConfig config = frozenConfig();
  const Drive drive;
  Localizer localizer = startedLocalizer(config);
  AugmentedStateEkf reference(config.history_steps, {config.proc_stddev_yaw_c, config.proc_stddev_vx_c, config.proc_stddev_wz_c},
                              1.0 / config.predict_frequency);
  Vector6d x0 = localizer.estimate()->state;
  reference.initialize(x0, localizer.estimate()->state_covariance);
  ReferenceDriver driver(reference);

  double largest_difference = 0.0;
  for (int k = 1; k <= 300; ++k) {
    localizer.advanceTo(kStart + k * kTick);
    driver.tick(k);
    if (k < 10) continue;  // stay clear of the ticks before initialisation, which Autoware fills with copies
    // Odometry one tick late, NDT at 10 Hz four ticks late, RSU fixes at 10 Hz two ticks late.
    const TwistMeasurement odom = twist(kStart + (k - 1) * kTick, drive.speed * 1.01, drive.yaw_rate - 0.002);
    ASSERT_TRUE(localizer.feedTwist("odom", odom).applied());
    driver.feed(std::get<UpdateRecord>(makeTwistRecord(odom, 0.0)), k, 1, config.twist_smoothing_steps);
    if (k % 5 == 0) {
      const PoseMeasurement ndt = ndtPoseAt(drive, k - 4);
      ASSERT_TRUE(localizer.feedPose("ndt", ndt).applied());
      driver.feed(std::get<UpdateRecord>(makePoseRecord(ndt)), k, 4, config.pose_smoothing_steps);
    }
    if (k % 5 == 2 && k > 150) {
      const PoseMeasurement fix = rsuFixAt(drive, k - 2);
      ASSERT_TRUE(localizer.feedPose("rsu", fix).applied());
      driver.feed(std::get<UpdateRecord>(makePoseRecord(fix)), k, 2, config.pose_smoothing_steps);
    }
    const Estimate e = *localizer.estimate();
    largest_difference = std::max(largest_difference, (e.state - reference.latest()).cwiseAbs().maxCoeff());
    largest_difference = std::max(largest_difference, (e.state_covariance - reference.latestCovariance()).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(largest_difference, 1e-9);
}

TEST(AugmentedEquivalence, RelinearizedReplayDiffersFromAugmentedFilterOnlyAtSecondOrder) {
  // The augmented filter carries a late correction forward with Jacobians taken before it; replaying
  // re-evaluates them. The difference must grow with the square of the correction. Without smoothing
  // nothing is replayed before the pose, so both filters are identical up to it.
  auto difference = [](double offset) {
    EkfConfig relinearize = quietConfig();
    relinearize.pose_smoothing_steps = relinearize.twist_smoothing_steps = 1;
    EkfConfig frozen_config = relinearize;
    frozen_config.relinearize_on_replay = false;
    const Drive drive;
    Localizer relinearized = startedLocalizer(relinearize), frozen = startedLocalizer(frozen_config);
    Vector6d at_stamp = Vector6d::Zero();
    for (int k = 1; k <= 60; ++k) {
      driveTick(relinearized, drive, k);
      driveTick(frozen, drive, k);
      if (k == 20) at_stamp = relinearized.estimate()->state;
    }
    const PoseMeasurement pose =
        planarPose(kStart + 20 * kTick, at_stamp[0] + offset, at_stamp[1] - offset, at_stamp[2] + offset);
    relinearized.feedPose("ndt", pose);
    frozen.feedPose("ndt", pose);
    return (relinearized.estimate()->state - frozen.estimate()->state).head<3>().norm();
  };
  const double large = difference(0.02), small = difference(0.01);
  EXPECT_GT(large, 1e-9);
  EXPECT_NEAR(large / small, 4.0, 0.4);
}

}  // namespace
}  // namespace coloc::fusion
