#pragma once
// LiDARs as the twin simulates them: Velodyne's real vertical angle tables (and an even 64-beam one for
// poles), 10 Hz rotation with 0.2 deg azimuth steps, each point stamped with its time in the sweep,
// Gaussian range noise growing with range, lost returns, range limits.
#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "coloc/sim/random_engine.hpp"
#include "coloc/sim/ray_caster.hpp"

namespace coloc::sim {

struct LidarSpec {
  std::string name;
  std::vector<double> vertical_deg;       ///< per laser
  std::vector<double> azimuth_offset_deg; ///< per laser (rot_correction)
  double rotation_hz = 10.0;
  double azimuth_step_deg = 0.2;
  double range_noise = 0.02;        ///< m, standard deviation at zero range
  double range_noise_per_m = 0.0;   ///< m of standard deviation per m of range
  double dropout = 0.0;             ///< share of returns lost at any range
  double dropout_at_max_range = 0.0;  ///< further share lost at max_range, growing with (range / max_range)^2
  double min_range = 0.9;     ///< m
  double max_range = 100.0;   ///< m
  /// The laser's footprint widens with range by this full angle across the scan (rad; Velodyne: 3.0
  /// mrad horizontal, 1.5 vertical). Where it straddles a depth edge (a car's outline against what lies
  /// behind), the return is not the centre ray's: echoes closer than `echo_separation` merge into one
  /// at a range between them (mixed pixels), farther ones are told apart and the strongest is
  /// returned (the sensor's default mode: a near edge covering part of the footprint blooms outwards).
  /// 0: each return is its centre ray's.
  double beam_divergence = 0.0;
  /// The same up and down (rad; Velodyne: 1.5 mrad). Its edges run between two objects one above the
  /// other: a car's sill against the road under it, its roof line against what lies behind. 0: none.
  double beam_divergence_vertical = 0.0;
  double echo_separation = 0.5;  ///< m; a pulse of a few ns, our estimate
};

/// Velodyne's published calibration (ros-drivers/velodyne VLP16db.yaml, VeloView-VLP-32C.yaml).
/// Their beam divergence is set by withErrors (ErrorSources::beam_divergence and beam_divergence_vertical).
LidarSpec vlp16();
LidarSpec vlp32c();
/// A 64-beam LiDAR with evenly spread beams (45 deg vertical, 1024 columns), as on roadside poles; an
/// idealised table, not a vendor's calibration.
LidarSpec os1_64();
/// "VLP-16", "VLP-32C" or "OS1-64"; throws coloc::Error for any other name.
LidarSpec lidarNamed(const std::string& name);
/// The spec with the noise and dropouts of `errors` (the error-sources header), the ideal ones kept otherwise.
struct ErrorSources;
LidarSpec withErrors(LidarSpec spec, const ErrorSources& errors);

struct LidarPoint {
  Eigen::Vector3f position;  ///< sensor frame at the time of its firing
  float time;                ///< s since the start of the sweep
  int laser;
  int mesh;                  ///< what the ray hit (ground truth only)
};

/// The sensor's pose in the world at time t since the start of the sweep.
using SensorTrajectory = std::function<Eigen::Isometry3d(double t)>;

/// One revolution. Each firing is cast from where the sensor is at its own time, so a moving sensor's
/// scan carries the motion distortion a real one has. Noise is drawn from `rng`.
std::vector<LidarPoint> scanSweep(const LidarSpec& spec, const RayCaster& world, const SensorTrajectory& pose, RandomEngine& rng);

/// scanSweep in its two halves. The geometry: every ray's hit, firing-major, lasers in spec order...
std::vector<RayHit> castSweep(const LidarSpec& spec, const RayCaster& world, const SensorTrajectory& pose);
/// (into `hits`, its room kept from sweep to sweep: fresh room costs page faults)
void castSweep(const LidarSpec& spec, const RayCaster& world, const SensorTrajectory& pose, std::vector<RayHit>& hits);
/// ...and the points those hits give with the spec's noise and dropouts: one draw of `rng` per sweep,
/// each ray's own draws from it (ray_noise.hpp). Throws coloc::Error if `hits` is not a sweep of this spec.
std::vector<LidarPoint> sweepPoints(const LidarSpec& spec, const std::vector<RayHit>& hits, RandomEngine& rng);
/// The same into `points` (its room kept: a loop over sweeps then allocates once).
void sweepPoints(const LidarSpec& spec, const std::vector<RayHit>& hits, RandomEngine& rng, std::vector<LidarPoint>& points);
/// Firings in one revolution (360 deg / azimuth step).
int firingsPerSweep(const LidarSpec& spec);

}  // namespace coloc::sim
