#include "coloc/twin/twin_recording.hpp"

#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <random>

#include "coloc/core/error.hpp"
#include "coloc/core/principal_variances.hpp"
#include "coloc/io/bag_writer.hpp"
#include "coloc/io/ros_messages.hpp"
#include "coloc/io/v2x_messages.hpp"
#include "coloc/ndt/pcd_file.hpp"
#include "coloc/ndt/tile_map.hpp"
#include "coloc/rsu_client/dds_transport.hpp"
#include "coloc/rsu_client/rsu_registry.hpp"
#include "coloc/roadside/background_model.hpp"
#include "coloc/roadside/fix_consistency.hpp"
#include "coloc/sim/lidar_model.hpp"
#include "coloc/roadside/roadside_perception.hpp"
#include "coloc/roadside/rsu_station.hpp"
#include "coloc/sim/survey_map.hpp"
#include "coloc/sim/vehicle_body.hpp"
#include "coloc/replay/replay_cache.hpp"
#include "coloc/replay/svg_plot.hpp"
#include "scan_pool.hpp"

namespace coloc::twin {

using replay::Plot;
using replay::PlotBand;
using replay::PlotSeries;
using replay::writeSvg;

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr Stamp kEpoch = 1'700'000'000'000'000'000LL;  // the twin's clock starts here: runs repeat exactly

Stamp at(double t) { return kEpoch + fromSeconds(t); }

// The sweep as its driver publishes it, into `m` (kept between sweeps: a fresh 640 KB message per sweep
// cost a zero fill and its page faults every time).
void toPointCloud2(const std::vector<sim::LidarPoint>& points, Stamp stamp, io::PointCloud2& m, const std::string& frame_id = "lidar") {
  m.header = {stamp, frame_id};
  m.height = 1;
  m.width = static_cast<std::uint32_t>(points.size());
  m.fields = {{"x", 0, io::PointField::kFloat32, 1}, {"y", 4, io::PointField::kFloat32, 1}, {"z", 8, io::PointField::kFloat32, 1},
              {"time", 12, io::PointField::kFloat32, 1}};
  m.point_step = 16;
  m.row_step = 16 * m.width;
  m.is_dense = true;
  m.data.resize(m.row_step);
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::memcpy(&m.data[16 * i], points[i].position.data(), 12);
    std::memcpy(&m.data[16 * i + 12], &points[i].time, 4);
  }
}

// The sweep as the pipeline decodes toPointCloud2's message (pipeline::toPointCloud), into `cloud`: its
// finite points, each point's time in seconds after the earliest point's (the difference taken in
// double, as there), without the message in between. Tested against the decoded file.
void scanOf(const std::vector<sim::LidarPoint>& sweep, ndt::PointCloud& cloud) {
  cloud.points.clear();
  cloud.times.clear();
  cloud.points.reserve(sweep.size());
  double first = std::numeric_limits<double>::infinity();
  for (const sim::LidarPoint& p : sweep) {
    if (!p.position.allFinite()) continue;
    cloud.points.push_back(p.position);
    first = std::min(first, static_cast<double>(p.time));
  }
  if (cloud.points.empty()) return;
  cloud.times.reserve(cloud.points.size());
  for (const sim::LidarPoint& p : sweep)
    if (p.position.allFinite()) cloud.times.push_back(static_cast<float>(static_cast<double>(p.time) - first));
}

// The drive's log: written as rosbag2, kept in memory, or both.
class LogRecorder {
 public:
  LogRecorder(const std::string& directory, bool write, bool keep) : keep_(keep) {
    if (write) bag_.emplace(io::BagWriter::create(directory));
  }
  void addTopic(const io::TopicInfo& topic) {
    if (bag_) bag_->addTopic(topic);
    if (keep_) topics_.push_back(topic);
  }
  void write(const std::string& topic, Stamp log_time, io::Bytes&& data) {
    if (bag_) bag_->write(topic, log_time, data.data(), data.size());
    if (!keep_) return;
    io::BagMessage m;
    m.topic = topic;
    m.log_time = log_time;
    m.data = std::move(data);
    messages_.push_back(std::move(m));
  }
  /// A sweep stamped `stamp`: kept as a replay decodes its message, serialised only for the file.
  void writeScan(const std::string& topic, Stamp log_time, const std::vector<sim::LidarPoint>& sweep, Stamp stamp) {
    if (bag_) {
      toPointCloud2(sweep, stamp, message_);
      const io::Bytes data = io::encodePointCloud2(message_);
      bag_->write(topic, log_time, data.data(), data.size());
    }
    if (!keep_) return;
    io::BagMessage m;
    m.topic = topic;
    m.log_time = log_time;
    messages_.push_back(std::move(m));
    decoded_.resize(messages_.size());
    decoded_.back() = {stamp, ScanPool::shared().make(sweep.size(), [&](ndt::PointCloud& cloud) { scanOf(sweep, cloud); }), std::string()};  // given decoded: no header
  }
  /// A roadside LiDAR's frame, in its sensor frame: written to the file only (coloc rsu-node reads it);
  /// in memory it is a message without a decoded scan.
  void writeRoadsideFrame(const std::string& topic, Stamp log_time, const std::vector<sim::LidarPoint>& sweep, Stamp stamp, const std::string& frame_id) {
    io::PointCloud2 m;
    toPointCloud2(sweep, stamp, m, frame_id);
    write(topic, log_time, io::encodePointCloud2(m));
  }
  std::shared_ptr<const replay::RecordedLog> close() {
    if (bag_) bag_->close();
    if (!keep_) return nullptr;
    if (!decoded_.empty()) decoded_.resize(messages_.size());
    return std::make_shared<const replay::RecordedLog>(std::move(topics_), std::move(messages_), std::move(decoded_));
  }

