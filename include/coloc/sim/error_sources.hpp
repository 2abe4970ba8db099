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

  /// The ideal twin: perfect survey and clocks, box-shaped car, 2 cm range noise, no dropouts.
  static ErrorSources ideal();
};

}  // namespace coloc::sim
