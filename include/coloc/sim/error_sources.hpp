#pragma once
// What goes wrong on a real road and the ideal twin leaves out: the RSU's surveyed pose and clock, the
// shape of a real car, and a LiDAR whose noise grows with range and which loses returns. The defaults
// are the realistic case, each from a published figure (README, "Error sources"); a scenario's
// `errors:` section overrides any of them, and `ideal()` is the twin without them.
#include <cstdint>

namespace coloc::sim {

struct ErrorSources {
  /// RSU survey: the surveyed pose minus the true pose, drawn once per RSU from the scenario's seed
  /// (one installation, one survey: the same on every drive) unless the RSU states its own.
  double survey_position_sd = 0.02;  ///< m per horizontal axis: RTK GNSS, 8-10 mm + 1 ppm, plus centring on the mast
  double survey_yaw_sd = 0.1 * 3.14159265358979323846 / 180.0;  ///< rad: target-based LiDAR pose, 0.1-0.2 deg
  /// The RSU's clock minus the vehicle's, drawn once per RSU (NTP over the Internet: a few ms), and
  /// each frame's stamp error on top of it (a PPS-locked Velodyne stamps within 50 us).
  double clock_offset_sd = 0.002;   ///< s
  double clock_jitter_sd = 50e-6;   ///< s
  /// The car the roadside LiDARs see: rounded corners, bumpers, wheels in their arches, 0.15 m ground
  /// clearance, a mid-size sedan's size (VehicleBody's defaults); false: the ideal twin's boxes.
  bool detailed_vehicle = true;
  /// Range noise (standard deviation) sd0 + k r: 2 cm repeatability near (VLP-16 against a TLS),
  /// reaching the datasheets' 3 cm "typical" at 50 m.
  double range_noise = 0.02;          ///< m
  double range_noise_per_m = 0.0002;  ///< m per m of range
  /// Lost returns: a share at any range, plus one growing with r^2 (the returned power falls as 1/r^2)
  /// to `dropout_at_max_range` at the datasheet's range.
  double dropout = 0.01;
  double dropout_at_max_range = 0.5;
  /// The survey map's own error: the mapping vehicle places its scans with a GNSS/INS pose that errs
  /// smoothly along the street (multipath and outages in street canyons), so the map is displaced from
  /// the world by a few centimetres, differently every few tens of metres. NDT then localizes in the
  /// map's frame, the RSU (RTK-surveyed) in the world's. Standard deviation per horizontal axis and of
  /// yaw; the error varies over wavelengths of `map_error_length` to four times that along the route.
  double map_position_sd = 0.05;  ///< m: mobile mapping in urban streets, 2-10 cm absolute
  double map_yaw_sd = 0.05 * 3.14159265358979323846 / 180.0;  ///< rad
  double map_error_length = 50.0;  ///< m
  /// The vehicle LiDAR's yaw on the car minus what its extrinsic calibration (the recording's
  /// lidar_pose) says: NDT then reports the car's heading off by this much while the car drives
  /// straight on. 0.3 deg: KITTI's HDL-64E against its reference trajectory shows 0.2-0.6 deg between
  /// the LiDAR's axis and the direction of travel after the published calibration.
  double lidar_mount_yaw = 0.3 * 3.14159265358979323846 / 180.0;  ///< rad
  /// The size a vehicle's CAM tells the RSU, rounded to this step (ETSI's CAM carries length and width
  /// in units of 0.1 m): the body then differs from the box the perception places by up to half a
  /// step (the twin's car, 4.88 x 1.84 m, is sent as 4.9 x 1.8). 0: the exact body size (the ideal twin).
  double cam_size_step = 0.1;  ///< m
  /// What the CAM's box adds to the body before that rounding, length and width: a V2X stack that counts
  /// the mirrors in the width or adds a margin, as a dataset's labels do. 0: the body's size.
  double cam_length_excess = 0.0, cam_width_excess = 0.0;  ///< m
  /// Every LiDAR's horizontal beam divergence (LidarSpec::beam_divergence): returns at depth edges are
  /// mixed or bloom, as a real footprint makes them. Velodyne's manuals: 3.0 mrad horizontal, 1.5
  /// vertical. 0: each return is its centre ray's (the ideal twin).
  double beam_divergence = 3.0e-3;  ///< rad
  /// The same up and down (LidarSpec::beam_divergence_vertical): at edges between objects one above the
  /// other (a car's sill over the road, seen from a pole, mixes them). Velodyne's is 1.5 mrad; off by
  /// default: it changed 0.17 % of a street sweep's returns for 1.66x its ray casting (ray_bench,
  /// BM_CastSweepFootprint), and the fixes from a pole not beyond their spread (docs/twin.md).
  double beam_divergence_vertical = 0.0;  ///< rad

  /// The ideal twin: perfect surveys (RSU and map), clocks and LiDAR mounting, box-shaped car, 2 cm range noise, no dropouts.
  static ErrorSources ideal();
};

}  // namespace coloc::sim
