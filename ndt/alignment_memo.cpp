#include "coloc/ndt/alignment_memo.hpp"

#include <condition_variable>
#include <cstring>
#include <exception>
#include <optional>

namespace coloc::ndt {

struct AlignmentMemo::Entry {
  // Held so that no other scan or target can take their addresses while the key names them.
  std::shared_ptr<const PointCloud> scan;
  std::shared_ptr<const NdtTarget> target;
  std::optional<ScanOutcome> outcome;
  std::exception_ptr failure;
  bool done = false;
  std::condition_variable ready;
};

namespace {

std::uint64_t bitsOf(double v) {
  std::uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

// The values' bytes, one after the other (each a scalar or an Eigen vector: no padding inside).
template <typename... T>
void append(std::string& out, const T&... values) {
  (out.append(reinterpret_cast<const char*>(&values), sizeof values), ...);
}

}  // namespace

bool AlignmentMemo::Key::operator==(const Key& o) const {
  return scan == o.scan && target == o.target && stamp == o.stamp && std::memcmp(bits, o.bits, sizeof bits) == 0 && config == o.config;
}

std::size_t AlignmentMemo::KeyHash::operator()(const Key& k) const {
  std::uint64_t h = std::hash<const void*>()(k.scan) ^ (std::hash<const void*>()(k.target) * 0x9e3779b97f4a7c15ULL) ^ static_cast<std::uint64_t>(k.stamp);
  for (std::uint64_t b : k.bits) h = (h ^ b) * 0x100000001b3ULL;
  return static_cast<std::size_t>(h ^ std::hash<std::string>()(k.config));
}

ScanOutcome AlignmentMemo::answer(const std::string& config, const Question& q, const std::function<ScanOutcome()>& compute) {
  Key key{config, q.scan.get(), q.target.get(), q.stamp, {}};
  const double values[9] = {q.predicted.position.x(), q.predicted.position.y(), q.predicted.position.z(),
                            q.predicted.orientation.w(), q.predicted.orientation.x(), q.predicted.orientation.y(),
                            q.predicted.orientation.z(), q.vx, q.wz};
  for (int i = 0; i < 9; ++i) key.bits[i] = bitsOf(values[i]);
  std::shared_ptr<Entry> entry;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    ++stats_.asked;
    const auto found = entries_.find(key);
    if (found != entries_.end()) {
      entry = found->second;
      entry->ready.wait(lock, [&] { return entry->done; });
      if (entry->failure) std::rethrow_exception(entry->failure);
      return *entry->outcome;
    }
    entry = std::make_shared<Entry>();
    entry->scan = q.scan;
    entry->target = q.target;
    entries_.emplace(key, entry);
    ++stats_.computed;
  }
  std::exception_ptr failure;
  std::optional<ScanOutcome> outcome;
  try {
    outcome = compute();
  } catch (...) {
    failure = std::current_exception();
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    entry->done = true;
    if (failure) {
      entry->failure = failure;
      entries_.erase(key);  // not kept: a later question computes afresh
    } else {
      entry->outcome = outcome;
    }
  }
  entry->ready.notify_all();
  if (failure) std::rethrow_exception(failure);
  return std::move(*outcome);
}

AlignmentMemoStats AlignmentMemo::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

std::string configFingerprint(const NdtPoseSourceConfig& c) {
  // Field by field (padding bytes are not part of a value). A field added to these structs must be
  // added here too, or sources differing only in it would share outcomes: the sizes below catch it.
  static_assert(sizeof(NdtConfig) == 192, "NdtConfig changed: fingerprint the new field");
  static_assert(sizeof(PreprocessConfig) == 48, "PreprocessConfig changed: fingerprint the new field");
  static_assert(sizeof(MapUpdateConfig) == 24, "MapUpdateConfig changed: fingerprint the new field");
  std::string out;
  const NdtConfig& n = c.ndt;
  append(out, n.backend, n.neighborhood, n.resolution, n.step_size, n.transformation_epsilon, n.max_iterations, n.outlier_ratio, n.threads,
         n.nvtl_threshold, n.max_oscillations, n.covariance, n.fixed_covariance, n.covariance_floor, n.score_temperature, n.score_yaw_offset_deg);
  const PreprocessConfig& p = c.preprocess;
  append(out, p.min_range, p.max_range, p.deskew, p.voxel_size, p.max_points, p.seed);
  append(out, c.map.radius, c.map.update_distance, c.map.background, c.lidar_pose);
  return out;
}

}  // namespace coloc::ndt
