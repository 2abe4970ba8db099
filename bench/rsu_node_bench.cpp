// The RSU node's per-frame cost: a 64-beam LiDAR at 10 Hz (65,536 rays a turn) 8 m up a pole, and one
// or five connected vehicles in view at 20-50 m. Per frame the station looks for each vehicle, and
// learns one frame in five into its background (RsuStationConfig::learn_every); learning one frame
// alone is the baseline, measured in the same run.
// A 10 Hz LiDAR leaves 100 ms per frame.
#include <benchmark/benchmark.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>

#include <cmath>

#include "coloc/roadside/rsu_station.hpp"
#include "coloc/sim/lidar_model.hpp"
#include "coloc/sim/mesh.hpp"
#include "coloc/sim/ray_caster.hpp"
#include "coloc/sim/vehicle_body.hpp"
#include "near_points.hpp"

namespace {

using namespace coloc;

struct Scene {
  roadside::RsuMount mount;
  std::vector<std::vector<Eigen::Vector3f>> frames;  // commissioning, then the frames measured
  std::vector<roadside::ConnectedVehicle> vehicles;
};

// Five cars at 20-50 m in two lanes, their CAMs 0.3 m off; 20 frames of traffic to commission on.
const Scene& scene() {
  static const Scene s = [] {
    Scene out;
    sim::RayCaster world;
    world.addMesh(sim::groundRectangle({-90, -40}, {90, 40}));
    world.addMesh(sim::box({0, 16, 0}, {180, 1, 9}));
    const sim::VehicleBody car;
    std::vector<int> meshes;
    for (int i = 0; i < 5; ++i) meshes.push_back(world.addMesh(car.mesh(1e4 + 10 * i, 1e4, 0)));
    world.commit();
    out.mount.position = {0.0, -8.0, 8.0};
    out.mount.pitch = 1.9 * M_PI / 180.0;
    const Eigen::Isometry3d pose = Eigen::Translation3d(out.mount.position) * Eigen::AngleAxisd(out.mount.pitch, Eigen::Vector3d::UnitY());
    sim::RandomEngine rng(2);
    const auto frame = [&] {
      std::vector<Eigen::Vector3f> f;
      for (const sim::LidarPoint& p : sim::scanSweep(sim::os1_64(), world, [&](double) { return pose; }, rng)) f.push_back(p.position);
      return f;
    };
    const double xs[5] = {-45, -25, 22, 35, 48}, ys[5] = {0, 3.5, 0, 3.5, 0};
    for (int k = 0; k < 24; ++k) {
      for (int i = 0; i < 5; ++i) world.updateMesh(meshes[i], car.mesh(xs[i] + 0.8 * k, ys[i], 0.0));
      world.commit();
      out.frames.push_back(frame());
    }
    for (int i = 0; i < 5; ++i) {
      roadside::ConnectedVehicle v;
      v.station_id = 1001 + i;
      v.centre = {xs[i] + 0.8 * 23 + 0.2, ys[i] - 0.25};
      v.speed = 0.0;  // the same frame again and again: the vehicles stand where it shows them
      v.length = std::round(car.length * 10) / 10;
      v.width = std::round(car.width * 10) / 10;
      out.vehicles.push_back(v);
    }
    return out;
  }();
  return s;
}

void BM_LearnFrameOnly(benchmark::State& state) {
  const Scene& s = scene();
  roadside::BackgroundLearner learner;
  for (auto _ : state) learner.add(s.frames.back());
  state.counters["points"] = static_cast<double>(s.frames.back().size());
}
BENCHMARK(BM_LearnFrameOnly)->Unit(benchmark::kMillisecond);

// Commissioning: the 24 frames, each with its own noise, learned into a fresh learner; time per frame.
// Unlike one frame again and again, most returns find their voxel cold or new.
void BM_LearnFreshFrames(benchmark::State& state) {
  const Scene& s = scene();
  for (auto _ : state) {
    roadside::BackgroundLearner learner;
    for (const auto& f : s.frames) learner.add(f);
    benchmark::DoNotOptimize(learner.voxels());
  }
  state.counters["frames"] = static_cast<double>(s.frames.size());
  state.counters["per_frame_ms"] = benchmark::Counter(static_cast<double>(s.frames.size()) * 1e-3, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_LearnFreshFrames)->Unit(benchmark::kMillisecond);

void BM_StationFrame(benchmark::State& state) {
  const Scene& s = scene();
  roadside::RsuStationConfig config;
  config.commissioning_frames = 20;
  // The same frame again and again would become background itself: the background stays as
  // commissioned (learning one frame in five still costs what it costs).
  config.refresh_frames = 1 << 30;
  roadside::RsuStation station(s.mount, config);
  for (int k = 0; k < 20; ++k) station.frame(s.frames[k], fromSeconds(0.1 * k));
  Stamp t = fromSeconds(2.0);
  std::uint64_t found = 0, looked = 0;
  for (auto _ : state) {
    for (int i = 0; i < state.range(0); ++i) {
      roadside::ConnectedVehicle v = s.vehicles[i];
      v.stamp = t;
      station.addVehicle(v);
    }
    for (const roadside::StationOutcome& o : station.frame(s.frames.back(), t)) found += o.detection.found, ++looked;
    t += fromSeconds(0.1);
  }
  state.counters["vehicles"] = static_cast<double>(state.range(0));
  state.counters["found_share"] = looked ? static_cast<double>(found) / static_cast<double>(looked) : 0.0;
}
BENCHMARK(BM_StationFrame)->Arg(1)->Arg(5)->Unit(benchmark::kMillisecond);

// Each of the five vehicles looked for in one frame by the perception alone, as a caller of it frame by
// frame does: with CAMs of the body's size (range 0) and with a label's box, 0.4 m wider and 0.15 m
// longer (range 1), where each frame that shows the front or rear measures the width and, before
// placing the box with it, walks the frame once more to see the face's far end (BodySizeConfig::
// end_clearance). The first is the baseline, measured in the same run.
void BM_DetectEachVehicle(benchmark::State& state) {
  const Scene& s = scene();
  roadside::RsuStationConfig config;
  config.commissioning_frames = 20;
  roadside::RsuStation station(s.mount, config);
  for (int k = 0; k < 20; ++k) station.frame(s.frames[k], fromSeconds(0.1 * k));
  const roadside::RoadsidePerception& perception = *station.perception();
  const double length_excess = state.range(0) ? 0.15 : 0.0, width_excess = state.range(0) ? 0.4 : 0.0;
  std::uint64_t found = 0, placed_short = 0, looked = 0;
  for (auto _ : state) {
    for (const roadside::ConnectedVehicle& v : s.vehicles) {
      const double length = std::round((v.length + length_excess) * 10) / 10, width = std::round((v.width + width_excess) * 10) / 10;
      const roadside::VehicleDetection d = perception.detect(s.frames.back(), fromSeconds(2.0), v.centre, v.heading, length, width);
      found += d.found;
      placed_short += d.found && d.placed_size != Eigen::Vector2d(length, width);
      ++looked;
    }
  }
  state.counters["found_share"] = looked ? static_cast<double>(found) / static_cast<double>(looked) : 0.0;
  state.counters["placed_short_share"] = looked ? static_cast<double>(placed_short) / static_cast<double>(looked) : 0.0;
}
BENCHMARK(BM_DetectEachVehicle)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// The perception's test of each return against the reference frame (is a point of it within 0.15 m?):
// a k-d tree's nearest neighbour (PCL's, which the perception used before; range 0, the baseline, in
// the same run) against the perception's own cells (roadside/near_points, range 1). The reference is
// the first commissioning frame, the returns are the last frame's; both give the same answers.
void BM_BackgroundTest(benchmark::State& state) {
  const Scene& s = scene();
  const std::vector<Eigen::Vector3f>& reference = s.frames.front();
  const std::vector<Eigen::Vector3f>& returns = s.frames.back();
  const double distance = 0.15;
  std::uint64_t background = 0, looked = 0;
  if (state.range(0) == 0) {
    auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
    for (const auto& p : reference) cloud->push_back({p.x(), p.y(), p.z()});
    pcl::KdTreeFLANN<pcl::PointXYZ> tree;
    tree.setInputCloud(cloud);
    std::vector<int> index(1);
    std::vector<float> distance_sq(1);
    for (auto _ : state)
      for (const Eigen::Vector3f& p : returns) {
        background += tree.nearestKSearch(pcl::PointXYZ(p.x(), p.y(), p.z()), 1, index, distance_sq) > 0 && distance_sq[0] <= distance * distance;
        ++looked;
      }
  } else {
    const roadside::NearPoints near(reference, distance);
    for (auto _ : state)
      for (const Eigen::Vector3f& p : returns) background += near.anyWithin(p), ++looked;
  }
  state.counters["returns"] = static_cast<double>(returns.size());
  state.counters["background_share"] = looked ? static_cast<double>(background) / static_cast<double>(looked) : 0.0;
}
BENCHMARK(BM_BackgroundTest)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
