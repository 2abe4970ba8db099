#pragma once
// One drive of the digital twin, recorded as the vehicle would have recorded it: a rosbag2 log of the
// roof LiDAR's scans, the odometry twist, each roadside unit's fixes (after its perception and an
// emulated V2I link) and ground truth; the survey map as PCD tiles; a fuse configuration. `coloc
// simulate` records one; `coloc experiment` records one per site and trial and replays it.
#include <cstdint>
#include <Eigen/Core>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "coloc/rsu_client/link_emulator.hpp"
#include "coloc/rsu_client/rsu_registry.hpp"
#include "coloc/sim/scene.hpp"

namespace coloc::twin {

struct TwinRecordingOptions {
  std::string out_dir;             ///< must be empty or absent
  rsu_client::LinkConfig link;     ///< applied to the fixes as recorded (its seed is the scenario's)
  double rsu_processing = 0.01;    ///< s from the end of the RSU's sweep to sending (simulated, so runs repeat)
  /// Empty: survey the map into out_dir/map. Otherwise the folder of an earlier survey of the same
  /// scenario, which the fuse configuration then names (trials of an experiment share one map).
  std::string map_dir;
  /// Also run the perception without each refinement (plain L-shape centre; no 0.8 m cut) on every
  /// RSU frame, into rsu_perception.csv and .svg: what each step buys.
  bool perception_ablation = true;
  std::function<void(double)> progress;  ///< share of the drive done
};

struct TwinRecordingSummary {
  double drive_seconds = 0.0, wall_seconds = 0.0;
  double map_seconds = 0.0, ray_casting_seconds = 0.0, perception_seconds = 0.0;
  std::uint64_t rays = 0, scans = 0, fixes = 0, fixes_lost = 0;
  std::string map_dir;  ///< where the map the log goes with is
  /// Per RSU id: each fix's error (x, y) against ground truth, whether the link delivered it or not.
  std::map<std::string, std::vector<Eigen::Vector2d>> fix_errors;
  /// Each odometry sample: (measured speed, true speed, measured yaw rate, true yaw rate).
  std::vector<Eigen::Vector4d> odometry;
};

/// Throws coloc::Error if the output cannot be written.
TwinRecordingSummary recordTwin(const sim::Scenario& scenario, const TwinRecordingOptions& options);

/// A scenario RSU as the vehicle's registry lists it (surveyed position, model, coverage, identity).
rsu_client::RsuInfo registryEntry(const sim::ScenarioRsu& rsu);

}  // namespace coloc::twin
