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

#include "coloc/io/ros_messages.hpp"
#include <vector>

#include "coloc/core/time.hpp"
#include "coloc/rsu_client/commissioning.hpp"
#include "coloc/rsu_client/link_emulator.hpp"
#include "coloc/rsu_client/rsu_registry.hpp"
#include "coloc/sim/sweep_cache.hpp"
#include "coloc/roadside/roadside_perception.hpp"
#include "coloc/sim/scene.hpp"

namespace coloc::replay {
class RecordedLog;
}  // namespace coloc::replay

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
  /// Also image every RSU frame in the ideal twin (box-shaped car, perfect survey and clock, constant
  /// range noise, no dropouts) and fix it: the fix error the error sources cost, paired frame by frame.
  bool ideal_comparison = false;
  std::function<void(double)> progress;  ///< share of the drive done
  /// The roof LiDAR's ray hits shared with other drives of the same scenario's world (trials differ in
  /// their draws, not in what the rays hit); none: every sweep is cast.
  std::shared_ptr<sim::SweepCache> roof_sweeps;
  /// The same for the RSUs' frames (the RSUs' true poses, the vehicle's path and the traffic are the
  /// same on every trial; their survey errors are not where the LiDARs are, only where the registry says).
  std::shared_ptr<sim::SweepCache> rsu_frames;
  /// Write the log to out_dir/log (rosbag2). Off, with keep_log: the drive exists in memory only,
  /// which spares the disk a few hundred MB per drive and the replays reading it back.
  bool write_log = true;
  /// Hand the log back in memory (TwinRecordingSummary::log), as a rosbag2 reader would give it.
  bool keep_log = false;
  /// Also record each RSU's fixes as the same RSU would send them if its survey and clock were perfect:
  /// the same frames, detections, link and stamp jitter, reported through its true pose and stamped
  /// on the vehicle's clock, on the topic of perfectRsuId(id) (registryEntry of the RSU without its
  /// survey error and clock offset, under that id). What a calibration is worth, on one drive.
  bool perfect_rsus = false;
  /// An analysis bound, not a perception: each RSU withholds every fix whose position (before its
  /// survey error) is farther than this from the vehicle's true position, which no RSU can know; such
  /// frames count as refused (roadside::Refusal::kBeyondOracleLimit). What a perception that never sent a
  /// fix of the tails would give. m; 0: off.
  double oracle_fix_limit = 0.0;
  /// Also record what an RSU's own node takes in (coloc rsu-node): each RSU's LiDAR frames on
  /// /rsu/<id>/points, in its sensor frame, and every connected vehicle's CAM on /v2x/cam (10 Hz, the
  /// vehicle's own 0.3 m error, its size in 0.1 m steps). Several MB per second of drive per RSU.
  bool record_rsu_frames = false;
  /// Also commissioning samples (TwinRecordingSummary::probe_fix_samples) from each frame fitted with
  /// the vehicle's own size instead of the size its CAM rounds (errors.cam_size_step): a commissioning
  /// probe whose size the operator enters to the millimetre. The fixes sent are unchanged.
  bool probe_size_for_commissioning = false;
  /// Frames of the busy street (its traffic and parked cars, not the vehicle) each RSU learns its
  /// background from before the drive (roadside::BackgroundLearner), as an RSU on site does. 0: a frame
  /// of the empty street as the map surveyed it, which no real RSU has.
  int rsu_commissioning_frames = 20;
};

/// The id under which TwinRecordingOptions::perfect_rsus records an RSU's perfect twin.
std::string perfectRsuId(const std::string& id);

/// A roadside fix as an RSU sends it under the protocol (docs/rsu-protocol.md): addressed to
/// the vehicle of `station_id`, the RSU's variance on x and y, not measured elsewhere.
io::Odometry addressedFix(Stamp stamp, const Eigen::Vector2d& position, double variance, std::uint32_t station_id);
/// The same with the covariance of the fix's own fit (map frame, m^2; roadside/fix_covariance.hpp),
/// never below `floor`, the registry's figure for the RSU's LiDAR (what a vehicle refuses as surer
/// than that), in any direction: each principal variance raised to it where below. A covariance that
/// is not finite sends the floor.
io::Odometry addressedFix(Stamp stamp, const Eigen::Vector2d& position, const Eigen::Matrix2d& covariance, double floor, std::uint32_t station_id);

