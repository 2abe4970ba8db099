// A vehicle stack that links coloc::pipeline: its driver callbacks push scans, twists and a roadside
// fix (from any thread), and the pipeline gives the fused estimate at every filter tick. The world is
// made up here so that the example needs no file: a street of walls and posts as the map, and scans
// that sample it from where the vehicle truly is. Its output is checked (exit 1 if the estimate is
// off), so the example is also a test.
#include <coloc/pipeline/pipeline.hpp>

#include <cmath>
#include <cstdio>
#include <random>

namespace {

constexpr coloc::Stamp kStart = 1'700'000'000'000'000'000LL;
constexpr double kSpeed = 8.0;  // m/s along x

// A 120 m street: walls 8 m either side with a post every 6 m, and a ground plane.
coloc::ndt::PointCloud street() {
  coloc::ndt::PointCloud map;
  for (double x = -20.0; x <= 120.0; x += 0.25) {
    for (double z = 0.0; z <= 4.0; z += 0.25) {
      map.points.emplace_back(x, 8.0, z);
      map.points.emplace_back(x, -8.0, z);
    }
    for (double y = -8.0; y <= 8.0; y += 0.5) map.points.emplace_back(x, y, 0.0);
    if (std::fmod(x + 20.0, 6.0) < 0.25)
      for (double z = 0.0; z <= 3.0; z += 0.1)
        for (double a = 0.0; a < 2 * M_PI; a += M_PI / 4) map.points.emplace_back(x + 0.15 * std::cos(a), 5.0 + 0.15 * std::sin(a), z);
  }
  return map;
}

// What a LiDAR at (x, 0) sees of the street within 40 m, in its own frame, with 2 cm of noise.
coloc::ndt::PointCloud scanAt(const coloc::ndt::PointCloud& world, double x, std::mt19937& rng) {
  std::normal_distribution<float> noise(0.0f, 0.02f);
  coloc::ndt::PointCloud scan;
  for (std::size_t i = 0; i < world.points.size(); i += 3) {
    const Eigen::Vector3f p = world.points[i] - Eigen::Vector3f(static_cast<float>(x), 0.0f, 0.0f);
    if (p.head<2>().norm() < 40.0f) scan.points.emplace_back(p.x() + noise(rng), p.y() + noise(rng), p.z() + noise(rng));
  }
  return scan;
}

}  // namespace

int main() {
  const coloc::ndt::PointCloud world = street();
  coloc::pipeline::Config config;                   // every default, as config/coloc.yaml lists them
  config.pipeline.initial_pose = Eigen::Vector4d(0.3, 0.2, 0.0, 0.02);  // where the stack believes it starts
  config.rsu.checks.station_id = 1001;              // this vehicle's CAM station id: the RSU addresses its fixes to it

  coloc::rsu_client::RsuInfo rsu;                   // one roadside unit with a VLP-32C at x = 60 m
  rsu.id = "rsu_a";
  rsu.position = {60.0, -9.0};
  rsu.lidar = *coloc::rsu_client::findLidarModel("VLP-32C");
  rsu.coverage_radius = rsu.lidar.range;
  rsu.identity = "CN=rsu_a";

  coloc::pipeline::PipelineOptions options;
  options.map = coloc::ndt::TileMap::fromCloud(world, 20.0);
  options.registry = coloc::rsu_client::RsuRegistry({rsu}, coloc::rsu_client::CovariancePlacement::kPublished);
  coloc::pipeline::Pipeline pipeline(config, std::move(options));
  const coloc::fusion::SourceId odometry = pipeline.addTwistSource("/vehicle/twist");
  coloc::fusion::Estimate last;
  pipeline.onEstimate([&](const coloc::fusion::Estimate& e) { last = e; });

  // Ten seconds of driving, fed as driver callbacks would: twist at 50 Hz, scans at 10 Hz (published
  // 30 ms after they were taken), and one RSU fix at 7.35 s that arrives 120 ms late.
  std::mt19937 rng(7);
  for (int k = 0; k <= 500; ++k) {
    const coloc::Stamp t = kStart + k * 20'000'000LL;
    coloc::TwistMeasurement twist;
    twist.stamp = t;
    twist.linear = {kSpeed, 0.0, 0.0};
    twist.covariance.diagonal() << 0.0004, coloc::kInfinity, coloc::kInfinity, coloc::kInfinity, coloc::kInfinity, 0.0001;
    pipeline.pushTwist(odometry, twist, t + 2'000'000);
    if (k % 5 == 0) pipeline.pushScan(scanAt(world, kSpeed * k * 0.02, rng), t, t + 30'000'000);
    if (k == 367) {
      const coloc::Stamp taken = t + 10'000'000;
      pipeline.pushFix({taken, "rsu_a", kSpeed * coloc::toSeconds(taken - kStart) + 0.004, -0.003, std::nullopt, std::nullopt, 1001u},
                       taken + 120'000'000);
    }
    pipeline.runUntil(t + 2'000'000);  // offline here; a live stack calls pipeline.start() instead
  }

  const coloc::pipeline::PipelineReport report = pipeline.report();
  const double truth_x = kSpeed * coloc::toSeconds(last.stamp - kStart);
  const double error = std::hypot(last.pose.position.x() - truth_x, last.pose.position.y());
  std::printf("estimate at %.2f s: x=%.3f y=%.3f (truth %.3f, 0.000): %.3f m off; %llu ticks, NDT %llu/%llu scans, fixes %llu/%llu applied\n",
              coloc::toSeconds(last.stamp - kStart), last.pose.position.x(), last.pose.position.y(), truth_x, error,
              static_cast<unsigned long long>(report.ticks), static_cast<unsigned long long>(report.ndt.poses),
              static_cast<unsigned long long>(report.ndt.scans), static_cast<unsigned long long>(report.filter_of_fixes.at("rsu_a").applied),
              static_cast<unsigned long long>(report.fixes.at("rsu_a").received));
  return error < 0.10 && report.filter_of_fixes.at("rsu_a").applied == 1 ? 0 : 1;
}
