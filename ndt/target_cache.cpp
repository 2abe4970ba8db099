#include "coloc/ndt/target_cache.hpp"

#include <sstream>

#include "coloc/core/error.hpp"

namespace coloc::ndt {

namespace {

// Everything the target's contents depend on: the tiles, and the settings NdtTarget bakes in (the
// stock backend's object also keeps its optimiser settings).
std::string keyOf(const std::string& map_id, const std::vector<std::size_t>& tiles, const NdtConfig& c) {
  std::ostringstream key;
  key.precision(17);
  key << map_id << '|' << static_cast<int>(c.backend) << '|' << c.resolution << '|' << c.outlier_ratio;
  if (c.backend == NdtBackend::kPcl) key << '|' << c.step_size << '|' << c.transformation_epsilon << '|' << c.max_iterations;
  key << '|';
  for (std::size_t t : tiles) key << t << ',';
  return key.str();
}

}  // namespace

TargetCache::TargetCache(std::size_t capacity) : capacity_(capacity) {
  if (capacity_ == 0) throw Error("NDT target cache: the capacity must be at least 1");
}

std::shared_ptr<const NdtTarget> TargetCache::get(const std::string& map_id, const std::vector<std::size_t>& tiles,
                                                  const NdtConfig& config, const Build& build) {
  const std::string key = keyOf(map_id, tiles, config);
  std::promise<std::shared_ptr<const NdtTarget>> promise;
  std::shared_future<std::shared_ptr<const NdtTarget>> waiting;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++stats_.requests;
    auto found = entries_.find(key);
    if (found != entries_.end()) {
      found->second.last_use = ++clock_;
      waiting = found->second.target;
    } else {
      ++stats_.builds;
      entries_[key] = Entry{promise.get_future().share(), ++clock_};
      evict();
    }
  }
  if (waiting.valid()) return waiting.get();  // rethrows a failed build's exception
  try {
    std::shared_ptr<const NdtTarget> target = build();
    promise.set_value(target);
    return target;
  } catch (...) {
    promise.set_exception(std::current_exception());
    std::lock_guard<std::mutex> lock(mutex_);
    entries_.erase(key);
    throw;
  }
}

void TargetCache::evict() {
  while (entries_.size() > capacity_) {
    auto oldest = entries_.end();
    for (auto it = entries_.begin(); it != entries_.end(); ++it) {
      // A build still under way stays: its requesters are waiting on it.
      const bool ready = it->second.target.wait_for(std::chrono::seconds(0)) == std::future_status::ready;
      if (ready && (oldest == entries_.end() || it->second.last_use < oldest->second.last_use)) oldest = it;
    }
    if (oldest == entries_.end()) return;
    entries_.erase(oldest);
  }
}

TargetCacheStats TargetCache::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

}  // namespace coloc::ndt
