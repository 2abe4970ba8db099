#pragma once
// NDT targets shared between maps that cover the same tiles: several replays of one drive (the
// experiment replays each drive 21 times), or several vehicles on one map in a simulation, build the
// target of a given set of tiles once. A target is immutable, so sharing it changes no result.
//
// Thread-safe. A request for a target being built by another thread waits for that build instead of
// starting its own. At most `capacity` targets are kept; the one unused the longest goes first (a
// target still in use by a map stays alive through its shared pointer).
#include <cstdint>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "coloc/ndt/ndt_config.hpp"
#include "coloc/ndt/ndt_target.hpp"

namespace coloc::ndt {

struct TargetCacheStats {
  std::uint64_t requests = 0;
  std::uint64_t builds = 0;  ///< requests that built (the rest were served a shared target)
};

class TargetCache {
 public:
  explicit TargetCache(std::size_t capacity = 16);

  using Build = std::function<std::shared_ptr<const NdtTarget>()>;
  /// The target of `tiles` of the map named `map_id` under `config`; `build` makes it when no such
  /// target is kept. An exception from `build` reaches every caller waiting for it and nothing is kept.
  std::shared_ptr<const NdtTarget> get(const std::string& map_id, const std::vector<std::size_t>& tiles, const NdtConfig& config,
                                       const Build& build);

  TargetCacheStats stats() const;

 private:
  struct Entry {
    std::shared_future<std::shared_ptr<const NdtTarget>> target;
    std::uint64_t last_use = 0;
  };
  void evict();  // with mutex_ held

  std::size_t capacity_;
  mutable std::mutex mutex_;
  std::map<std::string, Entry> entries_;
  std::uint64_t clock_ = 0;
  TargetCacheStats stats_;
};

}  // namespace coloc::ndt
