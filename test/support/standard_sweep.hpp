#pragma once
// A sweep's noise and dropouts drawn as the twin drew them before it had its own engine: per ray, hit or
// not, a std::normal_distribution and a std::uniform_real_distribution draw on std::mt19937_64: the
// baseline ray_bench measures sim::sweepPoints against (the same noise's distribution, not its draws).
#include <random>
#include <vector>

#include "coloc/sim/lidar_model.hpp"

namespace coloc::testing {

/// Per ray, its noisy range as a hit (the hit's mesh), or no hit where the ray missed, its return was
/// lost or its range fell outside the spec's; `kept` is resized to the sweep.
inline void standardSweepRanges(const sim::LidarSpec& spec, const std::vector<sim::RayHit>& hits, std::mt19937_64& rng,
                                std::vector<sim::RayHit>& kept) {
  std::normal_distribution<double> noise(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  kept.assign(hits.size(), sim::RayHit{});
  for (std::size_t i = 0; i < hits.size(); ++i) {
    const double n = noise(rng), u = uniform(rng);
    if (hits[i].distance < 0.0f) continue;
    const double r = hits[i].distance;
    if (u < spec.dropout + spec.dropout_at_max_range * (r / spec.max_range) * (r / spec.max_range)) continue;
    const double range = r + n * (spec.range_noise + spec.range_noise_per_m * r);
    if (range < spec.min_range || range > spec.max_range) continue;
    kept[i] = {static_cast<float>(range), hits[i].mesh};
  }
}

}  // namespace coloc::testing
