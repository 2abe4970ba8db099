// The roadside perception from the heights real RSUs stand at: the paper's 2 m mast and intersection
// poles of 5-9 m, cars 20-60 m away, the CAM 0.3 m off with its size quantized to 0.1 m.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <memory>

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
  int overhanging = 0;  ///< frames refused because returns reach out beyond the one face seen
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

// A street with a wall behind it, a car, and a LiDAR on a pole 8 m beside the lane at `height`, pitched
// down by `pitch_deg`; the perception commissioned on the empty street.
struct PoleStreet {
  LidarSpec lidar;
  RayCaster world;
  VehicleBody car;
  int car_mesh = -1;
  RsuMount mount;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  std::unique_ptr<RoadsidePerception> perception;

  PoleStreet(const LidarSpec& ideal, double height, double pitch_deg, RandomEngine& rng, bool measure_sides = true)
      : lidar(withErrors(ideal, ErrorSources{})) {  // range noise and dropouts as on a real road
    RoadsidePerceptionConfig config;
    config.covariance.azimuth_step = lidar.azimuth_step_deg * M_PI / 180.0;
    config.covariance.range_noise = lidar.range_noise;
    config.body_size.enabled = measure_sides;
    world.addMesh(groundRectangle({-90, -40}, {90, 40}));
    world.addMesh(box({0, 16, 0}, {180, 1, 9}));
    car_mesh = world.addMesh(car.mesh(1e4, 1e4, 0));
    world.commit();
    mount.position = {0.0, -8.0, height};
    mount.pitch = pitch_deg * M_PI / 180.0;
    pose = Eigen::Translation3d(mount.position) * Eigen::AngleAxisd(mount.pitch, Eigen::Vector3d::UnitY());
    perception = std::make_unique<RoadsidePerception>(frame(rng), mount, config);
  }
  /// The car at (x, 0) heading `yaw`, and the frame the LiDAR takes of it.
  std::vector<Eigen::Vector3f> frameWithCarAt(double x, double yaw, RandomEngine& rng) {
    world.updateMesh(car_mesh, car.mesh(x, 0.0, yaw));
    world.commit();
    return frame(rng);
  }
  std::vector<Eigen::Vector3f> frame(RandomEngine& rng) const {
    std::vector<Eigen::Vector3f> out;
    for (const LidarPoint& p : scanSweep(lidar, world, [&](double) { return pose; }, rng)) out.push_back(p.position);
    return out;
  }
};

