// An RSU station over time: commissioned on the frames of a busy street, then a fix for each connected
// vehicle its CAMs point to, each on its own track.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "coloc/core/error.hpp"
#include "coloc/roadside/rsu_station.hpp"
#include "coloc/sim/lidar_model.hpp"
#include "coloc/sim/mesh.hpp"
#include "coloc/sim/ray_caster.hpp"
#include "coloc/sim/vehicle_body.hpp"

namespace coloc::roadside {
namespace {

using namespace coloc::sim;  // the twin makes the frames

// Two connected cars and an unconnected one on a street, an RSU's 64-beam LiDAR 8 m up on a pole,
// pitched 1.9 deg down.
class Station : public ::testing::Test {
 protected:
  Station() {
    world_.addMesh(groundRectangle({-90, -40}, {90, 40}));
    world_.addMesh(box({0, 16, 0}, {180, 1, 9}));
    for (int i = 0; i < 3; ++i) cars_.push_back(world_.addMesh(car_.mesh(1e4 + 10 * i, 1e4, 0)));
    world_.commit();
    mount_.position = {0.0, -8.0, 8.0};
    mount_.pitch = 1.9 * M_PI / 180.0;
  }
  std::vector<Eigen::Vector3f> frame() {
    const Eigen::Isometry3d pose = Eigen::Translation3d(mount_.position) * Eigen::AngleAxisd(mount_.pitch, Eigen::Vector3d::UnitY());
    std::vector<Eigen::Vector3f> f;
    for (const LidarPoint& p : scanSweep(os1_64(), world_, [&](double) { return pose; }, rng_)) f.push_back(p.position);
    return f;
  }
  // Car i at time t: x along the road at `speed` from `start`, in lane y.
  struct Car {
    double start, speed, y, yaw;
  };
  Eigen::Vector2d at(const Car& c, double t) const { return {c.start + c.speed * t * std::cos(c.yaw), c.y}; }
  void place(const std::vector<Car>& cars, double t) {
    for (std::size_t i = 0; i < cars.size(); ++i) world_.updateMesh(cars_[i], car_.mesh(at(cars[i], t).x(), cars[i].y, cars[i].yaw));
    world_.commit();
  }
  // Its CAM, generated at `t` on the cars' clock, stamped `t + clock` on the station's.
  ConnectedVehicle cam(std::uint32_t id, const Car& c, double t, double clock = 0.0) const {
    ConnectedVehicle v;
    v.stamp = fromSeconds(t + clock);
    v.station_id = id;
    v.centre = at(c, t) + Eigen::Vector2d(0.2, -0.25);  // the vehicle's own error, about 0.3 m
    v.heading = c.yaw;
    v.speed = c.speed;
    v.length = std::round(car_.length * 10.0) / 10.0;  // a CAM's 0.1 m steps
    v.width = std::round(car_.width * 10.0) / 10.0;
    return v;
  }
  // Commissions `station` on `frames` frames of the street with every car far down the road.
  void commissionOnAnEmptyStreet(RsuStation& station, int frames) {
    place({{-80, 0, 30, 0}, {-90, 0, 30, 0}, {-100, 0, 30, 0}}, 0.0);
    for (int k = 0; k < frames; ++k) station.frame(frame(), fromSeconds(0.1 * k));
  }
  RayCaster world_;
  VehicleBody car_;
  std::vector<int> cars_;
  RsuMount mount_;
  RandomEngine rng_{8};
};

TEST_F(Station, CommissionedOnABusyStreetItFixesEachConnectedVehicleOnItsOwnTrack) {
  RsuStationConfig config;
  config.commissioning_frames = 40;
  RsuStation station(mount_, config);
  // Commissioning: 40 frames of traffic, never an empty street.
  const std::vector<Car> traffic = {{-70, 10, 0, 0}, {70, 9, 3.5, M_PI}, {-40, 12, 0, 0}};
  for (int k = 0; k < 40; ++k) {
    place(traffic, 0.1 * k);
    EXPECT_TRUE(station.frame(frame(), fromSeconds(0.1 * k)).empty());
  }
  ASSERT_TRUE(station.commissioned());
  ASSERT_TRUE(station.roadPlane());
  // Then two connected cars, one each way, and an unconnected one behind the first.
  const std::vector<Car> cars = {{-55, 9, 0, 0}, {50, 9, 3.5, M_PI}, {-62, 9, 0, 0}};
  std::map<std::uint32_t, int> fixes;
  std::map<std::uint32_t, double> worst;
  int looked_for = 0;
  for (int k = 0; k < 60; ++k) {
    const double t = 10.0 + 0.1 * k;
    place(cars, t - 10.0);
    station.addVehicle(cam(1001, cars[0], t - 10.0 - 0.05, 10.0));  // 50 ms before the frame
    station.addVehicle(cam(1002, cars[1], t - 10.0 - 0.05, 10.0));
    for (const StationOutcome& o : station.frame(frame(), fromSeconds(t))) {
      ++looked_for;
      if (!o.detection.found) continue;
      const Car& c = o.station_id == 1001 ? cars[0] : cars[1];
      ++fixes[o.station_id];
      worst[o.station_id] = std::max(worst[o.station_id], (o.detection.position - at(c, t - 10.0)).norm());
    }
  }
  std::printf("%d looks: station 1001 %d fixes (worst %.3f m), station 1002 %d fixes (worst %.3f m)\n", looked_for, fixes[1001], worst[1001],
              fixes[1002], worst[1002]);
  EXPECT_GE(fixes[1001], 20);
  EXPECT_GE(fixes[1002], 20);
  EXPECT_LT(worst[1001], 0.3);
  EXPECT_LT(worst[1002], 0.3);
  EXPECT_EQ(station.counters().fixes, static_cast<std::uint64_t>(fixes[1001] + fixes[1002]));
}

// Two connected cars close behind each other (1 m apart), as in a queue coming towards the RSU: the
// front car's CAM has the other car's body within its attribution radius, and it is found; the car
// behind shows the pole only part of one face (its front hidden by the first car) and is refused rather
// than sent wrong.
TEST_F(Station, InAQueueTheFrontCarIsFoundAndTheHalfHiddenOneRefusedNotSentWrong) {
  RsuStationConfig config;
  config.commissioning_frames = 20;
  RsuStation station(mount_, config);
  commissionOnAnEmptyStreet(station, 20);
  ASSERT_TRUE(station.commissioned());
  const double gap = 1.0;
  const std::vector<Car> queue = {{-30, 6, 0, 0}, {-30 - car_.length - gap, 6, 0, 0}, {-100, 0, 30, 0}};
  std::map<std::uint32_t, int> fixes, refused;
  std::map<std::uint32_t, double> worst;
  for (int k = 0; k < 20; ++k) {
    const double t = 0.1 * k;
    place(queue, t);
    station.addVehicle(cam(1001, queue[0], t, 2.0));
    station.addVehicle(cam(1002, queue[1], t, 2.0));
    for (const StationOutcome& o : station.frame(frame(), fromSeconds(t + 2.0))) {
      if (!o.detection.found) {
        ++refused[o.station_id];
        continue;
      }
      ++fixes[o.station_id];
      worst[o.station_id] = std::max(worst[o.station_id], (o.detection.position - at(queue[o.station_id == 1001 ? 0 : 1], t)).norm());
    }
  }
  std::printf("queue 1 m apart: 1001 %d fixes (worst %.3f m), %d refused; 1002 %d fixes (worst %.3f m), %d refused\n", fixes[1001], worst[1001],
              refused[1001], fixes[1002], worst[1002], refused[1002]);
  EXPECT_GE(fixes[1001], 12);
  EXPECT_LT(worst[1001], 0.3);
  EXPECT_LT(worst[1002], 0.3) << "a fix of the half-hidden car was sent wrong";
}

// A log played again into the node, or a driver restarted: the frames' and the CAMs' stamps go back.
// The station starts its vehicles afresh and finds them on the second pass as on the first.
TEST_F(Station, TimeGoingBackStartsTheVehiclesAfreshAndTheSecondPassIsFixedAsTheFirst) {
  RsuStationConfig config;
  config.commissioning_frames = 10;
  RsuStation station(mount_, config);
  commissionOnAnEmptyStreet(station, 10);
  const std::vector<Car> cars = {{-40, 6, 0, 0}, {-100, 0, 30, 0}, {-110, 0, 30, 0}};
  int fixes[2] = {0, 0};
  for (int pass = 0; pass < 2; ++pass)
    for (int k = 0; k < 15; ++k) {
      const double t = 0.1 * k;
      place(cars, t);
      station.addVehicle(cam(1001, cars[0], t, 5.0));
      for (const StationOutcome& o : station.frame(frame(), fromSeconds(t + 5.0))) fixes[pass] += o.detection.found ? 1 : 0;
    }
  std::printf("first pass %d fixes, second %d; %llu clock resets\n", fixes[0], fixes[1], (unsigned long long)station.counters().clock_resets);
  EXPECT_GE(fixes[0], 10);
  EXPECT_GE(fixes[1], fixes[0] - 1);
  EXPECT_EQ(station.counters().clock_resets, 1u);
}

// A pole's LiDAR pitched 1.9 deg down whose tilt the registry does not know: levelled from the road it
// sees while commissioning, its fixes are as good as with the tilt known; unlevelled, 0.1-0.3 m off.
TEST_F(Station, AnUnknownTiltIsTakenFromTheRoadWhileCommissioning) {
  const auto passWith = [&](bool level) {
    RsuMount told = mount_;
    told.pitch = 0.0;  // the registry's word: level
    RsuStationConfig config;
    config.commissioning_frames = 10;
    config.level_from_ground = level;
    RsuStation station(told, config);
    commissionOnAnEmptyStreet(station, 10);
    const std::vector<Car> cars = {{-45, 6, 0, 0}, {-100, 0, 30, 0}, {-110, 0, 30, 0}};
    std::vector<double> errors;
    for (int k = 0; k < 25; ++k) {
      const double t = 0.1 * k;
      place(cars, t);
      station.addVehicle(cam(1001, cars[0], t, 5.0));
      for (const StationOutcome& o : station.frame(frame(), fromSeconds(t + 5.0)))
        if (o.detection.found) errors.push_back((o.detection.position - at(cars[0], t)).norm());
    }
    std::sort(errors.begin(), errors.end());
    if (level) {
      EXPECT_TRUE(station.levelling());
      EXPECT_NEAR(station.mount().pitch, mount_.pitch, 0.2 * M_PI / 180.0);
      EXPECT_NEAR(station.levelling()->height, mount_.position.z(), 0.15);
    }
    return errors;
  };
  const std::vector<double> levelled = passWith(true), unlevelled = passWith(false);
  ASSERT_GE(levelled.size(), 10u);
  const double median = levelled[levelled.size() / 2];
  const double median_unlevelled = unlevelled.empty() ? 1e9 : unlevelled[unlevelled.size() / 2];
  std::printf("tilt unknown: levelled from the road %zu fixes, median %.3f m; unlevelled %zu fixes, median %.3f m\n", levelled.size(), median,
              unlevelled.size(), median_unlevelled);
  EXPECT_LT(median, 0.08);
  EXPECT_GT(median_unlevelled, 2.0 * median);
}

// After commissioning the station keeps learning, one frame in learn_every: a car that parks becomes
// background once it has been in enough of the frames learned (here nothing forgotten, and the
// background rebuilt every frame), so that its CAM then finds no vehicle where it stands, or only part
// of one. Learning one frame in four, that takes four times as many frames.
TEST_F(Station, ACarParkedSinceCommissioningBecomesBackgroundAfterAsManyLearnedFrames) {
  const auto framesUntilLost = [&](int learn_every) {
    RsuStationConfig config;
    config.commissioning_frames = 20;
    config.refresh_frames = 1;
    config.learn_every = learn_every;
    config.background.decay = 0.0;
    RsuStation station(mount_, config);
    commissionOnAnEmptyStreet(station, 20);
    const std::vector<Car> parked = {{25, 0, 0, 0}, {-100, 0, 30, 0}, {-110, 0, 30, 0}};
    place(parked, 0.0);
    bool fixed = false;  // the first frame has no track to agree with: lost once it had a fix
    for (int k = 1; k <= 80; ++k) {
      station.addVehicle(cam(1001, parked[0], 0.1 * k, 5.0));
      const std::vector<StationOutcome> o = station.frame(frame(), fromSeconds(0.1 * k + 5.0));
      const bool found = o.size() == 1u && o[0].detection.found;
      if (fixed && !found) return k;
      fixed = fixed || found;
    }
    return 1000;
  };
  const int every_frame = framesUntilLost(1), every_fourth = framesUntilLost(4);
  std::printf("a parked car becomes background after %d frames learning each, %d learning one in four\n", every_frame, every_fourth);
  // A voxel the car returns from in every frame is background once it holds min_occupancy of the
  // learned frames: 5 after the 20 commissioning ones (5 / 25). The car is lost once enough of its
  // voxels are, which over ten seeds of the LiDAR's noise took 9-13 learned frames in either pass (the
  // two passes draw different noise, so one is not a multiple of the other to the frame).
  EXPECT_GE(every_frame, 5) << "not in the background before it has been in a few frames";
  EXPECT_LE(every_frame, 15);
  EXPECT_GE(every_fourth, 4 * 5) << "learning one frame in four, as many learned frames take four times as long";
  EXPECT_LE(every_fourth, 4 * 15);
}

// A survey's frame of the empty street instead of commissioning frames: fixes from the first frames,
// the second once the track has a first to agree with.
TEST_F(Station, CommissionedFromASurveyedEmptyFrameItFixesFromTheFirstFrames) {
  RsuStation station(mount_);
  place({{-80, 0, 30, 0}, {-90, 0, 30, 0}, {-100, 0, 30, 0}}, 0.0);
  EXPECT_FALSE(station.commission(std::vector<Eigen::Vector3f>(3, Eigen::Vector3f::Constant(std::nanf(""))))) << "no finite point";
  EXPECT_FALSE(station.commissioned());
  ASSERT_TRUE(station.commission(frame()));
  ASSERT_NE(station.perception(), nullptr);
  const std::vector<Car> cars = {{-40, 6, 0, 0}, {-100, 0, 30, 0}, {-110, 0, 30, 0}};
  place(cars, 0.0);
  for (int k = 0; k < 4; ++k) {
    const double t = 0.1 * k;
    place(cars, t);
    station.addVehicle(cam(1001, cars[0], t));
    const std::vector<StationOutcome> o = station.frame(frame(), fromSeconds(t));
    ASSERT_EQ(o.size(), 1u);
    if (k == 0) {  // no track yet to agree with
      EXPECT_EQ(o[0].detection.refusal, Refusal::kInconsistent);
      continue;
    }
    ASSERT_TRUE(o[0].detection.found) << "frame " << k << ": " << toString(o[0].detection.refusal);
    EXPECT_LT((o[0].detection.position - at(cars[0], t)).norm(), 0.15);
  }
  EXPECT_EQ(station.counters().commissioning_frames, 1u);
}

// A connected car whose CAM's box is 0.4 m wider and 0.1 m longer than its body (mirrors counted, as a
// dataset's label would): placed with the CAM's size, every fix lies about 0.2 m across the lane from the
// body's centre. Each frame that sees the car's front whole measures the width from it; the station keeps
// the measures and, from five, places the box with them in the frames that do not; the same car, its CAM
// sent again with another size, is measured afresh.
TEST_F(Station, AVehicleWhoseCamOverstatesItsWidthIsPlacedWithTheWidthItsFramesMeasure) {
  // Each pass's fixes apart: those placed with the CAM's size and those placed with a side the frames
  // measured (the station's counter moving in that frame). One median over both would sit between
  // the two groups, as many fixes of this drive come before the station has its measures.
  struct Pass {
    std::vector<double> with_cam;       ///< each fix's distance across the lane from the body's centre, m
    std::vector<double> with_measured;  ///< the same, for the fixes placed with a measured side
    int measured_from = -1;             ///< the first frame placed with a measured side
    double after_new_size = -1;         ///< across, the first fix after the CAM sent another size
  };
  const auto pass = [&](bool measure, bool each_frame) {
    RsuStationConfig config;
    config.perception.body_size.enabled = measure;
    if (!each_frame) config.perception.body_size.frame_tolerance = 0.0;  // the station's measures alone
    config.commissioning_frames = 20;
    RsuStation station(mount_, config);
    commissionOnAnEmptyStreet(station, 20);
    const Car car{-62, 8, 0, 0};  // seen from 62 to 19 m, nearer under the pole's lowest beam
    Pass out;
    for (int k = 0; k < 56; ++k) {
      const double t = 0.1 * k;
      place({car, {-90, 0, 30, 0}, {-100, 0, 30, 0}}, t);
      ConnectedVehicle v = cam(1001, car, t - 0.05, 10.0);
      v.width = std::round((car_.width + (k < 50 ? 0.4 : 0.5)) * 10.0) / 10.0;  // from frame 50 another size
      v.length = std::round((car_.length + 0.1) * 10.0) / 10.0;
      station.addVehicle(v);
      const std::uint64_t counted_before = station.counters().fixes_with_measured_size;
      for (const StationOutcome& o : station.frame(frame(), fromSeconds(10.0 + t))) {
        if (!o.detection.found) continue;
        const double across = std::abs(o.detection.position.y() - car.y);
        if (k >= 50) {
          if (out.after_new_size < 0.0) out.after_new_size = across;
          continue;
        }
        const bool with_measured = station.counters().fixes_with_measured_size > counted_before;
        (with_measured ? out.with_measured : out.with_cam).push_back(across);
        if (with_measured && out.measured_from < 0) out.measured_from = k;
      }
    }
    for (std::vector<double>* v : {&out.with_cam, &out.with_measured}) std::sort(v->begin(), v->end());
    return out;
  };
  const auto median = [](const std::vector<double>& v) { return v.empty() ? -1.0 : v[v.size() / 2]; };
  const Pass cam_size = pass(false, false), learned = pass(true, false), measured = pass(true, true);
  for (const auto& [name, p] : {std::pair{"the CAM's width", &cam_size}, {"measured over the frames", &learned}, {"measured in each frame", &measured}})
    std::printf("%s: %zu fixes with the CAM's size (median across the lane %.3f m), %zu with a measured side (median %.3f m, from frame %d); "
                "the first fix after another size %.3f m\n",
                name, p->with_cam.size(), median(p->with_cam), p->with_measured.size(), median(p->with_measured), p->measured_from,
                p->after_new_size);
  ASSERT_GE(cam_size.with_cam.size(), 20u);
  EXPECT_TRUE(cam_size.with_measured.empty());
  EXPECT_GT(median(cam_size.with_cam), 0.12) << "the CAM's 0.36 m excess shows across the lane";
  // Over ten seeds of the LiDAR's noise: 19-27 fixes placed with a measured side, their median 0.5-1.8 cm
  // across the lane (the CAM's size puts it 18 cm off).
  for (const Pass* p : {&learned, &measured}) {
    EXPECT_GE(p->with_measured.size(), 15u) << "the fixes placed with the width measured are counted";
    EXPECT_LT(median(p->with_measured), 0.03);
    ASSERT_GE(p->after_new_size, 0.0) << "no fix after the CAM's new size";
  }
  // Each frame's own measure places the box from the first frame that sees the front whole; the
  // station's, once it has min_measures of them.
  EXPECT_LT(measured.measured_from, learned.measured_from);
  // Another size in the CAM: the station's measures start afresh, its first fix placed with the new
  // CAM's; the frame's own measure still places it.
  EXPECT_GT(learned.after_new_size, 0.15);
  EXPECT_LT(measured.after_new_size, 0.08);
}

TEST_F(Station, AConfigurationOutOfRangeIsRefusedNamingTheKeys) {
  for (const auto& [key, change] : std::vector<std::pair<std::string, void (*)(RsuStationConfig&)>>{
           {"learn_every", [](RsuStationConfig& c) { c.learn_every = 0; }},
           {"refresh_frames", [](RsuStationConfig& c) { c.refresh_frames = -1; }},
           {"commissioning_frames", [](RsuStationConfig& c) { c.commissioning_frames = 0; }},
           {"min_measures", [](RsuStationConfig& c) { c.perception.body_size.min_measures = 0; }},
           {"coverage", [](RsuStationConfig& c) { c.coverage = std::nan(""); }}}) {
    RsuStationConfig config;
    change(config);
    try {
      RsuStation station(mount_, config);
      ADD_FAILURE() << key << " out of range was taken";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
}

TEST_F(Station, AStaleOrMalformedCamIsNotLookedFor) {
  RsuStationConfig config;
  config.commissioning_frames = 2;
  RsuStation station(mount_, config);
  station.frame(frame(), 0);
  station.frame(frame(), fromSeconds(0.1));
  const Car c{20, 8, 0, 0};
  ConnectedVehicle old = cam(7, c, 0.0);
  EXPECT_TRUE(station.addVehicle(old));
  EXPECT_TRUE(station.frame(frame(), fromSeconds(1.5)).empty()) << "1.5 s after its CAM";
  ConnectedVehicle nan = cam(8, c, 1.5);
  nan.speed = std::nan("");
  EXPECT_FALSE(station.addVehicle(nan));
  ConnectedVehicle earlier = cam(7, c, -1.0);
  EXPECT_FALSE(station.addVehicle(earlier)) << "older than the vehicle's last CAM";
  EXPECT_EQ(station.counters().cams_refused, 2u);
  // Ten seconds on, a vehicle that sent nothing since is forgotten (hours of traffic take no memory).
  EXPECT_EQ(station.vehiclesKnown(), 1u);
  station.frame(frame(), fromSeconds(10.5));
  EXPECT_EQ(station.vehiclesKnown(), 0u);
}

}  // namespace
}  // namespace coloc::roadside
