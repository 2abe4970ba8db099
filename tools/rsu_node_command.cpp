// `coloc rsu-node`: a roadside unit's own process (the paper's RSU node). Its LiDAR's frames and the
// connected vehicles' CAMs in; for each vehicle it finds, a fix addressed to it out (docs/rsu-protocol.md,
// "The RSU fix protocol"). Live over DDS with ROS 2 names and QoS, or offline over a log that holds the frames
// (`coloc simulate --rsu-frames` records them), writing the fixes it would have sent.
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <thread>

#include "coloc/core/error.hpp"
#include "coloc/core/principal_variances.hpp"
#include "coloc/io/bag_reader.hpp"
#include "coloc/io/bag_writer.hpp"
#include "coloc/io/ros_messages.hpp"
#include "coloc/io/v2x_messages.hpp"
#include "coloc/pipeline/message_inputs.hpp"
#include "coloc/replay/svg_plot.hpp"
#include "coloc/roadside/rsu_station.hpp"
#include "coloc/rsu_client/dds_node.hpp"
#include "coloc/rsu_client/dds_transport.hpp"
#include "coloc/rsu_client/rsu_registry.hpp"
#include "coloc/twin/twin_recording.hpp"
#include "commands.hpp"
#include "dds_options.hpp"
#include "log_options.hpp"
#include "number_checks.hpp"
#include "teardown_watchdog.hpp"

