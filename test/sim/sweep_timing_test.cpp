// The time conventions of a LiDAR sweep, end to end: the simulated sensor stamps a sweep at its start and
// gives each point its time since then (as Velodyne drivers with per-point time do), deskewing moves
// every point to the sensor's frame at that start, and NDT's result is therefore the pose at the
// scan's stamp. A sweep of a well-structured street taken while driving must match there to within a
// centimetre at any speed; without deskewing it matches ahead of it.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "coloc/ndt/aligner.hpp"
#include "coloc/ndt/ndt_target.hpp"
#include "coloc/ndt/preprocess.hpp"
#include "coloc/sim/lidar_model.hpp"
#include "coloc/sim/ray_caster.hpp"
#include "coloc/sim/scene.hpp"
#include "coloc/sim/survey_map.hpp"
#include "coloc/sim/vehicle_motion.hpp"

namespace coloc::sim {
namespace {

constexpr double kLidarHeight = 1.9;

// A straight street with buildings, poles and trees on both sides: NDT is well constrained along it.
const char* kStreet = R"(
name: street
seed: 5
ground: {min: [-20, -30], max: [220, 30]}
objects:
  - {type: building, center: [20, 16], size: [20, 8, 9]}
  - {type: building, center: [55, -17], size: [14, 10, 12]}
  - {type: building, center: [90, 18], size: [24, 10, 8]}
  - {type: building, center: [130, -16], size: [18, 8, 10]}
  - {type: pole, at: [35, -7], height: 6}
  - {type: pole, at: [70, 7], height: 6}
  - {type: pole, at: [105, -7], height: 6}
  - {type: pole, at: [115, 7], height: 6}
  - {type: tree, at: [48, 8], height: 5, crown: 2.0}
  - {type: tree, at: [80, -8], height: 5, crown: 2.5}
  - {type: parked_car, at: [62, -6.5], yaw: 0.0}
route:
  start: [0, -1.75]
  heading: 0.0
  pieces: [{length: 200}]
  speed: 10.0
vehicle: {lidar: VLP-32C, lidar_height: 1.9}
errors: {preset: ideal}  # an exact map: only the sweep's timing may show
)";

Eigen::Isometry3d lidarPose(const VehicleState& s) {
  return Eigen::Translation3d(s.position.x(), s.position.y(), kLidarHeight) * Eigen::AngleAxisd(s.yaw, Eigen::Vector3d::UnitZ());
}

class SweepTiming : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scenario_ = new Scenario(parseScenario(kStreet, "street"));
    world_ = new RayCaster();
    for (const TriangleMesh& m : scenario_->worldMeshes()) world_->addMesh(m);
    world_->commit();
    target_ = new ndt::NdtTarget(surveyMap(*scenario_, {}), ndt::NdtConfig{});
  }
  static void TearDownTestSuite() {
    delete target_;
    delete world_;
    delete scenario_;
  }

  // Along-track error (m, + ahead) of NDT's result for a sweep that starts when the vehicle, cruising
  // at `speed`, passes x = 70 m, against the LiDAR's true pose at the sweep's start (its stamp).
  static double alongTrackError(double speed, bool deskew) {
    const Drive drive(Route(scenario_->route_start, scenario_->route_heading, scenario_->route), SpeedProfile{speed, 100.0});
    double t0 = 0.0;
    while (drive.at(t0).position.x() < 70.0) t0 += 0.001;
    EXPECT_NEAR(drive.at(t0).speed, speed, 1e-9) << "the sweep must be taken at cruise";
    RandomEngine rng(11);
    const auto sweep = scanSweep(vlp32c(), *world_, [&](double dt) { return lidarPose(drive.at(t0 + dt)); }, rng);
    ndt::PointCloud cloud;
    for (const LidarPoint& p : sweep) {
      cloud.points.push_back(p.position);
      cloud.times.push_back(p.time);
    }
    ndt::PreprocessConfig pre;  // coloc's defaults, as the pipeline runs them
    pre.deskew = deskew;
    const ndt::PointCloud scan = ndt::preprocessScan(cloud, pre, speed, 0.0);
    const Eigen::Isometry3d truth = lidarPose(drive.at(t0));
    Eigen::Matrix4d guess = truth.matrix();
    guess(0, 3) += 0.3;  // a prediction 30 cm off
    guess(1, 3) -= 0.1;
    const ndt::AlignResult r = ndt::align(*target_, scan, guess, ndt::NdtConfig{});
    EXPECT_TRUE(r.accepted()) << r.detail;
    const Eigen::Vector3d d = r.transform.topRightCorner<3, 1>() - truth.translation();
    EXPECT_LT(std::abs(d.y()), 0.01) << "across-track at " << speed << " m/s";
    return d.x();
  }

  static Scenario* scenario_;
  static RayCaster* world_;
  static ndt::NdtTarget* target_;
};
Scenario* SweepTiming::scenario_ = nullptr;
RayCaster* SweepTiming::world_ = nullptr;
ndt::NdtTarget* SweepTiming::target_ = nullptr;

TEST_F(SweepTiming, ADeskewedSweepMatchesThePoseAtItsStampAtAnySpeed) {
  for (double speed : {5.0, 10.0, 20.0}) EXPECT_NEAR(alongTrackError(speed, true), 0.0, 0.01) << speed << " m/s";
}

TEST_F(SweepTiming, WithoutDeskewingTheMatchIsAheadOfTheStamp) {
  // The points were taken after the stamp, on average half a sweep later: the undistorted match lies
  // ahead, by how much depends on where the structure is in the sweep (a third of the way here).
  for (double speed : {10.0, 20.0}) EXPECT_GT(alongTrackError(speed, false), 0.01 * speed) << speed << " m/s";
}

}  // namespace
}  // namespace coloc::sim