// A car passing an RSU beside a street at 20-60 m, one frame every metre. Its CAM's box is the body's
// size plus the extras, rounded to the CAM's step; its sides measured by no one, in each frame alone (the
// perception's default), or over the frames as well, as the station does (RsuStation, body_size.hpp).
Outcome drivePast(const LidarSpec& ideal, double height, double pitch_deg, double cam_extra_length = 0.0, double cam_extra_width = 0.0,
                  Measured measured = Measured::kEachFrame, std::uint64_t seed = 21) {
  const bool learn = measured == Measured::kOverTheFrames;
  RandomEngine rng(seed);
  PoleStreet street(ideal, height, pitch_deg, rng, measured != Measured::kNot);
  const VehicleBody& car = street.car;
  const RsuMount& mount = street.mount;
  // The CAM's size: quantized to 0.1 m (ETSI's vehicle length and width), the body a few cm off it.
  const double cam_length = std::round((car.length + cam_extra_length) * 10.0) / 10.0,
               cam_width = std::round((car.width + cam_extra_width) * 10.0) / 10.0;
  BodySizeLearner body;  // as the station keeps it for each vehicle
  Outcome out;
  for (double x = -60.0; x <= 60.0; x += 1.0) {
    const double range = std::hypot(x, 8.0);
    if (range < 20.0) continue;
    const double yaw = 0.02;
    const std::vector<Eigen::Vector3f> frame = street.frameWithCarAt(x, yaw, rng);
    const Eigen::Vector2d size = learn ? body.size(cam_length, cam_width) : Eigen::Vector2d(cam_length, cam_width);
    VehicleDetection d = street.perception->detect(frame, 0, {x + 0.2, -0.22}, yaw + 0.03, size.x(), size.y());
    if (learn && d.found) {
      if (size != Eigen::Vector2d(cam_length, cam_width)) d.covariance += sizeCovariance(body.doubt(cam_length, cam_width), d.yaw);
      body.add(d.measured_sides);
    }
    ++out.frames;
    out.overhanging += !d.found && d.face_overhang > street.perception->config().max_face_overhang ? 1 : 0;
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


// A label's box as the CAM's (0.4 m wider and 0.15 m longer than the body), each frame alone, as the
// held-back real frames are measured: a car coming or going at 40-60 m shows a pole its front or rear
// alone, short of the label's width by the excess and by up to a column's spacing at each end (0.6-0.9 m).
// Taken when its placement errs by at most 0.5 m across, 66-73 % of the frames gave a fix before and
// 75-82 % now over 13 drives; here six, from 2, 5 and 8 m.
TEST(HighMount, LabelSizedCamsFindCarsSeenOnTheirFrontOrRearAloneFromAfar) {
  for (double height : {2.0, 5.0, 8.0}) {
    Outcome all;
    for (std::uint64_t seed : {1, 2, 3, 4, 5, 6}) {
      Outcome o = drivePast(os1_64(), height, height > 2.0 ? 1.9 : 0.0, 0.15, 0.4, Measured::kEachFrame, seed);
      all.frames += o.frames;
      all.found += o.found;
      all.errors.insert(all.errors.end(), o.errors.begin(), o.errors.end());
    }
    std::printf("OS1-64 %.0f m, label-sized CAM, six drives: %d of %d frames give a fix, median %.3f m, p90 %.3f m, worst %.3f m\n", height,
                all.found, all.frames, all.median(), all.quantile(0.9), all.quantile(1.0));
    EXPECT_GE(all.found, 0.72 * all.frames) << height << " m";
    EXPECT_LE(all.median(), 0.12) << height << " m";
    EXPECT_LE(all.quantile(1.0), 0.45) << height << " m: a fix over 45 cm was sent";
  }
}

// From the 2 m mast a car going away at 55-60 m shows the 64-beam LiDAR's one ring under its rear bumper
// only below the cut: it returns from the underbody 0.9-1.0 m inside the body, a face as wide as the car,
// while the rings above, cut away, return from the bumper and the boot nearer the LiDAR. Resting the box
// on that face put fixes a metre off along the car (3 of 13 drives); the returns reaching out beyond it
// refuse it.
TEST(HighMount, AFaceSeenUnderTheBumperIsNotTakenForTheBodysEnd) {
  int overhanging = 0;
  double worst = 0.0;
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    Outcome o = drivePast(os1_64(), 2.0, 0.0, 0.0, 0.0, Measured::kEachFrame, seed);
    overhanging += o.overhanging;
    worst = std::max(worst, o.quantile(1.0));
  }
  std::printf("OS1-64 2 m, twelve drives: %d frames refused for returns beyond the one face seen, worst fix %.3f m\n", overhanging, worst);
  EXPECT_GE(overhanging, 3);
  EXPECT_LE(worst, 0.45);
}

// A box larger than the body, as a dataset's label or a CAM counting the mirrors gives: the width with
// the twin's 0.2 m mirrors each side, 0.15 m on the length (2.2 x 5.0 m for a 1.84 x 4.88 m body). Each
// fix from the CAM's size lands about 11 cm farther from the LiDAR, as on the real frames (8-20 cm), and
// most beyond 3 sd of their covariance. Measured in each frame alone (the perception's default), the
// width is the body's where the front or rear face shows it 0.25 m short; over the vehicle's frames (the
// station's), once five frames saw that face, and in each frame until then.
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

// One frame places the box with its own measure of a side only where it shows that side whole. The car
// coming towards an 8 m pole with its CAM 0.4 m wider than the body: frames that see its front whole
// place it with the width measured. The same frames with the front's far part missing (the sweep's
// seam there, or the frame's end), or with the body seen by one ring only (returns 0.3-0.55 m up: a
// slice at one height, which at a bumper's lip is shorter than the body), keep the CAM's width.
TEST(HighMount, OneFramePlacesTheBoxWithItsOwnMeasureOnlyWhereItShowsTheSideWhole) {
  RandomEngine rng(5);
  PoleStreet street(os1_64(), 8.0, 1.9, rng);
  const VehicleBody& car = street.car;
  const RsuMount& mount = street.mount;
  const BodySizeConfig config;
  const double cam_length = std::round((car.length + 0.1) * 10.0) / 10.0, cam_width = std::round((car.width + 0.4) * 10.0) / 10.0;
  const auto inMap = [&](const Eigen::Vector3f& p) { return street.pose * p.cast<double>(); };
  int whole = 0;
  struct Tally {
    int found = 0, kept = 0, short_enough = 0;  ///< fixes; of them placed with the CAM's width; measured short enough to be placed
  } cut, ring;
  // A measure the frame would place the box with, were the side not to be shown whole.
  const auto wouldPlace = [&](const VehicleDetection& d) {
    const double short_by = cam_width - d.measured_sides.y();
    return d.measured_sides.y() > 0.0 && short_by > config.frame_tolerance && short_by <= config.max_shortfall;
  };
  // A frame that does not show the front whole: its fix, if any, keeps the CAM's width.
  const auto keepsTheCamsWidth = [&](Tally& t, const VehicleDetection& d, double x, const char* why) {
    if (!d.found) return;
    ++t.found;
    t.kept += d.placed_size.y() == cam_width ? 1 : 0;
    t.short_enough += wouldPlace(d) ? 1 : 0;
    EXPECT_EQ(d.placed_size.y(), cam_width) << "x " << x << ": " << why << ", measured " << d.measured_sides.y();
  };
  std::vector<double> across;  // each fix placed with the width measured: its distance across the lane from the body's centre, m
  for (double x = -45.0; x <= -20.0; x += 1.0) {
    const double yaw = 0.0;
    const std::vector<Eigen::Vector3f> frame = street.frameWithCarAt(x, yaw, rng);
    const auto detect = [&](const std::vector<Eigen::Vector3f>& f) { return street.perception->detect(f, 0, {x + 0.2, -0.22}, yaw + 0.03, cam_length, cam_width); };
    const VehicleDetection d = detect(frame);
    if (!d.found || !(d.placed_size.y() < cam_width - 0.25)) continue;
    ++whole;
    // One frame's measure of the front: within 0.2 m of the body's width (the station's quantile over
    // the frames does better).
    EXPECT_NEAR(d.placed_size.y(), car.width, 0.25) << "x " << x;
    across.push_back(std::abs(d.position.y()));
    // Returns that are not numbers (a driver's dropouts) change nothing, the end's test included.
    std::vector<Eigen::Vector3f> with_nan = frame;
    with_nan.insert(with_nan.end(), {Eigen::Vector3f::Constant(std::nanf("")), Eigen::Vector3f::Constant(std::numeric_limits<float>::infinity())});
    const VehicleDetection n = detect(with_nan);
    EXPECT_TRUE(n.found && n.position == d.position && n.placed_size == d.placed_size) << "x " << x;
    // The frame ends 0.25 m short of the front's far corner: nothing beyond, in bearing, is in it.
    const Eigen::Vector2d cut_at = Eigen::Vector2d(x + 0.5 * car.length, 0.5 * car.width - 0.25) - mount.position.head<2>();
    std::vector<Eigen::Vector3f> cut_frame;
    for (const Eigen::Vector3f& p : frame) {
      const Eigen::Vector2d d2 = inMap(p).head<2>() - mount.position.head<2>();
      if (cut_at.x() * d2.y() - cut_at.y() * d2.x() >= 0.0) cut_frame.push_back(p);  // the seen corner's side of the cut
    }
    keepsTheCamsWidth(cut, detect(cut_frame), x, "the front's end not seen");
    // The body by one ring: its returns between 0.3 and 0.55 m up only.
    std::vector<Eigen::Vector3f> ring_frame;
    for (const Eigen::Vector3f& p : frame) {
      const Eigen::Vector3d q = inMap(p);
      const bool on_car = std::abs(q.x() - x) < 2.6 && std::abs(q.y()) < 1.2 && q.z() > 0.05;
      if (!on_car || (q.z() > 0.3 && q.z() < 0.55)) ring_frame.push_back(p);
    }
    keepsTheCamsWidth(ring, detect(ring_frame), x, "one ring");
  }
  std::sort(across.begin(), across.end());
  std::printf("frames placed with the width measured: %d (median %.3f m across the lane); with the front's end cut off, %d of %d found keep the CAM's width (%d measured "
              "it short enough to be placed); seen by one ring, %d of %d (%d)\n",
              whole, across.empty() ? std::nan("") : across[across.size() / 2], cut.kept, cut.found, cut.short_enough, ring.kept, ring.found,
              ring.short_enough);
  EXPECT_GE(whole, 10);
  if (!across.empty()) {
    EXPECT_LT(across[across.size() / 2], 0.06) << "median across the lane; with the CAM's width it is 0.18 m";
  }
  // The checks are what keeps those: the frames measured the width short enough to be placed with it.
  EXPECT_GE(cut.short_enough, 5);
  EXPECT_GE(ring.short_enough, 3);
}

}  // namespace
}  // namespace coloc::roadside
