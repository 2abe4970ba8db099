#pragma once
// A roadside unit's perception over time, as its node runs it: the connected vehicles' CAMs (the
// latest of each), its LiDAR's frames, the background learned from them (a commissioning period first,
// then kept up to date as the scene changes), and per frame a fix for each connected vehicle in
// coverage, or the reason there is none. Each vehicle has its own track (FixConsistency): a fix is for
// the vehicle whose CAM found it, addressed to its station id. Nothing here knows DDS or files.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include "coloc/core/time.hpp"
#include "coloc/roadside/background_model.hpp"
#include "coloc/roadside/fix_consistency.hpp"
#include "coloc/roadside/roadside_perception.hpp"

namespace coloc::roadside {

/// What a connected vehicle's CAM tells the RSU, in the map frame.
struct ConnectedVehicle {
  Stamp stamp = 0;  ///< the CAM's generation time
  std::uint32_t station_id = 0;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();  ///< of the body's footprint
  double heading = 0.0, speed = 0.0, yaw_rate = 0.0;
  double length = 0.0, width = 0.0;
};

struct RsuStationConfig {
  double coverage = 60.0;         ///< m from the LiDAR: vehicles farther are not looked for
  double max_cam_age = 1.0;       ///< s between a CAM and the frame it is used in (CAMs come at 1-10 Hz)
  double forget_after = 10.0;     ///< s without a CAM after which a vehicle and its track are forgotten
  int commissioning_frames = 50;  ///< frames learned before the first fix
  int refresh_frames = 100;       ///< afterwards, the background is rebuilt from what was learned this often
  /// Afterwards, one frame in this many is learned: the background changes over minutes, and learning
  /// a 64-beam frame costs about as much as looking for two vehicles in it.
  int learn_every = 5;
  /// Take the LiDAR's roll and pitch from the road its background shows (RoadSurface's plane in the
  /// sensor frame) instead of the mount's: for a pole whose tilt nobody measured. The tilt to the road,
  /// so a road's grade is counted as tilt.
  bool level_from_ground = false;
  BackgroundConfig background = [] {
    BackgroundConfig b;
    b.decay = 1.0 / 600.0;  // per frame learned: five minutes at 10 Hz learning every 5th frame; a car parked longer becomes background
    return b;
  }();
  RoadsidePerceptionConfig perception;
};

struct StationOutcome {
  std::uint32_t station_id = 0;
  VehicleDetection detection;  ///< found: a fix to send (position, yaw in the map frame, stamp)
  double distance = 0.0;       ///< m, from the LiDAR to the CAM's vehicle
};

struct StationCounters {
  std::uint64_t frames = 0, commissioning_frames = 0, cams = 0, cams_refused = 0, fixes = 0;
  std::array<std::uint64_t, kRefusalCount> refused{};  ///< per Refusal
  std::uint64_t background_rebuilds = 0;
  /// Fixes whose box was placed with a side the vehicle's frames measured shorter than its CAM's
  /// (a CAM box larger than the body: body_size.hpp).
  std::uint64_t fixes_with_measured_size = 0;
  std::uint64_t clock_resets = 0;  ///< frames stamped more than 1 s before the last: CAMs and tracks forgotten
};

class RsuStation {
 public:
  RsuStation(const RsuMount& mount, RsuStationConfig config = {});
  ~RsuStation();
  RsuStation(RsuStation&&) noexcept;
  RsuStation& operator=(RsuStation&&) noexcept;

  /// A CAM. One that is not finite, has no size, or is older than the vehicle's last is refused
  /// (false, counted); one older by more than forget_after starts the vehicle afresh (its clock went back).
  bool addVehicle(const ConnectedVehicle& vehicle);
  /// A frame (sensor frame) captured at `stamp`: learned into the background; once commissioned, each
  /// connected vehicle within coverage whose CAM is recent is looked for, and its outcome returned.
  std::vector<StationOutcome> frame(const std::vector<Eigen::Vector3f>& points, Stamp stamp);

  /// Commissioning from a period of frames given beforehand (a recording of the site): each is learned
  /// into the background only; commission() then builds the perception from what was learned, and
  /// frame() looks for vehicles from its first call.
  void learn(const std::vector<Eigen::Vector3f>& points);
  bool commission();
  /// Commissioning from a frame of the empty scene (a survey's) instead: the perception is built from
  /// it as it is, and it is learned as a first frame, so that the background kept up to date from the
  /// frames that follow starts from it. False (and nothing changes) if the frame has no finite point.
  bool commission(const std::vector<Eigen::Vector3f>& empty_scene);

  /// The background learned so far (BackgroundLearner::background), sensor frame.
  std::vector<Eigen::Vector3f> background() const;
  /// The perception frame() uses, null before commissioning: to fit a frame otherwise than frame() does
  /// (another size, a probe), without the vehicles' tracks.
  const RoadsidePerception* perception() const;

  bool commissioned() const;
  const StationCounters& counters() const;
  const RsuMount& mount() const;
  /// The LiDAR's roll, pitch and height over the road as its background showed them, once commissioned
  /// with level_from_ground (then the mount's roll and pitch are these).
  std::optional<Levelling> levelling() const;
  /// Connected vehicles whose CAM is recent enough to be kept (RsuStationConfig::forget_after).
  std::size_t vehiclesKnown() const;
  /// The road found in the background (its plane in the map frame), once commissioned.
  std::optional<GroundPlane> roadPlane() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace coloc::roadside
