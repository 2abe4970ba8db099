#pragma once
// The ray hits of a vehicle LiDAR's sweeps, kept for later drives along the same trajectory through the
// same world. An experiment's trials of one site differ in their draws (LiDAR noise, odometry, the RSUs'
// survey), not in what the roof LiDAR's rays hit, so its casting - most of a simulated drive - is done
// once per site instead of once per trial.
//
// A sweep is kept under its index in the drive together with a fingerprint of the rays it was cast
// from (sensor poses and LiDAR); a request whose fingerprint differs is cast afresh and not kept. The
// world itself is not fingerprinted: share a cache only between drives of one scenario's world.
// Thread-safe.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

#include "coloc/sim/lidar_model.hpp"
#include "coloc/sim/ray_caster.hpp"

namespace coloc::sim {

struct SweepCacheStats {
  std::uint64_t served = 0;  ///< sweeps given from the cache
  std::uint64_t cast = 0;    ///< sweeps cast (kept or not)
};

class SweepCache {
 public:
  using Hits = std::vector<RayHit>;
  /// Sweep `index` of a drive (any key the caller makes unique per sweep): the hits kept for it if their fingerprint is `fingerprint`, else `cast()`.
  std::shared_ptr<const Hits> get(std::size_t index, std::uint64_t fingerprint, const std::function<Hits()>& cast);
  SweepCacheStats stats() const;
  std::size_t bytes() const;  ///< held by the kept hits

 private:
  struct Entry {
    std::uint64_t fingerprint;
    std::shared_ptr<const Hits> hits;
  };
  mutable std::mutex mutex_;
  std::map<std::size_t, Entry> entries_;
  SweepCacheStats stats_;
};

/// What a sweep's rays depend on besides the world: the LiDAR's angles and range and where the sensor
/// is at each firing (sampled at every firing; bit for bit), and `count` values of the caller's that
/// describe the world's moving parts (where a vehicle in it is).
std::uint64_t sweepFingerprint(const LidarSpec& spec, const SensorTrajectory& pose, const double* world = nullptr, std::size_t count = 0);

}  // namespace coloc::sim