/// One RSU frame within coverage: what the perception made of it.
struct RsuFrameRecord {
  double distance = 0.0;       ///< m, vehicle to RSU
  bool neighbours = false;     ///< another road user within 10 m of the ego vehicle
  bool found = false;          ///< a fix was sent
  roadside::Refusal refusal = roadside::Refusal::kNone;
  double error = 0.0;          ///< m, planar, when found
  double ideal_error = -1.0;   ///< m, the ideal twin's fix on the same frame (< 0: none or not run)
  std::size_t fit_points = 0;  ///< points the L-shape fit had
};

struct TwinRecordingSummary {
  double drive_seconds = 0.0, wall_seconds = 0.0;
  double map_seconds = 0.0, perception_seconds = 0.0;
  double ray_casting_seconds = 0.0;  ///< casting the rays of the sweeps not taken from a cache (and the scene's moves for them)
  double lidar_seconds = 0.0;        ///< the LiDAR model on the hits: noise and dropouts, every sweep
  std::uint64_t rays = 0;            ///< rays cast
  std::uint64_t reused_sweeps = 0;   ///< sweeps and frames whose hits came from TwinRecordingOptions' caches
  std::uint64_t scans = 0, fixes = 0, fixes_lost = 0;
  /// Fixes the RSUs sent the other connected vehicles (traffic with a station id), on the ego's log too.
  std::uint64_t connected_fixes = 0;
  std::string map_dir;  ///< where the map the log goes with is
  /// Per RSU id: each fix's error (x, y) against ground truth, whether the link delivered it or not.
  std::map<std::string, std::vector<Eigen::Vector2d>> fix_errors;
  /// Per RSU id: each of those fixes as the RSU reported it (through its surveyed pose) with the
  /// vehicle's true position and velocity at the fix's stamp: what commissioning the RSU against a
  /// reference vehicle's RTK/INS log takes.
  std::map<std::string, std::vector<rsu_client::CommissioningSample>> fix_samples;
  /// The same with the vehicle's own size instead of its CAM's (TwinRecordingOptions::probe_size_for_commissioning);
  /// empty where the two sizes are equal.
  std::map<std::string, std::vector<rsu_client::CommissioningSample>> probe_fix_samples;
  /// Per RSU id: each fix_samples entry's covariance from its own fit, as the RSU reports it (map
  /// frame, m^2; before the floor of the LiDAR's figure): what the fix says of itself.
  std::map<std::string, std::vector<Eigen::Matrix2d>> fix_covariances;
  double ego_length = 0.0, ego_width = 0.0;  ///< m, the ego's body, which its CAM sends rounded (errors.cam_size_step)
  /// The vehicle's true position at every ground-truth sample the log has (100 Hz).
  std::vector<std::pair<Stamp, Eigen::Vector2d>> truth;
  /// Each odometry sample: (measured speed, true speed, measured yaw rate, true yaw rate).
  std::vector<Eigen::Vector4d> odometry;
  /// Per RSU id: every frame within its coverage.
  std::map<std::string, std::vector<RsuFrameRecord>> rsu_frames;
  /// The log, when TwinRecordingOptions::keep_log (replay::ReplayCache::add replays it as if read).
  std::shared_ptr<const replay::RecordedLog> log;
};

/// Throws coloc::Error if the output cannot be written.
TwinRecordingSummary recordTwin(const sim::Scenario& scenario, const TwinRecordingOptions& options);

/// A scenario RSU as the vehicle's registry lists it (surveyed position, model, coverage, identity).
rsu_client::RsuInfo registryEntry(const sim::ScenarioRsu& rsu);

}  // namespace coloc::twin
