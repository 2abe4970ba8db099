// `coloc simulate SCENARIO --out DIR`: drives the digital twin and records what the vehicle would have
// recorded, as a rosbag2 log that `coloc fuse` replays and ROS 2 plays: the roof LiDAR's scans, the
// odometry twist, the roadside units' fixes (after their perception and an emulated V2I link), and
// ground truth. Also writes the survey map as PCD tiles and a fuse configuration for the log.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>

#include "coloc/core/error.hpp"
#include "coloc/io/bag_writer.hpp"
#include "coloc/io/ros_messages.hpp"
#include "coloc/ndt/pcd_file.hpp"
#include "coloc/ndt/tile_map.hpp"
#include "coloc/rsu_client/link_emulator.hpp"
#include "coloc/rsu_client/rsu_registry.hpp"
#include "coloc/sim/lidar_model.hpp"
#include "coloc/sim/roadside_perception.hpp"
#include "coloc/sim/scene.hpp"
#include "coloc/sim/survey_map.hpp"
#include "coloc/sim/vehicle_body.hpp"
#include "commands.hpp"
#include "progress.hpp"
#include "svg_plot.hpp"

namespace coloc::tools {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr Stamp kEpoch = 1'700'000'000'000'000'000LL;  // the twin's clock starts here: runs repeat exactly

Stamp at(double t) { return kEpoch + fromSeconds(t); }

sim::LidarSpec lidarNamed(const std::string& name) { return name == "VLP-16" ? sim::vlp16() : sim::vlp32c(); }

io::TopicInfo topic(const std::string& name, const std::string& type) {
  io::TopicInfo t;
  t.name = name;
  t.type = type;
  return t;
}

io::PointCloud2 toPointCloud2(const std::vector<sim::LidarPoint>& points, Stamp stamp) {
  io::PointCloud2 m;
  m.header = {stamp, "lidar"};
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
  return m;
}

Eigen::Isometry3d vehiclePose(const sim::VehicleState& s, double height) {
  return Eigen::Translation3d(s.position.x(), s.position.y(), height) * Eigen::AngleAxisd(s.yaw, Eigen::Vector3d::UnitZ());
}

struct Timing {
  double ray_casting = 0, perception = 0, map = 0, writing = 0;
  std::uint64_t rays = 0;
};

}  // namespace

void addSimulateCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("simulate", "Drive the digital twin through a scenario and record a rosbag2 log");
  static std::string scenario_path, out_dir = "sim_out";
  static rsu_client::LinkConfig link;
  static double rsu_processing = 0.01;
  cmd->add_option("SCENARIO", scenario_path, "scenario YAML (see config/scenarios/)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--out", out_dir, "output folder: log/, map/, fuse.yaml, rsu_fixes.csv, rsu_fix_error.svg")->capture_default_str();
  cmd->add_option("--delay", link.delay, "V2I delay of the fixes, s")->capture_default_str();
  cmd->add_option("--jitter", link.jitter, "V2I delay jitter, s")->capture_default_str();
  cmd->add_option("--loss", link.loss, "V2I loss probability")->capture_default_str();
  cmd->add_option("--rsu-processing", rsu_processing,
                  "time the RSU takes from the end of its sweep to sending the fix, s (simulated, so runs repeat; "
                  "the measured time is in rsu_fixes.csv)")
      ->capture_default_str();
  cmd->callback([] {
    const auto wall_start = Clock::now();
    const sim::Scenario scenario = sim::loadScenario(scenario_path);
    if (fs::exists(out_dir) && !fs::is_empty(out_dir)) throw Error(out_dir + ": the output folder exists and is not empty");
    fs::create_directories(out_dir + "/map");
    Timing timing;
    link.seed = scenario.seed;

    // 1. The survey map, as 20 m PCD tiles.
    {
      ProgressBar progress("survey map");
      const auto t0 = Clock::now();
      const ndt::PointCloud map = sim::surveyMap(scenario, {}, [&](double f) { progress.update(f); });
      const ndt::TileMap tiles = ndt::TileMap::fromCloud(map, 20.0);
      for (std::size_t i = 0; i < tiles.tiles().size(); ++i) {
        char name[64];
        std::snprintf(name, sizeof name, "/map/tile_%04zu.pcd", i);
        ndt::savePcd(out_dir + name, tiles.load(i));
      }
      timing.map = std::chrono::duration<double>(Clock::now() - t0).count();
    }

    // 2. The world: static scene, plus the ego vehicle for the roadside LiDARs.
    sim::RayCaster scene, with_vehicle;
    for (const sim::TriangleMesh& m : scenario.worldMeshes()) {
      scene.addMesh(m);
      with_vehicle.addMesh(m);
    }
    const sim::VehicleBody body;
    const int body_mesh = with_vehicle.addMesh(body.mesh(1e4, 1e4, 0.0));
    scene.commit();
    with_vehicle.commit();
    const sim::Drive drive(sim::Route(scenario.route_start, scenario.route_heading, scenario.route), scenario.speed);
    std::mt19937_64 rng(scenario.seed);

    // 3. Roadside units: their background frames and perception.
    struct Rsu {
      sim::ScenarioRsu info;
      sim::LidarSpec lidar;
      std::unique_ptr<sim::RoadsidePerception> perception;
      rsu_client::LinkEmulator link;
      double variance;
      double range;
    };
    std::vector<Rsu> rsus;
    for (const sim::ScenarioRsu& r : scenario.rsus) {
      sim::RsuMount mount;
      mount.position = {r.position.x(), r.position.y(), r.height};
      mount.yaw = r.yaw;
      const Eigen::Isometry3d pose = Eigen::Translation3d(mount.position) * Eigen::AngleAxisd(r.yaw, Eigen::Vector3d::UnitZ());
      std::vector<Eigen::Vector3f> reference;
      for (const auto& p : sim::scanSweep(lidarNamed(r.lidar_model), scene, [&](double) { return pose; }, rng)) reference.push_back(p.position);
      const rsu_client::LidarModel* model = rsu_client::findLidarModel(r.lidar_model);
      rsu_client::LinkConfig l = link;
      l.seed = scenario.seed + rsus.size() + 1;
      rsus.push_back({r, lidarNamed(r.lidar_model), std::make_unique<sim::RoadsidePerception>(reference, mount), rsu_client::LinkEmulator(l),
                      model->sigma, model->range});
    }

    // 4. The drive, recorded.
    io::BagWriter bag = io::BagWriter::create(out_dir + "/log");
    bag.addTopic(topic("/points", "sensor_msgs/msg/PointCloud2"));
    bag.addTopic(topic("/vehicle/twist", "geometry_msgs/msg/TwistWithCovarianceStamped"));
    bag.addTopic(topic("/ground_truth/odom", "nav_msgs/msg/Odometry"));
    for (const Rsu& r : rsus) bag.addTopic(topic("/rsu/" + r.info.id + "/fix", "geometry_msgs/msg/PoseWithCovarianceStamped"));
    std::ofstream fixes_csv(out_dir + "/rsu_fixes.csv");
    std::map<std::string, PlotSeries> fix_errors;  // per RSU: error against distance
    fixes_csv << "stamp_s,rsu,distance_m,error_x_m,error_y_m,error_m,processing_ms,delivered\n";
    const sim::LidarSpec roof = lidarNamed(scenario.vehicle_lidar);
    const sim::OdometryNoise odometry_noise;
    ProgressBar progress("simulating");
    const int ticks = static_cast<int>(std::floor(drive.duration() * 100.0));
    std::uint64_t scans = 0, fixes = 0;
    for (int k = 0; k <= ticks; ++k) {  // 100 Hz
      const double t = k * 0.01;
      const sim::VehicleState truth = drive.at(t);
      progress.update(static_cast<double>(k) / ticks);
      io::Odometry gt;
      gt.header = {at(t), "map"};
      gt.child_frame_id = "base_link";
      gt.pose.pose.position = {truth.position.x(), truth.position.y(), 0.0};
      gt.pose.pose.orientation = quaternionFromRollPitchYaw(0, 0, truth.yaw);
      gt.twist.linear = {truth.speed, 0, 0};
      gt.twist.angular = {0, 0, truth.yaw_rate};
      const io::Bytes gt_bytes = io::encodeOdometry(gt);
      bag.write("/ground_truth/odom", at(t), gt_bytes.data(), gt_bytes.size());
      if (k % 2 == 0) {  // 50 Hz odometry, logged 2 ms after sensing
        const sim::OdometrySample o = sim::measureOdometry(truth, odometry_noise, rng);
        io::StampedTwist tw;
        tw.header = {at(t), "base_link"};
        tw.measurement.linear = {o.speed, 0, 0};
        tw.measurement.angular = {0, 0, o.yaw_rate};
        tw.measurement.covariance = Matrix6d::Zero();
        tw.measurement.covariance.diagonal() << 0.04, kInfinity, kInfinity, kInfinity, kInfinity, 0.01;
        const io::Bytes b = io::encodeTwistWithCovarianceStamped(tw);
        bag.write("/vehicle/twist", at(t) + 2'000'000, b.data(), b.size());
      }
      if (k % 10 == 0) {  // 10 Hz: a roof sweep, and each RSU's frame
        const auto c0 = Clock::now();
        const auto sweep = sim::scanSweep(roof, scene, [&](double dt) { return vehiclePose(drive.at(t + dt), scenario.vehicle_lidar_height); }, rng);
        timing.ray_casting += std::chrono::duration<double>(Clock::now() - c0).count();
        timing.rays += static_cast<std::uint64_t>(roof.vertical_deg.size() * 1800);
        const io::Bytes b = io::encodePointCloud2(toPointCloud2(sweep, at(t)));
        bag.write("/points", at(t + 0.1) + 5'000'000, b.data(), b.size());  // the sweep ends, the driver publishes
        ++scans;
        // The RSUs see the vehicle where it is half-way through their sweep, and stamp the fix then.
        const double capture = t + 0.05;
        const sim::VehicleState seen = drive.at(capture);
        with_vehicle.updateMesh(body_mesh, body.mesh(seen.position.x(), seen.position.y(), seen.yaw));
        with_vehicle.commit();
        for (Rsu& r : rsus) {
          const double distance = (seen.position - r.info.position).norm();
          if (distance > r.range) continue;
          const Eigen::Isometry3d pose = Eigen::Translation3d(r.info.position.x(), r.info.position.y(), r.info.height) *
                                         Eigen::AngleAxisd(r.info.yaw, Eigen::Vector3d::UnitZ());
          const auto c1 = Clock::now();
          std::vector<Eigen::Vector3f> frame;
          for (const auto& p : sim::scanSweep(r.lidar, with_vehicle, [&](double) { return pose; }, rng)) frame.push_back(p.position);
          timing.ray_casting += std::chrono::duration<double>(Clock::now() - c1).count();
          timing.rays += static_cast<std::uint64_t>(r.lidar.vertical_deg.size() * 1800);
          // The CAM gives the RSU a reference position with the vehicle's own error, about 0.3 m.
          std::normal_distribution<double> cam(0.0, 0.3);
          const Eigen::Vector2d reference = seen.position + Eigen::Vector2d(cam(rng), cam(rng));
          const sim::VehicleDetection d = r.perception->detect(frame, at(capture), reference, seen.yaw, body.length, body.width);
          timing.perception += d.processing_ms * 1e-3;
          if (!d.found) continue;
          const Stamp ready = at(capture + 0.05 + rsu_processing);  // end of the sweep + processing
          const std::optional<Stamp> delivered = r.link.transmit(ready);
          const Eigen::Vector2d error = d.position - seen.position;
          fixes_csv << formatSeconds(at(capture)) << "," << r.info.id << "," << distance << "," << error.x() << "," << error.y() << ","
                    << error.norm() << "," << d.processing_ms << "," << (delivered ? 1 : 0) << "\n";
          PlotSeries& series = fix_errors[r.info.id];
          series.label = r.info.id + " (" + r.info.lidar_model + ")";
          series.points = true;
          series.x.push_back(distance);
          series.y.push_back(error.norm());
          if (!delivered) continue;
          io::StampedPose fix;
          fix.header = {at(capture), "map"};
          fix.measurement.pose.position = {d.position.x(), d.position.y(), 0.0};
          fix.measurement.covariance = Matrix6d::Zero();
          fix.measurement.covariance.diagonal() << r.variance, r.variance, kInfinity, kInfinity, kInfinity, kInfinity;
          const io::Bytes fb = io::encodePoseWithCovarianceStamped(fix);
          bag.write("/rsu/" + r.info.id + "/fix", *delivered, fb.data(), fb.size());
          ++fixes;
        }
      }
    }
    progress.finish();
    bag.close();
    if (!fix_errors.empty()) {
      Plot plot;
      plot.title = "RSU fix error against distance from the RSU: " + scenario.name;
      plot.x_label = "distance from the RSU [m]";
      plot.y_label = "fix error [m]";
      plot.y_from_zero = true;
      for (auto& [id, series] : fix_errors) plot.series.push_back(series);
      writeSvg(out_dir + "/rsu_fix_error.svg", plot);
    }
    // 5. How to replay it: NDT needs a first guess; the twin knows where the drive starts.
    std::ofstream fuse(out_dir + "/fuse.yaml");
    fuse << "# coloc fuse " << out_dir << "/log --map " << out_dir << "/map --config " << out_dir << "/fuse.yaml\n"
         << "replay:\n  initial_pose: [" << scenario.route_start.x() << ", " << scenario.route_start.y() << ", 0.0, "
         << scenario.route_heading << "]\nndt:\n  lidar_pose: [0.0, 0.0, " << scenario.vehicle_lidar_height << ", 0.0, 0.0, 0.0]\n";
    const double wall = std::chrono::duration<double>(Clock::now() - wall_start).count();
    std::printf("simulated %s: %.1f s of driving in %.1f s (%.1fx real time)\n", scenario.name.c_str(), drive.duration(), wall,
                drive.duration() / wall);
    std::printf("  %llu roof scans, %llu RSU fixes recorded; %.2f M rays/s of ray casting\n", (unsigned long long)scans,
                (unsigned long long)fixes, timing.rays / std::max(timing.ray_casting, 1e-9) * 1e-6);
    std::printf("  time: survey map %.1f s, ray casting %.1f s, roadside perception %.2f s, the rest %.1f s\n", timing.map,
                timing.ray_casting, timing.perception, wall - timing.map - timing.ray_casting - timing.perception);
    std::printf("  wrote %s/{log/, map/, fuse.yaml, rsu_fixes.csv, rsu_fix_error.svg}\n", out_dir.c_str());
  });
}

}  // namespace coloc::tools