 private:
  bool keep_;
  std::optional<io::BagWriter> bag_;
  std::vector<io::TopicInfo> topics_;
  std::vector<io::BagMessage> messages_;
  std::vector<replay::RecordedLog::Scan> decoded_;  ///< per message so far; empty: none decoded
  io::PointCloud2 message_;  ///< a sweep's, its room kept from sweep to sweep (640 KB each)
};

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// The world as a LiDAR sees it at one instant: the static meshes, the other road users and, for the
// roadside LiDARs, the ego vehicle. Vehicles off the road wait out of every sensor's reach.
class MovingWorld {
 public:
  MovingWorld(const std::vector<sim::TriangleMesh>& statics, const sim::Scenario& scenario, bool detailed, bool with_ego)
      : scenario_(scenario), route_(scenario.route_start, scenario.route_heading, scenario.route) {
    for (const sim::TriangleMesh& m : statics) caster_.addMesh(m);
    for (const sim::TrafficVehicle& v : scenario.traffic) {
      sim::VehicleBody body = detailed ? sim::VehicleBody{} : sim::VehicleBody::boxes();
      body.length = v.body.length;
      body.width = v.body.width;
      traffic_bodies_.push_back(body);
      traffic_.push_back(caster_.addMesh(body.mesh(away(traffic_.size()), 1e4, 0.0)));
    }
    ego_body_ = detailed ? sim::VehicleBody{} : sim::VehicleBody::boxes();
    if (with_ego) ego_ = caster_.addMesh(ego_body_.mesh(1e4, 1e4, 0.0));
    caster_.commit();
  }
  /// Moves the traffic (and the ego vehicle, if there is one) to time t.
  void place(double t, const sim::VehicleState* ego) {
    for (std::size_t i = 0; i < traffic_.size(); ++i) {
      const auto pose = sim::trafficPose(route_, scenario_.traffic[i], t);
      caster_.updateMesh(traffic_[i], pose ? traffic_bodies_[i].mesh(pose->x(), pose->y(), pose->z()) : traffic_bodies_[i].mesh(away(i), 1e4, 0.0));
    }
    if (ego && ego_ >= 0) caster_.updateMesh(ego_, ego_body_.mesh(ego->position.x(), ego->position.y(), ego->yaw));
    if (!traffic_.empty() || (ego && ego_ >= 0)) caster_.commit();
  }
  const sim::RayCaster& caster() const { return caster_; }
  const sim::VehicleBody& egoBody() const { return ego_body_; }

 private:
  static double away(std::size_t i) { return 1e4 + 20.0 * static_cast<double>(i + 1); }
  const sim::Scenario& scenario_;
  sim::Route route_;
  sim::RayCaster caster_;
  std::vector<int> traffic_;
  std::vector<sim::VehicleBody> traffic_bodies_;
  sim::VehicleBody ego_body_;
  int ego_ = -1;
};

// Whether another road user the RSU's background does not have is within `radius` of the ego vehicle
// at time t: traffic, and a car parked since the survey when the background is the surveyed street
// (`parked_too`; a background learned on site has it).
bool neighboursNear(const sim::Scenario& scenario, const sim::Route& route, const Eigen::Vector2d& ego, double t, double radius, bool parked_too) {
  for (const sim::TrafficVehicle& v : scenario.traffic)
    if (const auto pose = sim::trafficPose(route, v, t); pose && (pose->head<2>() - ego).norm() <= radius) return true;
  if (parked_too)
    for (const sim::SceneObject& o : scenario.objects)
      if (o.type == "parked_car" && o.in_world && !o.in_map && (o.position - ego).norm() <= radius) return true;
  return false;
}

void positionsOf(const std::vector<sim::LidarPoint>& points, std::vector<Eigen::Vector3f>& frame) {
  frame.clear();
  frame.reserve(points.size());
  for (const auto& p : points) frame.push_back(p.position);
}

// An RSU's frame into `frame`, its rays' hits and points in `room`: the room of a frame (1-2 MB) is
// kept from frame to frame instead of fresh memory each time.
struct FrameRoom {
  std::vector<sim::RayHit> hits;
  std::vector<sim::LidarPoint> points;
};

void frameOf(const sim::LidarSpec& spec, const sim::RayCaster& world, const Eigen::Isometry3d& pose, sim::RandomEngine& rng, FrameRoom& room,
             std::vector<Eigen::Vector3f>& frame) {
  sim::castSweep(spec, world, [&](double) { return pose; }, room.hits);
  sim::sweepPoints(spec, room.hits, rng, room.points);
  positionsOf(room.points, frame);
}

std::vector<Eigen::Vector3f> frameOf(const sim::LidarSpec& spec, const sim::RayCaster& world, const Eigen::Isometry3d& pose, sim::RandomEngine& rng) {
  FrameRoom room;
  std::vector<Eigen::Vector3f> frame;
  frameOf(spec, world, pose, rng, room, frame);
  return frame;
}

std::uint64_t raysPerSweep(const sim::LidarSpec& spec) {
  return spec.vertical_deg.size() * static_cast<std::uint64_t>(std::lround(360.0 / spec.azimuth_step_deg));
}

io::TopicInfo topic(const std::string& name, const std::string& type) {
  io::TopicInfo t;
  t.name = name;
  t.type = type;
  return t;
}

