#include "coloc/sim/sweep_cache.hpp"

#include <cstring>

namespace coloc::sim {

namespace {

// A fingerprint, not a defence against crafted input: 64-bit words folded in by multiply and shift.
// A byte at a time (FNV-1a) it cost 1.5 % of an experiment's CPU: 1,800 poses are hashed per sweep.
// Every value hashed here is a whole number of doubles; a tail of bytes is folded in one by one.
void mix(std::uint64_t& h, const void* data, std::size_t size) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i + 8 <= size; i += 8) {
    std::uint64_t word;
    std::memcpy(&word, bytes + i, 8);
    h = (h ^ word) * 0x9E3779B97F4A7C15ULL;
    h ^= h >> 29;
  }
  for (std::size_t i = size & ~std::size_t{7}; i < size; ++i) h = (h ^ bytes[i]) * 1099511628211ULL;
}

}  // namespace

std::uint64_t sweepFingerprint(const LidarSpec& spec, const SensorTrajectory& pose, const double* world, std::size_t count) {
  std::uint64_t h = 14695981039346656037ULL;
  if (count > 0) mix(h, world, count * sizeof(double));
  mix(h, spec.vertical_deg.data(), spec.vertical_deg.size() * sizeof(double));
  mix(h, spec.azimuth_offset_deg.data(), spec.azimuth_offset_deg.size() * sizeof(double));
  for (double v : {spec.rotation_hz, spec.azimuth_step_deg, spec.max_range, spec.beam_divergence, spec.beam_divergence_vertical, spec.echo_separation}) mix(h, &v, sizeof v);
  const int firings = firingsPerSweep(spec);
  const double sweep = 1.0 / spec.rotation_hz;
  for (int f = 0; f < firings; ++f) {
    const Eigen::Isometry3d p = pose(sweep * f / firings);  // the very times castSweep uses
    mix(h, p.matrix().data(), 16 * sizeof(double));
  }
  return h;
}

std::shared_ptr<const SweepCache::Hits> SweepCache::get(std::size_t index, std::uint64_t fingerprint, const std::function<Hits()>& cast) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto found = entries_.find(index);
    if (found != entries_.end() && found->second.fingerprint == fingerprint) {
      ++stats_.served;
      return found->second.hits;
    }
  }
  auto hits = std::make_shared<const Hits>(cast());
  std::lock_guard<std::mutex> lock(mutex_);
  ++stats_.cast;
  entries_.emplace(index, Entry{fingerprint, hits});  // keeps the first drive's sweep if one is there
  return hits;
}

SweepCacheStats SweepCache::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

std::size_t SweepCache::bytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::size_t total = 0;
  for (const auto& [index, e] : entries_) total += e.hits->size() * sizeof(RayHit);
  return total;
}

}  // namespace coloc::sim