namespace coloc::tools {

namespace {

std::atomic<bool> g_stop_node{false};
extern "C" void requestNodeStop(int) { g_stop_node.store(true); }

struct NodeSettings {
  std::string registry_path = "config/rsu.yaml", id, log, out_dir = "rsu_node_out";
  int commission = 50;
  bool level_from_ground = false;
  bool recover = false;
  double frame_time_offset = 0.05;  // s from a frame's header stamp to the moment the vehicle is seen
  std::int64_t truth_station = -1;
  double duration = 0.0, idle = 0.0;
  DdsOptions dds;
};

roadside::RsuMount mountOf(const rsu_client::RsuInfo& rsu) {
  roadside::RsuMount m;
  m.position = {rsu.position.x(), rsu.position.y(), rsu.height};
  m.yaw = rsu.yaw;
  m.roll = rsu.roll;
  m.pitch = rsu.pitch;
  return m;
}

// The station as this RSU and the command line set it up, live and offline alike.
roadside::RsuStation stationFor(const NodeSettings& s, const rsu_client::RsuInfo& rsu) {
  roadside::RsuStationConfig config;
  config.coverage = rsu.coverage_radius;
  config.commissioning_frames = std::max(1, s.commission);
  config.level_from_ground = s.level_from_ground;
  // The perception's column spacing is the registry's LiDAR model's: it bounds a face's ends, each
  // fix's doubt and what a face seen alone may lack.
  config.perception.covariance.azimuth_step = rsu.lidar.azimuth_step_deg * M_PI / 180.0;
  return roadside::RsuStation(mountOf(rsu), config);
}

roadside::ConnectedVehicle vehicleOf(const io::Cam& cam) {
  roadside::ConnectedVehicle v;
  v.stamp = cam.header.stamp;
  v.station_id = cam.station_id;
  v.centre = cam.centre();
  v.heading = cam.heading;
  v.speed = cam.speed;
  v.yaw_rate = cam.yaw_rate;
  v.length = cam.length;
  v.width = cam.width;
  return v;
}

std::string refusalCounts(const roadside::StationCounters& c) {
  std::string out;
  for (int r = 1; r < roadside::kRefusalCount; ++r)
    if (c.refused[r]) out += std::string(out.empty() ? "" : "; ") + roadside::toString(static_cast<roadside::Refusal>(r)) + " " + std::to_string(c.refused[r]);
  return out.empty() ? "none" : out;
}

void printCounters(const roadside::RsuStation& station) {
  const roadside::StationCounters& c = station.counters();
  std::printf("  %llu frames (%llu learned while commissioning), %llu CAMs (%llu refused), %llu fixes; refused: %s\n", (unsigned long long)c.frames,
              (unsigned long long)c.commissioning_frames, (unsigned long long)c.cams, (unsigned long long)c.cams_refused, (unsigned long long)c.fixes,
              refusalCounts(c).c_str());
  if (const auto l = station.levelling())
    std::printf("  levelled from the road: roll %.2f deg, pitch %.2f deg, %.2f m above it (the registry's tilt replaced)\n", l->roll * 180.0 / M_PI,
                l->pitch * 180.0 / M_PI, l->height);
  if (c.fixes_with_measured_size)
    std::printf("  %llu fixes placed with a side the vehicle's frames measured shorter than its CAM said (a CAM box larger than the body)\n",
                (unsigned long long)c.fixes_with_measured_size);
  if (c.clock_resets) std::printf("  the frames' clock went back %llu times: CAMs and tracks started afresh each time\n", (unsigned long long)c.clock_resets);
  if (const auto plane = station.roadPlane()) {
    const roadside::Levelling l = roadside::levellingOf(*plane);
    std::printf("  road found in the background: %zu cells, %.3f m rms about its plane; the plane slopes %.2f deg along x, %.2f deg along y "
                "(in the map, after the registry's tilt)\n",
                plane->cells, plane->rms, -l.pitch * 180.0 / M_PI, l.roll * 180.0 / M_PI);
    if (!station.levelling() && std::hypot(l.roll, l.pitch) > 0.5 * M_PI / 180.0)
      std::printf("  warning: a road this steep is more likely a LiDAR tilted other than the registry says (roll_deg, pitch_deg): "
                  "--level-from-ground takes the tilt from the road\n");
  }
}

// A fix as sent: addressed to its vehicle, with the covariance of its own fit, never below the
// registry's figure for this RSU's LiDAR (what a vehicle refuses).
io::Bytes fixMessage(Stamp stamp, const roadside::StationOutcome& o, double floor) {
  return io::encodeOdometry(twin::addressedFix(stamp, o.detection.position, o.detection.covariance, floor, o.station_id));
}

// The frame's points, in its sensor frame.
std::vector<Eigen::Vector3f> pointsOf(const io::Bytes& bytes, Stamp& stamp) {
  const io::PointCloud2 cloud = io::decodePointCloud2(bytes.data(), bytes.size());
  stamp = cloud.header.stamp;
  return pipeline::toPointCloud(cloud).points;
}

void runOffline(const NodeSettings& s, const rsu_client::RsuRegistry& registry, const rsu_client::RsuInfo& rsu) {
  const std::string points_topic = rsu_client::roadsidePointsTopic(rsu.id), fix_topic = rsu_client::addressedFixTopic(rsu.id);
  bool has_points = false, has_cams = false;
  {
    const io::BagReader probe = io::BagReader::open(s.log, io::BagReadOptions{s.recover});
    for (const io::TopicInfo& t : probe.topics()) {
      has_points = has_points || t.name == points_topic;
      has_cams = has_cams || t.name == rsu_client::kCamTopic;
    }
  }
  if (!has_points) throw Error(s.log + ": has no topic " + points_topic + " (RSU " + rsu.id + "'s frames; `coloc simulate --rsu-frames` records them)");
  if (!has_cams) throw Error(s.log + ": has no topic " + std::string(rsu_client::kCamTopic) + " (the connected vehicles' CAMs)");
  roadside::RsuStation station = stationFor(s, rsu);
  // Commissioning: the background and the road from the log's first frames, before any fix.
  std::map<Stamp, Eigen::Vector2d> truth;
  {
    io::BagReader bag = io::BagReader::open(s.log, io::BagReadOptions{s.recover});
    io::BagMessage m;
    int learned = 0;
    while (bag.next(m)) {
      if (m.topic == points_topic && learned < s.commission) {
        Stamp stamp = 0;
        station.learn(pointsOf(m.data, stamp));
        ++learned;
      } else if (m.topic == "/ground_truth/odom" && s.truth_station >= 0) {
        const io::Odometry o = io::decodeOdometry(m.data.data(), m.data.size());
        truth[o.header.stamp] = o.pose.pose.position.head<2>();
      }
    }
    if (!station.commission()) throw Error(s.log + ": no background could be learned from " + std::to_string(learned) + " frames of " + points_topic);
  }
  std::filesystem::create_directories(s.out_dir);
  std::ofstream csv(s.out_dir + "/fixes.csv");
  csv << "stamp_s,station_id,outcome,x,y,yaw_deg,distance_m,fit_points,processing_ms,error_m,sd_x_m,sd_y_m\n";
  io::BagWriter out = io::BagWriter::create(s.out_dir + "/log");
  io::TopicInfo fix_info;
  fix_info.name = fix_topic;
  fix_info.type = "nav_msgs/msg/Odometry";
  out.addTopic(fix_info);
  const double variance = registry.variance(rsu);
  io::BagReader bag = io::BagReader::open(s.log, io::BagReadOptions{s.recover});
  io::BagMessage m;
  std::vector<double> errors;
  replay::PlotSeries error_series, sd_series;  // the scored station's fixes against range
  error_series.label = "fix error";
  error_series.points = true;
  sd_series.label = "its own sd (larger axis)";
  sd_series.points = true;
  std::uint64_t undecodable = 0;
  while (bag.next(m)) {
    try {
      if (m.topic == rsu_client::kCamTopic) {
        station.addVehicle(vehicleOf(io::decodeCam(m.data.data(), m.data.size())));
      } else if (m.topic == points_topic) {
        Stamp stamp = 0;
        const std::vector<Eigen::Vector3f> points = pointsOf(m.data, stamp);
        const Stamp seen = stamp + fromSeconds(s.frame_time_offset);
        for (const roadside::StationOutcome& o : station.frame(points, seen)) {
          const roadside::VehicleDetection& d = o.detection;
          double error = std::nan("");
          if (d.found && static_cast<std::int64_t>(o.station_id) == s.truth_station && !truth.empty()) {
            const auto after = truth.lower_bound(seen);
            if (after != truth.end() && after != truth.begin()) {
              const auto before = std::prev(after);
              const double w = toSeconds(seen - before->first) / std::max(1e-9, toSeconds(after->first - before->first));
              error = (d.position - (before->second + w * (after->second - before->second))).norm();
              errors.push_back(error);
              error_series.x.push_back(o.distance);
              error_series.y.push_back(error);
              sd_series.x.push_back(o.distance);
              sd_series.y.push_back(std::sqrt(largestPrincipalVariance(d.covariance)));
            }
          }
          csv << formatSeconds(seen) << "," << o.station_id << "," << (d.found ? "fix" : roadside::toString(d.refusal)) << "," << d.position.x() << ","
              << d.position.y() << "," << d.yaw * 180.0 / M_PI << "," << o.distance << "," << d.fit_points << "," << d.processing_ms << "," << error << ","
              << std::sqrt(d.covariance(0, 0)) << "," << std::sqrt(d.covariance(1, 1)) << "\n";
          if (!d.found) continue;
          // Sent once the frame is processed: the log's time of the frame plus the measured processing.
          const io::Bytes fix = fixMessage(seen, o, variance);
          out.write(fix_topic, m.log_time + fromSeconds(d.processing_ms * 1e-3), fix.data(), fix.size());
        }
      }
    } catch (const Error& e) {
      if (undecodable++ == 0) std::fprintf(stderr, "rsu-node: %s: %s (further ones counted)\n", m.topic.c_str(), e.what());
    }
  }
  out.close();
  std::printf("rsu-node %s offline over %s:\n", rsu.id.c_str(), s.log.c_str());
  printCounters(station);
  if (undecodable) std::printf("  %llu messages undecodable, skipped\n", (unsigned long long)undecodable);
  if (!errors.empty()) {
    std::sort(errors.begin(), errors.end());
    std::printf("  station %lld's fixes against /ground_truth/odom: %zu, median %.3f m, p90 %.3f m, worst %.3f m\n", (long long)s.truth_station,
                errors.size(), errors[errors.size() / 2], errors[std::min(errors.size() - 1, errors.size() * 9 / 10)], errors.back());
  }
  if (!errors.empty()) {
    replay::Plot plot;
    plot.title = "RSU " + rsu.id + ": station " + std::to_string(s.truth_station) + "'s fixes against range";
    plot.x_label = "distance from the RSU [m]";
    plot.y_label = "[m]";
    plot.y_from_zero = true;
    plot.series = {error_series, sd_series};
    replay::writeSvg(s.out_dir + "/fix_error.svg", plot);
  }
  std::printf("  wrote %s/{fixes.csv, log/%s} (%s, nav_msgs/msg/Odometry addressed to each vehicle)\n", s.out_dir.c_str(),
              errors.empty() ? "" : ", fix_error.svg", fix_topic.c_str());
}

void runLive(const NodeSettings& s, const rsu_client::RsuRegistry& registry, const rsu_client::RsuInfo& rsu) {
  roadside::RsuStation station = stationFor(s, rsu);
  std::mutex station_mutex;
  const double variance = registry.variance(rsu);
  const rsu_client::DdsConfig dds = ddsConfig(s.dds, "coloc_rsu_" + rsu.id);
  printSecurity(dds);
  std::signal(SIGINT, requestNodeStop);
  std::signal(SIGTERM, requestNodeStop);
  TeardownWatchdog watchdog("rsu-node");
  watchdog.arm(1);
  rsu_client::DdsNode node(dds);
  watchdog.disarm();
  const TeardownWatchdog::ArmOnExit arm_on_exit(watchdog);
  rsu_client::TopicQos fix_qos;
  fix_qos.reliable = true;
  fix_qos.depth = 10;
  rsu_client::DdsNode::Writer writer = node.advertise(rsu_client::addressedFixTopic(rsu.id), "nav_msgs/msg/Odometry", fix_qos);
  std::atomic<std::uint64_t> inputs{0}, undecodable{0}, sent{0};
  std::mutex error_mutex;
  std::string first_error;  // the first refused input, named with its reason
  const auto refused = [&](const std::string& topic, const std::string& why) {
    if (undecodable++ != 0) return;
    std::lock_guard<std::mutex> lock(error_mutex);
    first_error = topic + ": " + why;
    std::fprintf(stderr, "rsu-node: %s (further ones counted)\n", first_error.c_str());
  };
  rsu_client::TopicQos cam_qos;
  cam_qos.reliable = s.dds.reliable;
  cam_qos.depth = 100;  // a CAM from each vehicle in range, 10 Hz
  node.subscribe(rsu_client::kCamTopic, io::kCamType, cam_qos, [&](std::vector<std::uint8_t>&& bytes, Stamp) {
    ++inputs;
    try {
      const io::Cam cam = io::decodeCam(bytes.data(), bytes.size());
      std::lock_guard<std::mutex> lock(station_mutex);
      station.addVehicle(vehicleOf(cam));
    } catch (const Error& e) {
      refused(rsu_client::kCamTopic, e.what());
    }
  });
  rsu_client::TopicQos points_qos;  // the LiDAR driver's sensor data: best effort unless asked
  points_qos.reliable = s.dds.reliable;
  points_qos.depth = 2;
  node.subscribe(rsu_client::roadsidePointsTopic(rsu.id), "sensor_msgs/msg/PointCloud2", points_qos, [&](std::vector<std::uint8_t>&& bytes, Stamp) {
    ++inputs;
    try {
      Stamp stamp = 0;
      const std::vector<Eigen::Vector3f> points = pointsOf(bytes, stamp);
      const Stamp seen = stamp + fromSeconds(s.frame_time_offset);
      std::vector<roadside::StationOutcome> outcomes;
      {
        std::lock_guard<std::mutex> lock(station_mutex);
        outcomes = station.frame(points, seen);
      }
      for (const roadside::StationOutcome& o : outcomes)
        if (o.detection.found && writer.write(fixMessage(seen, o, variance))) ++sent;
    } catch (const Error& e) {
      refused(rsu_client::roadsidePointsTopic(rsu.id), e.what());
    }
  });
  std::printf("rsu-node %s: frames %s, CAMs %s; fixes out on %s; LiDAR at [%.2f, %.2f] %.2f m up, yaw %.2f deg, roll %.2f, pitch %.2f; commissioning "
              "on the first %d frames\n",
              rsu.id.c_str(), rsu_client::roadsidePointsTopic(rsu.id).c_str(), rsu_client::kCamTopic, rsu_client::addressedFixTopic(rsu.id).c_str(),
              rsu.position.x(), rsu.position.y(), rsu.height, rsu.yaw * 180.0 / M_PI, rsu.roll * 180.0 / M_PI, rsu.pitch * 180.0 / M_PI, s.commission);
  std::fflush(stdout);
  const auto start = std::chrono::steady_clock::now();
  auto last_status = start, last_input = start;
  std::uint64_t seen_inputs = 0;
  while (!g_stop_node.load()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    const auto now = std::chrono::steady_clock::now();
    if (inputs.load() != seen_inputs) seen_inputs = inputs.load(), last_input = now;
    if (now - last_status >= std::chrono::seconds(1)) {
      last_status = now;
      std::lock_guard<std::mutex> lock(station_mutex);
      const roadside::StationCounters& c = station.counters();
      std::printf("[%6.1f s] %s | %llu frames, %llu CAMs | %llu fixes sent | refused: %s | undecodable %llu\n",
                  std::chrono::duration<double>(now - start).count(), station.commissioned() ? "running" : "commissioning", (unsigned long long)c.frames,
                  (unsigned long long)c.cams, (unsigned long long)sent.load(), refusalCounts(c).c_str(), (unsigned long long)undecodable.load());
      std::fflush(stdout);
    }
    if (s.duration > 0.0 && std::chrono::duration<double>(now - start).count() >= s.duration) break;
    if (s.idle > 0.0 && seen_inputs > 0 && std::chrono::duration<double>(now - last_input).count() >= s.idle) break;
  }
  writer.waitForAcknowledgments(2.0);
  std::lock_guard<std::mutex> lock(station_mutex);
  std::printf("rsu-node %s stopped: %llu fixes sent\n", rsu.id.c_str(), (unsigned long long)sent.load());
  printCounters(station);
  if (undecodable.load()) std::printf("  %llu inputs refused; the first: %s\n", (unsigned long long)undecodable.load(), first_error.c_str());
  std::fflush(stdout);
}

}  // namespace

void addRsuNodeCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("rsu-node",
                                 "A roadside unit's node: its LiDAR's frames and the vehicles' CAMs in, a fix addressed to each vehicle found out "
                                 "(live over DDS, or offline over a log with --log)");
  static NodeSettings s;
  cmd->add_option("--registry", s.registry_path, "RSU registry (YAML): this RSU's position, height, mounting yaw and tilt, LiDAR")
      ->capture_default_str();
  cmd->add_option("--id", s.id, "this RSU's id in the registry (default: the registry's only RSU)");
  cmd->add_option("--log", s.log, "offline: a log holding the RSU's frames (/rsu/<id>/points) and the CAMs (/v2x/cam)")->check(CLI::ExistingPath);
  addRecoverFlag(cmd, s.recover);
  cmd->add_option("--out", s.out_dir, "offline: where fixes.csv and log/ (the fixes it would have sent) go")->capture_default_str();
  cmd->add_option("--commission", s.commission, "frames the background and the road are learned from before the first fix")
      ->check(wholeNumber(1, 100000))
      ->capture_default_str();
  cmd->add_flag("--level-from-ground", s.level_from_ground,
                "take the LiDAR's roll and pitch from the road it sees while commissioning (the tilt to the road) instead of the registry's");
  cmd->add_option("--frame-time-offset", s.frame_time_offset,
                  "s from a frame's header stamp to when the vehicle is seen in it (half a sweep for a driver that stamps its start)")
      ->check(finiteNumber(-1.0, 1.0))
      ->capture_default_str();
  cmd->add_option("--truth-station", s.truth_station, "offline: score this station's fixes against the log's /ground_truth/odom")
      ->check(CLI::Range(static_cast<std::int64_t>(0), static_cast<std::int64_t>(4294967295LL)));
  cmd->add_option("--duration", s.duration, "live: stop after this many seconds (0 = until SIGINT or SIGTERM)")->check(finiteNumber(0.0));
  cmd->add_option("--idle-exit", s.idle, "live: stop once no input arrived for this many seconds, after the first (0 = never)")->check(finiteNumber(0.0));
  cmd->add_option("--name", s.dds.name, "DDS participant name (and security file prefix)");
  addDdsOptions(cmd, s.dds);
  cmd->callback([] {
    const rsu_client::RsuRegistry registry = rsu_client::RsuRegistry::load(s.registry_path);
    const rsu_client::RsuInfo* rsu = nullptr;
    if (s.id.empty()) {
      if (registry.rsus().size() != 1)
        throw Error(s.registry_path + ": lists " + std::to_string(registry.rsus().size()) + " RSUs: say which this node is (--id)");
      rsu = &registry.rsus().front();
    } else if (!(rsu = registry.find(s.id))) {
      throw Error(s.registry_path + ": has no RSU '" + s.id + "'");
    }
    if (!s.log.empty()) runOffline(s, registry, *rsu);
    else runLive(s, registry, *rsu);
  });
}

}  // namespace coloc::tools