// Where an RSU's LiDAR stands and how it is turned and tilted (RsuMount's convention).
Eigen::Isometry3d rsuPose(const sim::ScenarioRsu& r) {
  return Eigen::Translation3d(r.position.x(), r.position.y(), r.height) * Eigen::AngleAxisd(r.yaw, Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(r.pitch, Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(r.roll, Eigen::Vector3d::UnitX());
}

Eigen::Isometry3d vehiclePose(const sim::VehicleState& s, double height) {
  return Eigen::Translation3d(s.position.x(), s.position.y(), height) * Eigen::AngleAxisd(s.yaw, Eigen::Vector3d::UnitZ());
}

// The perception with and without each of the paper's refinements; the first is the full pipeline,
// whose result is the fix.
struct PerceptionVariant {
  const char* name;
  bool align_true_size, height_cut;
};
constexpr std::array<PerceptionVariant, 4> kVariants = {{{"aligned box with 0.8 m cut", true, true},
                                                         {"aligned box without cut", true, false},
                                                         {"plain L-shape centre with 0.8 m cut", false, true},
                                                         {"plain L-shape centre without cut", false, false}}};

// Mean of y in bins of x, for plots that would be clouds of points otherwise.
PlotSeries binnedMean(const std::string& label, const std::vector<double>& x, const std::vector<double>& y, double bin) {
  std::map<long, std::pair<double, int>> bins;
  for (std::size_t i = 0; i < x.size(); ++i) {
    auto& b = bins[static_cast<long>(std::floor(x[i] / bin))];
    b.first += y[i];
    ++b.second;
  }
  PlotSeries s;
  s.label = label;
  for (const auto& [k, b] : bins) {
    s.x.push_back((k + 0.5) * bin);
    s.y.push_back(b.first / b.second);
  }
  return s;
}

void writeMap(const sim::Scenario& scenario, const std::string& dir) {
  const ndt::PointCloud map = sim::surveyMap(scenario, {});
  const ndt::TileMap tiles = ndt::TileMap::fromCloud(map, 20.0);
  fs::create_directories(dir);
  for (std::size_t i = 0; i < tiles.tiles().size(); ++i) {
    char name[64];
    std::snprintf(name, sizeof name, "/tile_%04zu.pcd", i);
    ndt::savePcd(dir + name, tiles.load(i));
  }
}

}  // namespace

rsu_client::RsuInfo registryEntry(const sim::ScenarioRsu& r) {
  const rsu_client::LidarModel* model = rsu_client::findLidarModel(r.lidar_model);
  if (!model) throw Error("RSU " + r.id + ": no LiDAR model '" + r.lidar_model + "' (VLP-16, VLP-32C, OS1-64)");
  rsu_client::RsuInfo info;
  info.id = r.id;
  info.position = r.position + r.survey_error.head<2>();  // the vehicle knows the surveyed position
  info.height = r.height;
  info.yaw = r.yaw + r.survey_error.z();  // as surveyed
  info.roll = r.roll;
  info.pitch = r.pitch;
  info.lidar = *model;
  info.coverage_radius = model->range;
  info.identity = "CN=" + r.id;
  return info;
}

std::string perfectRsuId(const std::string& id) { return id + "_perfect"; }

io::Odometry addressedFix(Stamp stamp, const Eigen::Vector2d& position, double variance, std::uint32_t station_id) {
  io::Odometry fix;
  fix.header = {stamp, "map"};
  fix.child_frame_id = std::to_string(station_id);
  fix.pose.stamp = stamp;
  fix.pose.pose.position = {position.x(), position.y(), 0.0};
  fix.pose.covariance = Matrix6d::Zero();
  fix.pose.covariance.diagonal() << variance, variance, kInfinity, kInfinity, kInfinity, kInfinity;
  // Not part of a fix: its covariance says so (REP 145's -1).
  fix.twist.stamp = stamp;
  fix.twist.covariance = Matrix6d::Zero();
  fix.twist.covariance.diagonal().setConstant(-1.0);
  return fix;
}

io::Odometry addressedFix(Stamp stamp, const Eigen::Vector2d& position, const Eigen::Matrix2d& covariance, double floor, std::uint32_t station_id) {
  io::Odometry fix = addressedFix(stamp, position, floor, station_id);
  if (!covariance.allFinite()) return fix;
  // Each principal variance at least the floor: what the fit says beyond it survives as said (a
  // receiver that has calibrated this RSU replaces the floor alone: rsu_client/rsu_fix.cpp).
  fix.pose.covariance.topLeftCorner<2, 2>() = principalVariancesAtLeast(covariance, floor);
  return fix;
}

TwinRecordingSummary recordTwin(const sim::Scenario& scenario, const TwinRecordingOptions& options) {
  const auto wall_start = Clock::now();
  const std::string& out_dir = options.out_dir;
  if (fs::exists(out_dir) && !fs::is_empty(out_dir)) throw Error(out_dir + ": the output folder exists and is not empty");
  // The options that would otherwise fail only after the survey, or not at all.
  rsu_client::checkLinkConfig(options.link);
  if (!(std::isfinite(options.rsu_processing) && options.rsu_processing >= 0.0))
    throw Error("twin: the RSU's processing time must be a finite number of seconds >= 0");
  if (!(std::isfinite(options.oracle_fix_limit) && options.oracle_fix_limit >= 0.0))
    throw Error("twin: the oracle fix limit must be a finite number of metres >= 0 (0: off)");
  if (options.rsu_commissioning_frames < 0 || options.rsu_commissioning_frames > 10000)
    throw Error("twin: the RSUs' commissioning frames must be 0-10000 (0: the surveyed empty street), not " +
                std::to_string(options.rsu_commissioning_frames));
  if (options.perfect_rsus)
    for (const sim::ScenarioRsu& a : scenario.rsus)
      for (const sim::ScenarioRsu& b : scenario.rsus)
        if (perfectRsuId(a.id) == b.id)
          throw Error("twin: RSU " + a.id + "'s perfect twin would send on RSU " + b.id + "'s topic: rename " + b.id + " to record perfect twins");
  fs::create_directories(out_dir);
  TwinRecordingSummary summary;

  // 1. The survey map, as 20 m PCD tiles (unless an earlier survey is shared).
  summary.map_dir = options.map_dir.empty() ? out_dir + "/map" : options.map_dir;
  if (options.map_dir.empty()) {
    const auto t0 = Clock::now();
    writeMap(scenario, summary.map_dir);
    summary.map_seconds = since(t0);
  }

  // 2. The world: static scene and traffic for the vehicle's LiDAR, plus the ego vehicle for the
  //    roadside LiDARs; the ideal twin's world beside it if asked. The RSUs' background frames are of
  //    the world as surveyed: what was parked since is foreground to them.
  const sim::ErrorSources& errors = scenario.errors;
  const std::vector<sim::TriangleMesh> world_meshes = scenario.worldMeshes();
  MovingWorld scene(world_meshes, scenario, errors.detailed_vehicle, false), with_vehicle(world_meshes, scenario, errors.detailed_vehicle, true);
  // One sweep cast afresh in `world` moved to time t (placing rebuilds its BVH), its time and rays counted.
  const auto castAt = [&summary](MovingWorld& world, double t, const sim::LidarSpec& spec, const sim::SensorTrajectory& pose, bool& cast_flag) {
    const auto c0 = Clock::now();
    world.place(t, nullptr);
    std::vector<sim::RayHit> hits = sim::castSweep(spec, world.caster(), pose);
    summary.ray_casting_seconds += since(c0);
    summary.rays += raysPerSweep(spec);
    cast_flag = true;
    return hits;
  };
  std::unique_ptr<MovingWorld> ideal_world;
  if (options.ideal_comparison) ideal_world = std::make_unique<MovingWorld>(world_meshes, scenario, false, true);
  sim::RayCaster surveyed;
  for (const sim::TriangleMesh& m : scenario.mapMeshes()) surveyed.addMesh(m);
  surveyed.commit();
  const sim::VehicleBody& body = with_vehicle.egoBody();
  const sim::Route route(scenario.route_start, scenario.route_heading, scenario.route);
  const sim::Drive drive(route, scenario.speed);
  sim::RandomEngine rng(scenario.seed);
  sim::RandomEngine ideal_rng(scenario.seed + 17), stamp_rng(scenario.seed + 29);  // own streams: the main one unchanged by them
  std::mt19937_64 connected_rng(scenario.seed + 41);  // the other connected vehicles' CAM errors, likewise
  std::normal_distribution<double> stamp_jitter(0.0, 1.0);

  // 3. Roadside units: their background frames and perception.
  struct Rsu {
    sim::ScenarioRsu info;
    sim::LidarSpec lidar;
    /// The RSU's perception over time, as its node runs it (roadside::RsuStation): the connected
    /// vehicles' CAMs, its background kept up to date from the frames, each vehicle's track.
    roadside::RsuStation station;
    /// The perception without each refinement (kVariants, with perception_ablation), on the background
    /// the station was commissioned with: what each step buys.
    std::vector<roadside::RoadsidePerception> ablation;
    rsu_client::LinkEmulator link;
    double variance;
    double range;
    sim::LidarSpec ideal_lidar;
    std::unique_ptr<roadside::RoadsidePerception> ideal_perception;
    roadside::FixConsistency ideal_consistency{};
    /// Per other connected vehicle: its share of the radio link.
    std::vector<rsu_client::LinkEmulator> connected_links;
  };
  std::vector<std::size_t> connected;  // the traffic that is connected
  for (std::size_t i = 0; i < scenario.traffic.size(); ++i)
    if (scenario.traffic[i].station_id) connected.push_back(i);
  std::vector<Rsu> rsus;
  // Each RSU's background as it learns one on site (roadside/background_model): frames of the street
  // with its traffic passing and its cars parked, never an empty scene, taken before this drive (the
  // vehicle is not in them). The traffic is where it is at evenly spaced times of the drive. Their hits
  // are the same on every trial of a site, as the frames' are; the noise is drawn afresh.
  sim::RandomEngine background_rng(scenario.seed + 59);  // its own stream: the main one unchanged by it
  const auto learnBackground = [&](std::size_t index, const sim::LidarSpec& lidar, const Eigen::Isometry3d& pose, roadside::RsuStation& station) {
    const sim::SensorTrajectory still = [&](double) { return pose; };
    FrameRoom room;
    std::vector<Eigen::Vector3f> frame;
    const int frames = options.rsu_commissioning_frames;
    std::shared_ptr<const std::vector<sim::RayHit>> hits;
    for (int k = 0; k < frames; ++k) {
      const double t = drive.duration() * (k + 0.5) / frames;
      bool cast_here = false;
      const auto cast = [&] { return castAt(with_vehicle, t, lidar, still, cast_here); };
      // Without traffic every frame's rays hit the same: one cast, each frame its own noise.
      if (!hits || !scenario.traffic.empty()) {
        const std::uint64_t key = (static_cast<std::uint64_t>(index) << 32) | (0xC0000000ULL + static_cast<std::uint64_t>(k));
        hits = options.rsu_frames ? options.rsu_frames->get(key, sim::sweepFingerprint(lidar, still, &t, 1), cast)
                                  : std::make_shared<const std::vector<sim::RayHit>>(cast());
        if (!cast_here) ++summary.reused_sweeps;
      }
      const auto c1 = Clock::now();
      sim::sweepPoints(lidar, *hits, background_rng, room.points);
      positionsOf(room.points, frame);
      summary.lidar_seconds += since(c1);
      const auto c2 = Clock::now();
      station.learn(frame);
      summary.perception_seconds += since(c2);
    }
    station.commission();
  };
  for (const sim::ScenarioRsu& r : scenario.rsus) {
    roadside::RsuMount mount;
    mount.position = {r.position.x(), r.position.y(), r.height};
    mount.yaw = r.yaw;
    mount.roll = r.roll;
    mount.pitch = r.pitch;
    const Eigen::Isometry3d pose = rsuPose(r);
    const sim::LidarSpec lidar = sim::withErrors(sim::lidarNamed(r.lidar_model), errors);
    // The empty street's frame is drawn either way (one frame, a few ms): the main stream then gives the
    // roof LiDAR and the vehicle the same draws whichever background the RSUs have, so that the two are
    // compared on the same drive.
    const std::vector<Eigen::Vector3f> empty_street = frameOf(lidar, surveyed, pose, rng);
    const rsu_client::LidarModel* model = rsu_client::findLidarModel(r.lidar_model);
    // The twin casts an RSU's frame only while the vehicle is truly within the LiDAR's range; the
    // station's own gate, on the CAM's position, is wider by five of the CAM's 0.3 m sd so that it
    // looks for the vehicle in every frame cast for it.
    roadside::RsuStationConfig station_config;
    station_config.coverage = model->range + 1.5;
    // The perception's column spacing is its LiDAR model's, as the RSU's own node takes it (stationFor).
    station_config.perception.covariance.azimuth_step = model->azimuth_step_deg * M_PI / 180.0;
    roadside::RsuStation station(mount, station_config);
    if (options.rsu_commissioning_frames > 0) learnBackground(rsus.size(), lidar, pose, station);
    else station.commission(empty_street);
    if (!station.commissioned()) throw Error("twin: RSU " + r.id + " learned no background from its commissioning frames");
    std::vector<roadside::RoadsidePerception> ablation;
    if (options.perception_ablation) {
      const std::vector<Eigen::Vector3f> reference = options.rsu_commissioning_frames > 0 ? station.background() : empty_street;
      for (const PerceptionVariant& v : kVariants) {
        roadside::RoadsidePerceptionConfig c;
        c.align_true_size = v.align_true_size;
        c.height_cut = v.height_cut;
        ablation.emplace_back(reference, mount, c);
      }
    }
    rsu_client::LinkConfig l = options.link;
    l.seed = scenario.seed + rsus.size() + 1;
    Rsu rsu{r, lidar, std::move(station), std::move(ablation), rsu_client::LinkEmulator(l), model->sigma, model->range, {}, nullptr, roadside::FixConsistency(), {}};
    for (std::size_t j = 0; j < connected.size(); ++j) {
      rsu_client::LinkConfig own = l;
      own.seed = l.seed * 1000003ULL + 104729ULL * (j + 1);  // its own draws: the ego's link unchanged by it
      rsu.connected_links.emplace_back(own);
    }
    if (ideal_world) {
      rsu.ideal_lidar = sim::withErrors(sim::lidarNamed(r.lidar_model), sim::ErrorSources::ideal());
      rsu.ideal_perception = std::make_unique<roadside::RoadsidePerception>(frameOf(rsu.ideal_lidar, surveyed, pose, ideal_rng), mount);
    }
    rsus.push_back(std::move(rsu));
  }

  // 4. The drive, recorded.
  LogRecorder bag(out_dir + "/log", options.write_log, options.keep_log);
  bag.addTopic(topic("/points", "sensor_msgs/msg/PointCloud2"));
  bag.addTopic(topic("/vehicle/twist", "geometry_msgs/msg/TwistWithCovarianceStamped"));
  bag.addTopic(topic("/ground_truth/odom", "nav_msgs/msg/Odometry"));
  // The RSUs address each fix to the vehicle it is of (the station id of its CAM): the protocol.
  for (const Rsu& r : rsus) bag.addTopic(topic(rsu_client::addressedFixTopic(r.info.id), "nav_msgs/msg/Odometry"));
  if (options.perfect_rsus)
    for (const Rsu& r : rsus) bag.addTopic(topic(rsu_client::addressedFixTopic(perfectRsuId(r.info.id)), "nav_msgs/msg/Odometry"));
  if (options.record_rsu_frames) {
    for (const Rsu& r : rsus) bag.addTopic(topic(rsu_client::roadsidePointsTopic(r.info.id), "sensor_msgs/msg/PointCloud2"));
    bag.addTopic(topic(rsu_client::kCamTopic, io::kCamType));
  }
  std::mt19937_64 cam_rng(scenario.seed + 53);  // the recorded CAMs' errors: a stream of their own
  // The size a CAM tells the RSUs (errors.cam_size_step, cam_length_excess, cam_width_excess).
  const auto camLength = [&errors](double length) { return io::camSizeSent(length + errors.cam_length_excess, errors.cam_size_step); };
  const auto camWidth = [&errors](double width) { return io::camSizeSent(width + errors.cam_width_excess, errors.cam_size_step); };
  std::ofstream fixes_csv(out_dir + "/rsu_fixes.csv");
  fixes_csv << "stamp_s,rsu,lidar,distance_m,error_x_m,error_y_m,error_m,processing_ms,delivered\n";
  std::ofstream frames_csv(out_dir + "/rsu_frames.csv");
  frames_csv << "stamp_s,rsu,lidar,distance_m,neighbours,outcome,error_m,ideal_error_m,fit_points\n";
  std::ofstream ablation_csv;
  if (options.perception_ablation) {
    ablation_csv.open(out_dir + "/rsu_perception.csv");
    ablation_csv << "stamp_s,rsu,lidar,distance_m,variant,found,error_m\n";
  }
  std::map<std::string, PlotSeries> fix_errors;  // per RSU: error against distance
  std::map<std::pair<std::string, std::size_t>, std::pair<std::vector<double>, std::vector<double>>> variant_errors;
  const sim::LidarSpec roof = sim::withErrors(sim::lidarNamed(scenario.vehicle_lidar), errors);
  const sim::OdometryNoise& odometry_noise = scenario.odometry;
  const int ticks = static_cast<int>(std::floor(drive.duration() * 100.0));
  // The roof sweep, an RSU's frame and the ideal twin's, their room kept from sweep to sweep.
  std::vector<sim::LidarPoint> sweep;
  std::vector<Eigen::Vector3f> frame, ideal_frame;
  FrameRoom frame_room;
  for (int k = 0; k <= ticks; ++k) {  // 100 Hz
    const double t = k * 0.01;
    const sim::VehicleState truth = drive.at(t);
    if (options.progress && k % 10 == 0) options.progress(static_cast<double>(k) / ticks);
    io::Odometry gt;
    gt.header = {at(t), "map"};
    gt.child_frame_id = "base_link";
    gt.pose.pose.position = {truth.position.x(), truth.position.y(), 0.0};
    gt.pose.pose.orientation = quaternionFromRollPitchYaw(0, 0, truth.yaw);
    gt.twist.linear = {truth.speed, 0, 0};
    gt.twist.angular = {0, 0, truth.yaw_rate};
    bag.write("/ground_truth/odom", at(t), io::encodeOdometry(gt));
    summary.truth.emplace_back(at(t), truth.position);
    if (k % 2 == 0) {  // 50 Hz odometry, logged 2 ms after sensing
      const sim::OdometrySample o = sim::measureOdometry(truth, odometry_noise, rng);
      summary.odometry.emplace_back(o.speed, truth.speed, o.yaw_rate, truth.yaw_rate);
      io::StampedTwist tw;
      tw.header = {at(t), "base_link"};
      tw.measurement.linear = {o.speed, 0, 0};
      tw.measurement.angular = {0, 0, o.yaw_rate};
      tw.measurement.covariance = Matrix6d::Zero();
      tw.measurement.covariance.diagonal() << 0.04, kInfinity, kInfinity, kInfinity, kInfinity, 0.01;
      bag.write("/vehicle/twist", at(t) + 2'000'000, io::encodeTwistWithCovarianceStamped(tw));
    }
    if (k % 10 != 0) continue;
    // 10 Hz: a roof sweep, and each RSU's frame; the traffic where it is half-way through them.
    const double capture = t + 0.05;
    const sim::VehicleState seen = drive.at(capture);
    // The LiDAR as mounted, which its recorded extrinsic (yaw 0) misses by errors.lidar_mount_yaw.
    const sim::SensorTrajectory roof_pose = [&](double dt) {
      return vehiclePose(drive.at(t + dt), scenario.vehicle_lidar_height) * Eigen::AngleAxisd(errors.lidar_mount_yaw, Eigen::Vector3d::UnitZ());
    };
    // The worlds are moved to the capture time only for a sweep cast afresh (placing rebuilds their BVH).
    bool cast_now = false;
    auto cast = [&] { return castAt(scene, capture, roof, roof_pose, cast_now); };
    {
      const std::shared_ptr<const std::vector<sim::RayHit>> hits =
          options.roof_sweeps ? options.roof_sweeps->get(summary.scans, sim::sweepFingerprint(roof, roof_pose), cast)
                              : std::make_shared<const std::vector<sim::RayHit>>(cast());
      if (!cast_now) ++summary.reused_sweeps;
      const auto c0 = Clock::now();
      sim::sweepPoints(roof, *hits, rng, sweep);
      summary.lidar_seconds += since(c0);
    }
    bag.writeScan("/points", at(t + 0.1) + 5'000'000, sweep, at(t));  // the sweep ends, the driver publishes
    ++summary.scans;
    // Each connected vehicle's CAM (10 Hz): where it thinks it is (0.3 m off), its front centre as
    // ETSI's reference point, its size in the CAM's 0.1 m steps.
    if (options.record_rsu_frames) {
      const auto writeCam = [&](std::uint32_t station, const Eigen::Vector3d& pose, double speed, double yaw_rate, const sim::VehicleBody& b) {
        std::normal_distribution<double> error(0.0, 0.3);
        io::Cam c;
        c.header = {at(t), "map"};
        c.station_id = station;
        c.heading = pose.z();
        c.speed = speed;
        c.yaw_rate = yaw_rate;
        c.length = camLength(b.length);
        c.width = camWidth(b.width);
        const Eigen::Vector2d centre = pose.head<2>() + Eigen::Vector2d(error(cam_rng), error(cam_rng));
        c.reference = centre + 0.5 * c.length * Eigen::Vector2d(std::cos(c.heading), std::sin(c.heading));
        bag.write(rsu_client::kCamTopic, at(t) + 1'000'000, io::encodeCam(c));
      };
      writeCam(scenario.vehicle_station_id, Eigen::Vector3d(truth.position.x(), truth.position.y(), truth.yaw), truth.speed, truth.yaw_rate, body);
      for (std::size_t j : connected) {
        const sim::TrafficVehicle& other = scenario.traffic[j];
        if (const std::optional<Eigen::Vector3d> p = sim::trafficPose(route, other, t)) writeCam(*other.station_id, *p, other.speed, 0.0, other.body);
      }
    }
    // The RSUs see the vehicle where it is half-way through their sweep, and stamp the fix then.
    bool placed = false;
    const auto placeVehicle = [&] {
      if (!placed) with_vehicle.place(capture, &seen);
      placed = true;
    };
    if (ideal_world) ideal_world->place(capture, &seen);
    bool any_in_range = false;
    for (const Rsu& r : rsus) any_in_range = any_in_range || (seen.position - r.info.position).norm() <= r.range;
    const bool neighbours = any_in_range && neighboursNear(scenario, route, seen.position, capture, 10.0, options.rsu_commissioning_frames <= 0);
    for (Rsu& r : rsus) {
      const double distance = (seen.position - r.info.position).norm();
      if (distance > r.range) continue;
      const Eigen::Isometry3d pose = rsuPose(r.info);
      if (options.rsu_frames) {
        // Keyed by RSU and sweep; the fingerprint adds where the vehicle is, which the world holds.
        const sim::SensorTrajectory still = [&](double) { return pose; };
        const double ego[3] = {seen.position.x(), seen.position.y(), seen.yaw};
        const std::uint64_t key = (static_cast<std::uint64_t>(&r - rsus.data()) << 32) | summary.scans;
        bool frame_cast = false;
        const auto hits = options.rsu_frames->get(key, sim::sweepFingerprint(r.lidar, still, ego, 3), [&] {
          const auto c1 = Clock::now();
          placeVehicle();
          std::vector<sim::RayHit> cast_hits = sim::castSweep(r.lidar, with_vehicle.caster(), still);
          summary.ray_casting_seconds += since(c1);
          summary.rays += raysPerSweep(r.lidar);
          frame_cast = true;
          return cast_hits;
        });
        if (!frame_cast) ++summary.reused_sweeps;
        const auto c1 = Clock::now();
        sim::sweepPoints(r.lidar, *hits, rng, frame_room.points);
        positionsOf(frame_room.points, frame);
        summary.lidar_seconds += since(c1);
      } else {
        const auto c1 = Clock::now();
        placeVehicle();
        frameOf(r.lidar, with_vehicle.caster(), pose, rng, frame_room, frame);
        summary.ray_casting_seconds += since(c1);  // the LiDAR model's share with it
        summary.rays += raysPerSweep(r.lidar);
      }
      // The frame as the RSU's LiDAR driver publishes it: stamped at the sweep's start, in its own frame.
      if (options.record_rsu_frames)
        bag.writeRoadsideFrame(rsu_client::roadsidePointsTopic(r.info.id), at(t + 0.1) + 5'000'000, frame_room.points, at(t), r.info.id);
      // The CAMs the RSU holds at the capture time: every connected vehicle's within range, each with
      // its own error of about 0.3 m, its size in the CAM's steps. Every other connected vehicle in the
      // same frame gets its own fix, found through its own CAM and addressed to its station id, on the
      // same topic: the ego's radio hears them all.
      std::map<std::uint32_t, std::size_t> others;  // station id -> index in `connected`
      for (std::size_t j = 0; j < connected.size(); ++j) {
        const sim::TrafficVehicle& other = scenario.traffic[connected[j]];
        const std::optional<Eigen::Vector3d> at_capture = sim::trafficPose(route, other, capture);
        if (!at_capture || (at_capture->head<2>() - r.info.position).norm() > r.range) continue;
        std::normal_distribution<double> cam_error(0.0, 0.3);
        roadside::ConnectedVehicle v;
        v.stamp = at(capture);
        v.station_id = *other.station_id;
        v.centre = at_capture->head<2>() + Eigen::Vector2d(cam_error(connected_rng), cam_error(connected_rng));
        v.heading = at_capture->z();
        v.speed = other.speed;
        v.length = camLength(other.body.length);
        v.width = camWidth(other.body.width);
        r.station.addVehicle(v);
        others[v.station_id] = j;
      }
      // The ego's CAM: a reference position with the vehicle's own error, about 0.3 m.
      std::normal_distribution<double> cam(0.0, 0.3);
      const Eigen::Vector2d reference = seen.position + Eigen::Vector2d(cam(rng), cam(rng));
      {
        roadside::ConnectedVehicle v;
        v.stamp = at(capture);
        v.station_id = scenario.vehicle_station_id;
        v.centre = reference;
        v.heading = seen.yaw;
        v.speed = seen.speed;
        v.yaw_rate = seen.yaw_rate;
        v.length = camLength(body.length);
        v.width = camWidth(body.width);
        r.station.addVehicle(v);
      }
      const auto c_station = Clock::now();
      const std::vector<roadside::StationOutcome> outcomes = r.station.frame(frame, at(capture));
      summary.perception_seconds += since(c_station);
      roadside::VehicleDetection d;
      d.refusal = roadside::Refusal::kNoVehicle;  // unless the station looked: it always does (its gate is wider)
      for (const roadside::StationOutcome& o : outcomes) {
        if (o.station_id == scenario.vehicle_station_id) {
          d = o.detection;
          continue;
        }
        const auto j = others.find(o.station_id);
        if (j == others.end() || !o.detection.found) continue;  // a CAM the frame no longer holds the vehicle of
        const sim::TrafficVehicle& other = scenario.traffic[connected[j->second]];
        const std::optional<Stamp> sent = r.connected_links[j->second].transmit(at(capture + 0.05 + options.rsu_processing));
        if (!sent) continue;
        const roadside::VehicleDetection& od = o.detection;
        const Eigen::Vector2d local = Eigen::Rotation2Dd(r.info.yaw).inverse() * (od.position - r.info.position);
        const Eigen::Vector2d reported = r.info.position + r.info.survey_error.head<2>() + Eigen::Rotation2Dd(r.info.yaw + r.info.survey_error.z()) * local;
        const Eigen::Matrix2d turn = Eigen::Rotation2Dd(r.info.survey_error.z()).toRotationMatrix();
        bag.write(rsu_client::addressedFixTopic(r.info.id), *sent,
                  io::encodeOdometry(addressedFix(at(capture) + fromSeconds(r.info.clock_offset), reported, turn * od.covariance * turn.transpose(), r.variance,
                                                  *other.station_id)));
        ++summary.connected_fixes;
      }
      for (std::size_t v = 0; v < r.ablation.size(); ++v) {
        const roadside::VehicleDetection dv = r.ablation[v].detect(frame, at(capture), reference, seen.yaw, camLength(body.length), camWidth(body.width));
        const double e = dv.found ? (dv.position - seen.position).norm() : std::nan("");
        ablation_csv << formatSeconds(at(capture)) << "," << r.info.id << "," << r.info.lidar_model << "," << distance << ","
                     << kVariants[v].name << "," << (dv.found ? 1 : 0) << "," << e << "\n";
        if (dv.found) {
          auto& series = variant_errors[{r.info.id + " (" + r.info.lidar_model + ")", v}];
          series.first.push_back(distance);
          series.second.push_back(e);
        }
      }
      // The CAM's velocity carries the previous frame's fix to this one.
      const Eigen::Vector2d velocity = seen.speed * Eigen::Vector2d(std::cos(seen.yaw), std::sin(seen.yaw));
      const auto confirm = [&](roadside::VehicleDetection& det, roadside::FixConsistency& consistency) {
        if (!det.found) return consistency.miss();
        if (!consistency.agrees(det.stamp, det.position, velocity)) det.found = false, det.refusal = roadside::Refusal::kInconsistent;
      };
      RsuFrameRecord record;
      record.distance = distance;
      record.neighbours = neighbours;
      record.found = d.found;
      record.refusal = d.refusal;
      record.fit_points = d.fit_points;
      if (r.ideal_perception) {
        const auto c2 = Clock::now();
        frameOf(r.ideal_lidar, ideal_world->caster(), pose, ideal_rng, frame_room, ideal_frame);
        summary.ray_casting_seconds += since(c2);
        summary.rays += raysPerSweep(r.ideal_lidar);
        roadside::VehicleDetection di = r.ideal_perception->detect(ideal_frame, at(capture), reference, seen.yaw, ideal_world->egoBody().length,
                                                                    ideal_world->egoBody().width);
        confirm(di, r.ideal_consistency);
        if (di.found) record.ideal_error = (di.position - seen.position).norm();
      }
      const auto keep = [&](const RsuFrameRecord& f) {
        summary.rsu_frames[r.info.id].push_back(f);
        frames_csv << formatSeconds(at(capture)) << "," << r.info.id << "," << r.info.lidar_model << "," << f.distance << "," << (f.neighbours ? 1 : 0)
                   << "," << (f.found ? "fix" : roadside::toString(f.refusal)) << "," << (f.found ? f.error : std::nan("")) << ","
                   << (f.ideal_error >= 0.0 ? f.ideal_error : std::nan("")) << "," << f.fit_points << "\n";
      };
      if (!d.found) {
        keep(record);
        continue;
      }
      const bool withheld = options.oracle_fix_limit > 0.0 && (d.position - seen.position).norm() > options.oracle_fix_limit;
      const Stamp ready = at(capture + 0.05 + options.rsu_processing);  // end of the sweep + processing
      const std::optional<Stamp> delivered = r.link.transmit(ready);
      // The RSU reports in the map frame through its surveyed pose, and stamps on its own clock.
      const Eigen::Rotation2Dd true_yaw(r.info.yaw), surveyed_yaw(r.info.yaw + r.info.survey_error.z());
      const Eigen::Vector2d local = true_yaw.inverse() * (d.position - r.info.position);
      d.position = r.info.position + r.info.survey_error.head<2>() + surveyed_yaw * local;
      // The fit's covariance, as the RSU reports it: turned with the position (a survey error in yaw).
      const Eigen::Matrix2d turn = (surveyed_yaw * true_yaw.inverse()).toRotationMatrix();
      const Eigen::Matrix2d sent_covariance = turn * d.covariance * turn.transpose();
      const Eigen::Vector2d error = d.position - seen.position;
      // Stamped on the RSU's clock, with its per-frame stamp error; where the vehicle was at that stamp.
      const double jitter = errors.clock_jitter_sd > 0.0 ? errors.clock_jitter_sd * stamp_jitter(stamp_rng) : 0.0;
      const double stamp_offset = r.info.clock_offset + jitter;
      const sim::VehicleState at_stamp = drive.at(capture + stamp_offset);
      if (withheld) {  // after the draws a sent fix makes: every other fix of the drive is as without the oracle
        record.found = false;
        record.refusal = roadside::Refusal::kBeyondOracleLimit;
        keep(record);
        continue;
      }
      summary.fix_errors[r.info.id].push_back(error);
      const Eigen::Vector2d velocity_then = at_stamp.speed * Eigen::Vector2d(std::cos(at_stamp.yaw), std::sin(at_stamp.yaw));
      summary.fix_samples[r.info.id].push_back({d.position, at_stamp.position, velocity_then});
      summary.fix_covariances[r.info.id].push_back(sent_covariance);
      // A probe whose size the operator enters: the same frame fitted with the body's own size, the
      // survey then not taking the CAM's rounding.
      if (options.probe_size_for_commissioning && (camLength(body.length) != body.length || camWidth(body.width) != body.width)) {
        const roadside::VehicleDetection probe = r.station.perception()->detect(frame, at(capture), reference, seen.yaw, body.length, body.width);
        if (probe.found)
          summary.probe_fix_samples[r.info.id].push_back(
              {r.info.position + r.info.survey_error.head<2>() + surveyed_yaw * (true_yaw.inverse() * (probe.position - r.info.position)),
               at_stamp.position, velocity_then});
      }
      record.error = error.norm();
      keep(record);
      fixes_csv << formatSeconds(at(capture)) << "," << r.info.id << "," << r.info.lidar_model << "," << distance << "," << error.x() << ","
                << error.y() << "," << error.norm() << "," << d.processing_ms << "," << (delivered ? 1 : 0) << "\n";
      PlotSeries& series = fix_errors[r.info.id];
      series.label = r.info.id + " (" + r.info.lidar_model + ")";
      series.points = true;
      series.x.push_back(distance);
      series.y.push_back(error.norm());
      if (!delivered) {
        ++summary.fixes_lost;
        continue;
      }
      bag.write(rsu_client::addressedFixTopic(r.info.id), *delivered,
                io::encodeOdometry(addressedFix(at(capture) + fromSeconds(stamp_offset), d.position, sent_covariance, r.variance, scenario.vehicle_station_id)));
      ++summary.fixes;
      if (options.perfect_rsus) {
        // Through the true pose, as the same expression computes it with a survey error of zero.
        const Eigen::Vector2d perfect = r.info.position + true_yaw * local;
        bag.write(rsu_client::addressedFixTopic(perfectRsuId(r.info.id)), *delivered,
                  io::encodeOdometry(addressedFix(at(capture) + fromSeconds(jitter), perfect, d.covariance, r.variance, scenario.vehicle_station_id)));
      }
    }
  }
  if (options.progress) options.progress(1.0);
  summary.log = bag.close();
  if (!fix_errors.empty()) {
    Plot plot;
    plot.title = "RSU fix error against distance from the RSU: " + scenario.name;
    plot.x_label = "distance from the RSU [m]";
    plot.y_label = "fix error [m]";
    plot.y_from_zero = true;
    for (auto& [id, series] : fix_errors) plot.series.push_back(series);
    if (options.ideal_comparison)
      for (const auto& [id, frames] : summary.rsu_frames) {
        std::vector<double> x, y;
        for (const RsuFrameRecord& f : frames)
          if (f.ideal_error >= 0.0) x.push_back(f.distance), y.push_back(f.ideal_error);
        if (!x.empty()) plot.series.push_back(binnedMean(id + ", ideal twin (mean per 2 m)", x, y, 2.0));
      }
    writeSvg(out_dir + "/rsu_fix_error.svg", plot);
  }
  if (!variant_errors.empty()) {
    Plot plot;
    plot.title = "What each perception step buys: mean fix error per 5 m, " + scenario.name;
    plot.x_label = "distance from the RSU [m]";
    plot.y_label = "mean fix error [m]";
    plot.y_from_zero = true;
    for (const auto& [key, xy] : variant_errors)
      plot.series.push_back(binnedMean(key.first + ": " + kVariants[key.second].name, xy.first, xy.second, 5.0));
    writeSvg(out_dir + "/rsu_perception.svg", plot);
  }
  // 5. How to replay it: NDT needs a first guess, which the twin knows, and the fixes pass the checks of
  // a registry of the scenario's RSUs, as fixes received over DDS do.
  std::vector<rsu_client::RsuInfo> registry;
  for (const sim::ScenarioRsu& r : scenario.rsus) registry.push_back(registryEntry(r));
  std::ofstream(out_dir + "/rsu.yaml") << rsu_client::RsuRegistry(registry, rsu_client::CovariancePlacement::kPublished).toYaml();
  std::ofstream fuse(out_dir + "/fuse.yaml");
  fuse << "# coloc fuse " << out_dir << "/log --map " << summary.map_dir << " --config " << out_dir << "/fuse.yaml\n"
       << "pipeline:\n  initial_pose: [" << scenario.route_start.x() << ", " << scenario.route_start.y() << ", 0.0, " << scenario.route_heading
       << "]\nndt:\n  lidar_pose: [0.0, 0.0, " << scenario.vehicle_lidar_height << ", 0.0, 0.0, 0.0]\n"
       << "rsu:\n  registry: rsu.yaml\n  station_id: " << scenario.vehicle_station_id << "  # the ego's: its fixes are addressed to it\n";
  // The car knows its own size and what its CAM rounds it to.
  if (errors.cam_size_step > 0.0)
    fuse << "  vehicle_length: " << body.length << "  # the ego's own size; its CAM sends it in steps of " << errors.cam_size_step << " m\n"
         << "  vehicle_width: " << body.width << "\n  cam_size_step: " << errors.cam_size_step << "\n";
  summary.ego_length = body.length;
  summary.ego_width = body.width;
  // The map was surveyed to this (errors.map_position_sd): the reported covariance carries it, as a
  // user gives their map's survey accuracy.
  if (errors.map_position_sd > 0.0) fuse << "fusion:\n  map_error_sd: " << errors.map_position_sd << "  # the survey map's error per axis (errors.map_position_sd)\n";
  summary.drive_seconds = drive.duration();
  summary.wall_seconds = since(wall_start);
  return summary;
}

}  // namespace coloc::twin
