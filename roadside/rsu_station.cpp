#include "coloc/roadside/rsu_station.hpp"

#include <algorithm>
#include <cmath>

#include "coloc/core/error.hpp"

namespace coloc::roadside {

struct RsuStation::Impl {
  RsuMount mount;
  RsuStationConfig config;
  BackgroundLearner learner;
  std::optional<RoadsidePerception> perception;
  int since_rebuild = 0;
  int since_learned = 0;  ///< frames since the last one learned, once commissioned
  std::map<std::uint32_t, ConnectedVehicle> vehicles;
  std::map<std::uint32_t, FixConsistency> tracks;
  std::map<std::uint32_t, BodySizeLearner> bodies;  ///< each vehicle's sides measured over its frames
  std::optional<Stamp> last_frame;
  bool levelled = false;
  std::optional<Levelling> levelling;  ///< what the road showed of the LiDAR's tilt and height
  StationCounters counters;

  Impl(const RsuMount& m, const RsuStationConfig& c) : mount(m), config(c), learner(c.background) {}

  void rebuild() {
    const std::vector<Eigen::Vector3f> background = learner.background();
    if (background.empty()) return;  // nothing returned often enough yet: keep learning
    build(background);
  }

  /// The perception from `background` (sensor frame): learned, or a frame of the empty scene.
  void build(const std::vector<Eigen::Vector3f>& background) {
    // The first time, the LiDAR's tilt from the road it sees, if asked (the registry's otherwise).
    if (config.level_from_ground && !levelled) {
      std::vector<Eigen::Vector3d> sensor;
      sensor.reserve(background.size());
      for (const Eigen::Vector3f& p : background) sensor.push_back(p.cast<double>());
      if (const std::optional<GroundPlane> plane = fitGroundPlane(sensor, Eigen::Vector2d::Zero(), config.perception.road)) {
        const Levelling l = levellingOf(*plane);
        mount.roll = l.roll;
        mount.pitch = l.pitch;
        levelling = l;
        levelled = true;
      }
    }
    perception.emplace(background, mount, config.perception);
    since_rebuild = 0;
    ++counters.background_rebuilds;
  }
};

RsuStation::RsuStation(const RsuMount& mount, RsuStationConfig config) {
  if (!mount.position.allFinite() || !std::isfinite(mount.yaw) || !std::isfinite(mount.roll) || !std::isfinite(mount.pitch))
    throw Error("RSU station: the mount's position and angles must be finite");
  if (!(config.coverage > 0.0) || !(config.max_cam_age > 0.0) || !(config.forget_after >= config.max_cam_age))
    throw Error("RSU station: coverage and max_cam_age must be > 0, forget_after at least max_cam_age");
  if (config.commissioning_frames < 1 || config.refresh_frames < 1 || config.learn_every < 1)
    throw Error("RSU station: commissioning_frames, refresh_frames and learn_every must be >= 1");
  validate(config.perception);  // before commissioning, not at the first frame after it
  impl_ = std::make_unique<Impl>(mount, config);
}

RsuStation::~RsuStation() = default;
RsuStation::RsuStation(RsuStation&&) noexcept = default;
RsuStation& RsuStation::operator=(RsuStation&&) noexcept = default;

bool RsuStation::commissioned() const { return impl_->perception.has_value(); }
const StationCounters& RsuStation::counters() const { return impl_->counters; }
const RsuMount& RsuStation::mount() const { return impl_->mount; }
std::size_t RsuStation::vehiclesKnown() const { return impl_->vehicles.size(); }
std::optional<Levelling> RsuStation::levelling() const { return impl_->levelling; }

std::optional<GroundPlane> RsuStation::roadPlane() const {
  if (!impl_->perception) return std::nullopt;
  return impl_->perception->roadPlane();
}

void RsuStation::learn(const std::vector<Eigen::Vector3f>& points) {
  impl_->learner.add(points);
  ++impl_->counters.commissioning_frames;
}

bool RsuStation::commission() {
  impl_->rebuild();
  return commissioned();
}

bool RsuStation::commission(const std::vector<Eigen::Vector3f>& empty_scene) {
  Impl& d = *impl_;
  if (std::none_of(empty_scene.begin(), empty_scene.end(), [](const Eigen::Vector3f& p) { return p.allFinite(); })) return false;
  d.learner.add(empty_scene);
  ++d.counters.commissioning_frames;
  d.build(empty_scene);
  return true;
}

std::vector<Eigen::Vector3f> RsuStation::background() const { return impl_->learner.background(); }

const RoadsidePerception* RsuStation::perception() const { return impl_->perception ? &*impl_->perception : nullptr; }

bool RsuStation::addVehicle(const ConnectedVehicle& v) {
  Impl& d = *impl_;
  ++d.counters.cams;
  const bool finite = v.centre.allFinite() && std::isfinite(v.heading) && std::isfinite(v.speed) && std::isfinite(v.yaw_rate) &&
                      std::isfinite(v.length) && std::isfinite(v.width);
  auto known = d.vehicles.find(v.station_id);
  // Far older than the vehicle's last: its clock (or a replayed log's) went back; a new timeline.
  if (finite && known != d.vehicles.end() && toSeconds(known->second.stamp - v.stamp) > d.config.forget_after) {
    d.tracks.erase(known->first);
    d.bodies.erase(known->first);
    d.vehicles.erase(known);
    known = d.vehicles.end();
  }
  if (!finite || !(v.length > 0.0) || !(v.width > 0.0) || (known != d.vehicles.end() && v.stamp < known->second.stamp)) {
    ++d.counters.cams_refused;
    return false;
  }
  // Another size sent (a trailer hitched, another vehicle behind the id): its sides are measured afresh.
  if (known != d.vehicles.end() && (known->second.length != v.length || known->second.width != v.width)) d.bodies.erase(v.station_id);
  d.vehicles[v.station_id] = v;
  return true;
}

std::vector<StationOutcome> RsuStation::frame(const std::vector<Eigen::Vector3f>& points, Stamp stamp) {
  Impl& d = *impl_;
  ++d.counters.frames;
  // The frames' clock went back (a LiDAR driver restarted, a log played again): the CAMs and tracks
  // belong to the other timeline. The background does not.
  if (d.last_frame && stamp + kNanosPerSecond < *d.last_frame) {
    d.vehicles.clear();
    d.tracks.clear();
    d.bodies.clear();
    ++d.counters.clock_resets;
  }
  d.last_frame = stamp;
  if (!d.perception) {
    d.learner.add(points);
    ++d.counters.commissioning_frames;
    if (static_cast<int>(d.counters.commissioning_frames) >= d.config.commissioning_frames) d.rebuild();
    return {};
  }
  if (++d.since_learned >= d.config.learn_every) {
    d.learner.add(points);
    d.since_learned = 0;
  }
  if (++d.since_rebuild >= d.config.refresh_frames) d.rebuild();
  // Vehicles long gone are forgotten with their tracks: a busy intersection sees thousands a day.
  for (auto it = d.vehicles.begin(); it != d.vehicles.end();) {
    if (toSeconds(stamp - it->second.stamp) > d.config.forget_after) {
      d.tracks.erase(it->first);
      d.bodies.erase(it->first);
      it = d.vehicles.erase(it);
    } else {
      ++it;
    }
  }
  std::vector<StationOutcome> out;
  const Eigen::Vector2d lidar = d.mount.position.head<2>();
  for (auto& [id, v] : d.vehicles) {
    const double age = toSeconds(stamp - v.stamp);
    if (std::abs(age) > d.config.max_cam_age) continue;
    // Where the CAM's vehicle is at the frame's capture time: carried by its speed and yaw rate.
    const double heading = v.heading + v.yaw_rate * age;
    const double mid = v.heading + 0.5 * v.yaw_rate * age;
    const Eigen::Vector2d centre = v.centre + v.speed * age * Eigen::Vector2d(std::cos(mid), std::sin(mid));
    const double distance = (centre - lidar).norm();
    if (distance > d.config.coverage) continue;
    StationOutcome o;
    o.station_id = id;
    o.distance = distance;
    // The box's size: the CAM's, or a side its faces measured shorter over the vehicle's frames.
    BodySizeLearner& body = d.bodies.try_emplace(id, d.config.perception.body_size).first->second;
    const Eigen::Vector2d size = body.size(v.length, v.width);
    o.detection = d.perception->detect(points, stamp, centre, heading, size.x(), size.y());
    if (o.detection.found && size != Eigen::Vector2d(v.length, v.width))
      o.detection.covariance += sizeCovariance(body.doubt(v.length, v.width), o.detection.yaw);
    // Placed with a side shorter than the CAM's: the station's measures, or this frame's own.
    const bool measured_size = o.detection.found && o.detection.placed_size != Eigen::Vector2d(v.length, v.width);
    FixConsistency& track = d.tracks.try_emplace(id).first->second;
    if (!o.detection.found) {
      track.miss();
    } else if (!track.agrees(stamp, o.detection.position, v.speed * Eigen::Vector2d(std::cos(heading), std::sin(heading)))) {
      o.detection.found = false;
      o.detection.refusal = Refusal::kInconsistent;
    }
    // Measures from the fixes sent only: a fit the track refused may be another object's.
    if (o.detection.found) {
      body.add(o.detection.measured_sides);
      if (measured_size) ++d.counters.fixes_with_measured_size;
    }
    if (o.detection.found) ++d.counters.fixes;
    else ++d.counters.refused[static_cast<std::size_t>(o.detection.refusal)];
    out.push_back(std::move(o));
  }
  return out;
}

}  // namespace coloc::roadside
