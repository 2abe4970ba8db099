// The roadside perception from the heights real RSUs stand at: the paper's 2 m mast and intersection
// poles of 5-9 m, cars 20-60 m away, the CAM 0.3 m off with its size quantized to 0.1 m.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include "coloc/roadside/roadside_perception.hpp"
#include "coloc/sim/error_sources.hpp"
#include "coloc/sim/lidar_model.hpp"
#include "coloc/sim/mesh.hpp"
#include "coloc/sim/ray_caster.hpp"
#include "coloc/sim/vehicle_body.hpp"

namespace coloc::roadside {
namespace {

using namespace coloc::sim;  // the twin makes the frames

struct Outcome {
  int frames = 0, found = 0;
  std::vector<double> errors;
  std::vector<std::pair<double, double>> by_range;  ///< (range, error) of each fix
  std::array<int, 4> frames_by_range{};            ///< frames at 20-30, 30-40, 40-50, 50-60 m
  std::vector<double> nis;  ///< each fix's error squared, normalized by its covariance (chi-square, 2 dof)
  std::vector<double> radial;  ///< each fix's error along the line of sight, m (+: farther from the LiDAR)
  double beyond3sd() const {
    return nis.empty() ? 0.0 : static_cast<double>(std::count_if(nis.begin(), nis.end(), [](double v) { return v > 9.0; })) / nis.size();
  }
  double meanNis() const {
    double s = 0.0;
    for (double v : nis) s += v;
    return nis.empty() ? 0.0 : s / nis.size();
  }
  double median() { return quantile(0.5); }
  double quantile(double q) {
    if (errors.empty()) return -1.0;
    std::sort(errors.begin(), errors.end());
    return errors[std::min(errors.size() - 1, static_cast<std::size_t>(q * errors.size()))];
  }
};

enum class Measured { kNot, kEachFrame, kOverTheFrames };

// A car passing an RSU beside a street at 20-60 m, one frame every metre. Its CAM's box is the body's
// size plus the extras, rounded to the CAM's step; its sides measured by no one, in each frame alone (the
// perception's default), or over the frames as well, as the station does (RsuStation, body_size.hpp).
Outcome drivePast(const LidarSpec& ideal, double height, double pitch_deg, double cam_extra_length = 0.0, double cam_extra_width = 0.0,
                  Measured measured = Measured::kEachFrame) {
  const bool learn = measured == Measured::kOverTheFrames;
  const LidarSpec lidar = withErrors(ideal, ErrorSources{});  // range noise and dropouts as on a real road
  RoadsidePerceptionConfig config;
  config.covariance.azimuth_step = lidar.azimuth_step_deg * M_PI / 180.0;
  config.covariance.range_noise = lidar.range_noise;
  config.body_size.enabled = measured != Measured::kNot;
  if (measured == Measured::kEachFrame) config.body_size.frame_tolerance = 0.25;  // off by default
  RayCaster world;
  world.addMesh(groundRectangle({-90, -40}, {90, 40}));
  world.addMesh(box({0, 16, 0}, {180, 1, 9}));
  const VehicleBody car;
  const int car_mesh = world.addMesh(car.mesh(1e4, 1e4, 0));
  world.commit();
  RsuMount mount;
  mount.position = {0.0, -8.0, height};
  mount.pitch = pitch_deg * M_PI / 180.0;
  const Eigen::Isometry3d pose = Eigen::Translation3d(mount.position) * Eigen::AngleAxisd(mount.pitch, Eigen::Vector3d::UnitY());
  const auto sensor = [&](double) { return pose; };
  RandomEngine rng(21);
  std::vector<Eigen::Vector3f> reference;
  for (const LidarPoint& p : scanSweep(lidar, world, sensor, rng)) reference.push_back(p.position);
  const RoadsidePerception perception(reference, mount, config);
  // The CAM's size: quantized to 0.1 m (ETSI's vehicle length and width), the body a few cm off it.
  const double cam_length = std::round((car.length + cam_extra_length) * 10.0) / 10.0,
               cam_width = std::round((car.width + cam_extra_width) * 10.0) / 10.0;
  BodySizeLearner body;  // as the station keeps it for each vehicle
  Outcome out;
  for (double x = -60.0; x <= 60.0; x += 1.0) {
    const double range = std::hypot(x, 8.0);
    if (range < 20.0) continue;
    const double yaw = 0.02;
    world.updateMesh(car_mesh, car.mesh(x, 0.0, yaw));
    world.commit();
    std::vector<Eigen::Vector3f> frame;
    for (const LidarPoint& p : scanSweep(lidar, world, sensor, rng)) frame.push_back(p.position);
    const Eigen::Vector2d size = learn ? body.size(cam_length, cam_width) : Eigen::Vector2d(cam_length, cam_width);
    VehicleDetection d = perception.detect(frame, 0, {x + 0.2, -0.22}, yaw + 0.03, size.x(), size.y());
    if (learn && d.found) {
      if (size != Eigen::Vector2d(cam_length, cam_width)) d.covariance += sizeCovariance(body.doubt(cam_length, cam_width), d.yaw);
      body.add(d.measured_sides);
    }
    ++out.frames;
    ++out.frames_by_range[std::min<std::size_t>(3, static_cast<std::size_t>((range - 20.0) / 10.0))];
    if (d.found) {
      ++out.found;
      const Eigen::Vector2d e = d.position - Eigen::Vector2d(x, 0.0);
      out.errors.push_back(e.norm());
      out.by_range.emplace_back(range, e.norm());
      out.nis.push_back(e.dot(d.covariance.inverse() * e));
      out.radial.push_back(e.dot((Eigen::Vector2d(x, 0.0) - mount.position.head<2>()).normalized()));
    }
  }
  return out;
}

// The bar for the twin: a fix in at least 80 % of frames, median at most 15 cm, p90 at most 30 cm,
// none over 50 cm sent (that one for every case), and each fix's covariance honest: at most 1 % of all
// fixes beyond 3 sd. The paper's VLP-32C on its 2 m mast gives a fix in every frame. A 64-beam LiDAR
// with even beams gives one in 90-94 % from 2 and 5 m and 83 % from 8 m (held at 85 / 85 / 80 %: from
// 8 m, side faces seen alone and fewer than five returns under the 0.8 m cut are refused; front and rear
// faces seen alone and obliquely up to 0.6 m short are taken, without which 8 m gave 61 of 84); the VLP-32C's
// beams below -8.8 deg are 2-10 deg apart, and from 5 and 8 m most frames give no fix (printed, not
// held).
TEST(HighMount, FixesFromAMastAndFromPolesAreAccurateAndTheirCovarianceHonest) {
  struct Case {
    LidarSpec lidar;
    double height;
    double held;  ///< share of frames with a fix held to; 0: printed only
  };
  int fixes = 0, beyond = 0;
  for (const Case& c : {Case{vlp32c(), 2.0, 0.8}, Case{vlp32c(), 5.0, 0.0}, Case{vlp32c(), 8.0, 0.0}, Case{os1_64(), 2.0, 0.85},
                        Case{os1_64(), 5.0, 0.85}, Case{os1_64(), 8.0, 0.80}}) {
    Outcome o = drivePast(c.lidar, c.height, c.height > 2.0 ? 1.9 : 0.0);
    std::printf("%-8s %.0f m: %2d of %2d frames give a fix, median %.3f m, p90 %.3f m, worst %.3f m; normalized error squared: mean %.2f, "
                "beyond 3 sd %.1f %%\n",
                c.lidar.name.c_str(), c.height, o.found, o.frames, o.median(), o.quantile(0.9), o.quantile(1.0), o.meanNis(), 100.0 * o.beyond3sd());
    // The same by range, beside the real roadside frames' figures (docs/roadside.md).
    std::printf("  by range:");
    for (int bin = 0; bin < 4; ++bin) {
      std::vector<double> e;
      for (const auto& [range, error] : o.by_range)
        if (range >= 20.0 + 10.0 * bin && (range < 30.0 + 10.0 * bin || bin == 3)) e.push_back(error);
      std::sort(e.begin(), e.end());
      std::printf(" %d-%d m %zu of %d, median %.1f cm;", 20 + 10 * bin, 30 + 10 * bin, e.size(), o.frames_by_range[static_cast<std::size_t>(bin)],
                  e.empty() ? std::nan("") : 100.0 * e[e.size() / 2]);
    }
    std::printf("\n");
    fixes += static_cast<int>(o.nis.size());
    beyond += static_cast<int>(std::count_if(o.nis.begin(), o.nis.end(), [](double v) { return v > 9.0; }));
    EXPECT_LE(o.quantile(1.0), 0.5) << c.lidar.name << " " << c.height << " m: a fix over 50 cm was sent";
    if (c.held <= 0.0) continue;
    EXPECT_GE(o.found, c.held * o.frames) << c.lidar.name << " " << c.height << " m";
    EXPECT_LE(o.median(), 0.15) << c.lidar.name << " " << c.height << " m";
    EXPECT_LE(o.quantile(0.9), 0.30) << c.lidar.name << " " << c.height << " m";
  }
  std::printf("all: %d fixes, %d beyond 3 sd of their own covariance\n", fixes, beyond);
  EXPECT_LE(beyond, 0.01 * fixes);
}


// A box larger than the body, as a dataset's label or a CAM counting the mirrors gives: the width with
// the twin's 0.2 m mirrors each side, 0.15 m on the length (2.2 x 5.0 m for a 1.84 x 4.88 m body). Each
// fix from the CAM's size lands about 11 cm farther from the LiDAR, as on the real frames (8-20 cm), and
// most beyond 3 sd of their covariance. Measured in each frame alone (frame_tolerance 0.25, off by
// default), the width is the body's where the front or rear face shows it 0.25 m short; over the
// vehicle's frames (the station's default), once five frames saw that face.
// What is left is the length's excess, which the side face seen at grazing incidence cannot measure. A
// CAM of the body's size keeps it: the fixes are the same to the bit whether measured or not.
TEST(HighMount, ACamBoxLargerThanTheBodyIsMeasuredDownInEachFrameAndOverTheVehiclesFrames) {
  std::map<Measured, std::pair<int, int>> beyond;  // fixes beyond 3 sd, fixes
  for (double height : {2.0, 5.0, 8.0}) {
    const double pitch = height > 2.0 ? 1.9 : 0.0;
    const auto meanRadial = [](const Outcome& o) {
      double s = 0.0;
      for (double r : o.radial) s += r;
      return o.radial.empty() ? 0.0 : s / o.radial.size();
    };
    std::map<Measured, Outcome> o;
    for (Measured m : {Measured::kNot, Measured::kEachFrame, Measured::kOverTheFrames}) {
      o[m] = drivePast(os1_64(), height, pitch, 0.15, 0.4, m);
      std::printf("OS1-64 %.0f m, CAM 0.15 / 0.4 m larger, sides measured %s: %d of %d frames, median %.3f m, p90 %.3f m, worst %.3f m, %.3f m "
                  "farther, beyond 3 sd %.1f %%\n",
                  height, m == Measured::kNot ? "by no one" : m == Measured::kEachFrame ? "in each frame" : "over the frames", o[m].found, o[m].frames,
                  o[m].median(), o[m].quantile(0.9), o[m].quantile(1.0), meanRadial(o[m]), 100.0 * o[m].beyond3sd());
      beyond[m].first += static_cast<int>(std::count_if(o[m].nis.begin(), o[m].nis.end(), [](double v) { return v > 9.0; }));
      beyond[m].second += static_cast<int>(o[m].nis.size());
    }
    Outcome& cam = o[Measured::kNot];
    EXPECT_GE(meanRadial(cam), 0.08) << height << " m: the harness shows the real frames' offset";
    for (Measured m : {Measured::kEachFrame, Measured::kOverTheFrames}) {
      EXPECT_LE(meanRadial(o[m]), 0.085) << height << " m";
      EXPECT_LE(o[m].median(), 0.11) << height << " m";
      EXPECT_LT(o[m].median(), 0.6 * cam.median()) << height << " m";
      EXPECT_GE(o[m].found, cam.found) << height << " m";
      EXPECT_LE(o[m].quantile(1.0), 0.5) << height << " m";
    }
    // The CAM of the body's size, rounded: nothing measured shorter.
    const Outcome exact = drivePast(os1_64(), height, pitch, 0.0, 0.0, Measured::kNot);
    EXPECT_EQ(exact.errors, drivePast(os1_64(), height, pitch, 0.0, 0.0, Measured::kOverTheFrames).errors) << height << " m";
  }
  EXPECT_GE(beyond[Measured::kNot].first, 0.5 * beyond[Measured::kNot].second);
  // Beyond 3 sd are the frames whose front or rear face did not measure the width (too few returns on it),
  // and, over the frames, those before five did.
  EXPECT_LE(beyond[Measured::kEachFrame].first, 0.15 * beyond[Measured::kEachFrame].second) << "fixes beyond 3 sd of their covariance";
  EXPECT_LE(beyond[Measured::kOverTheFrames].first, 0.10 * beyond[Measured::kOverTheFrames].second) << "fixes beyond 3 sd of their covariance";
}

}  // namespace
}  // namespace coloc::roadside
