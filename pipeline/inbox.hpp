#pragma once
// The pipeline's inbox: inputs pushed from any thread, taken in arrival order (ties in push order).
#include <condition_variable>
#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <utility>

#include "coloc/core/time.hpp"

namespace coloc::pipeline {

template <typename Item>
class Inbox {
 public:
  void push(Item item, Stamp arrival) {
    std::lock_guard<std::mutex> lock(mutex_);
    items_.emplace(std::make_pair(arrival, next_++), std::move(item));
  }

  /// The earliest item that arrived by `now`, with its arrival; nullopt if there is none.
  std::optional<std::pair<Stamp, Item>> takeArrivedBy(Stamp now) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (items_.empty() || items_.begin()->first.first > now) return std::nullopt;
    auto node = items_.extract(items_.begin());
    return std::make_pair(node.key().first, std::move(node.mapped()));
  }

  /// Drops every item that arrived after `now` (on a clock that went back: they belong to the time
  /// before the jump); returns how many.
  std::size_t dropArrivedAfter(Stamp now) {
    std::lock_guard<std::mutex> lock(mutex_);
    std::size_t dropped = 0;
    for (auto it = items_.begin(); it != items_.end();) {
      if (it->first.first > now) {
        it = items_.erase(it);
        ++dropped;
      } else {
        ++it;
      }
    }
    return dropped;
  }

  std::size_t size() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return items_.size();
  }

 private:
  mutable std::mutex mutex_;
  std::map<std::pair<Stamp, std::uint64_t>, Item> items_;
  std::uint64_t next_ = 0;
};

}  // namespace coloc::pipeline
