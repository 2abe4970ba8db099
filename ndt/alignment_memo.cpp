#include "coloc/ndt/alignment_memo.hpp"

#include <condition_variable>
#include <cstring>
#include <exception>
#include <optional>

namespace coloc::ndt {

template <typename T>
struct AlignmentMemo::Slot {
  // Held so that no other scan or target can take their addresses while the key names them.
  std::shared_ptr<const PointCloud> scan;
  std::shared_ptr<const NdtTarget> target;
  std::optional<T> value;
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

template <typename T>
T AlignmentMemo::share(Table<T>& table, const Key& key, const Question& q, std::uint64_t& asked, std::uint64_t& computed,
                       const std::function<T()>& compute) {
  std::shared_ptr<Slot<T>> slot;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    ++asked;
    const auto found = table.find(key);
    if (found != table.end()) {
      slot = found->second;
      slot->ready.wait(lock, [&] { return slot->done; });
      if (slot->failure) std::rethrow_exception(slot->failure);
      return *slot->value;
    }
    slot = std::make_shared<Slot<T>>();
    slot->scan = q.scan;
    slot->target = q.target;
    table.emplace(key, slot);
    ++computed;
  }
  std::exception_ptr failure;
  std::optional<T> value;
  try {
    value = compute();
  } catch (...) {
    failure = std::current_exception();
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    slot->done = true;
    if (failure) {
      slot->failure = failure;
      table.erase(key);  // not kept: a later question computes afresh
    } else {
      slot->value = value;
    }
  }
  slot->ready.notify_all();
  if (failure) std::rethrow_exception(failure);
  return std::move(*value);
}

ScanOutcome AlignmentMemo::answer(const std::string& config, const Question& q, const std::function<ScanOutcome()>& compute) {
  Key key{config, q.scan.get(), q.target.get(), q.stamp, {}};
  const double values[9] = {q.predicted.position.x(), q.predicted.position.y(), q.predicted.position.z(),
                            q.predicted.orientation.w(), q.predicted.orientation.x(), q.predicted.orientation.y(),
                            q.predicted.orientation.z(), q.vx, q.wz};
  for (int i = 0; i < 9; ++i) key.bits[i] = bitsOf(values[i]);
  return share<ScanOutcome>(entries_, key, q, stats_.asked, stats_.computed, compute);
}

std::shared_ptr<const PointCloud> AlignmentMemo::preprocessed(const std::string& config, const std::shared_ptr<const PointCloud>& scan, double vx,
                                                              double wz, const std::function<PointCloud()>& compute) {
  Key key{config, scan.get(), nullptr, 0, {}};
  key.bits[0] = bitsOf(vx);
  key.bits[1] = bitsOf(wz);
  Question q;
  q.scan = scan;
  return share<std::shared_ptr<const PointCloud>>(preprocessed_, key, q, stats_.preprocessings_asked, stats_.preprocessings_computed,
                                                  [&] { return std::make_shared<const PointCloud>(compute()); });
}

AlignmentMemoStats AlignmentMemo::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

std::string configFingerprint(const NdtPoseSourceConfig& c) {
  // Field by field (padding bytes are not part of a value). A field added to these structs must be
  // added here too, or sources differing only in it would share outcomes: the sizes below catch it.
  static_assert(sizeof(NdtConfig) == 192, "NdtConfig changed: fingerprint the new field");
  static_assert(sizeof(MapUpdateConfig) == 24, "MapUpdateConfig changed: fingerprint the new field");
  std::string out;
  const NdtConfig& n = c.ndt;
  append(out, n.backend, n.neighborhood, n.resolution, n.step_size, n.transformation_epsilon, n.max_iterations, n.outlier_ratio, n.threads,
         n.nvtl_threshold, n.max_oscillations, n.covariance, n.fixed_covariance, n.covariance_floor, n.score_temperature, n.score_yaw_offset_deg);
  out += preprocessFingerprint(c.preprocess);
  append(out, c.map.radius, c.map.update_distance, c.map.background, c.lidar_pose);
  return out;
}

std::string preprocessFingerprint(const PreprocessConfig& p) {
  static_assert(sizeof(PreprocessConfig) == 48, "PreprocessConfig changed: fingerprint the new field");
  std::string out;
  append(out, p.min_range, p.max_range, p.deskew, p.voxel_size, p.max_points, p.seed);
  return out;
}

}  // namespace coloc::ndt
