#include "stamp_clock.hpp"

#include <algorithm>
#include <vector>

namespace coloc::live {

StampClock::StampClock(pipeline::ClockMode mode, double tolerance, double same_within)
    : mode_(mode), tolerance_(fromSeconds(tolerance)), same_within_(fromSeconds(same_within)) {
  clear();
}

void StampClock::reset(Stamp from, Stamp to) {
  std::lock_guard<std::mutex> lock(mutex_);
  // The old relation, if there was one, tells the stale inputs apart: stamped on the old timeline.
  after_jump_ = decided_ && (!separate_ || have_offset_) && from > to;
  halfway_ = to + (from - to) / 2;
  old_offset_ = separate_ ? offset_ : 0;
  taken_since_jump_ = 0;
  clear();
}

void StampClock::clear() {
  decided_ = mode_ != pipeline::ClockMode::kAuto;
  separate_ = mode_ == pipeline::ClockMode::kSeparate;
  have_offset_ = false;
  offset_ = 0;
  recent_.clear();
}

namespace {
constexpr std::size_t kKept = 64;                        // delays kept: a few seconds of inputs
constexpr Duration kNearMedian = 1'000'000'000LL;        // a delay this far below the median is not one
constexpr int kSettling = 16;                            // inputs after a jump back that end its watch
}  // namespace

bool StampClock::observe(Stamp arrival, Stamp stamp) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (after_jump_) {
    // Stamped on the old timeline, or taken at an arrival read before the jump (another reader's
    // thread): either way from before it. Once the new relation has enough inputs of its own, none
    // from before is still on its way.
    if (arrival >= halfway_ || stamp + old_offset_ > halfway_) return false;
    if (++taken_since_jump_ >= kSettling) after_jump_ = false;
  }
  recent_.push_back(arrival - stamp);
  if (recent_.size() > kKept) recent_.pop_front();
  std::vector<Duration> sorted(recent_.begin(), recent_.end());
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const Duration median = sorted[sorted.size() / 2];
  if (mode_ == pipeline::ClockMode::kAuto) {
    decided_ = true;
    separate_ = median < -tolerance_ || median > same_within_;
  }
  if (!separate_) return true;
  // The smallest delay among those near the median: the least-delayed message, not an outlier.
  Duration smallest = median;
  for (const Duration d : recent_)
    if (d >= median - kNearMedian && d < smallest) smallest = d;
  // Never later than before (the clock would go back), unless the old offset's messages are long gone.
  if (!have_offset_ || smallest < offset_ || offset_ < median - kNearMedian) offset_ = smallest;
  have_offset_ = true;
  return true;
}

Stamp StampClock::toStampClock(Stamp node_time) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!decided_) return 0;
  if (!separate_) return node_time;
  return have_offset_ ? node_time - offset_ : 0;
}

bool StampClock::separate() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return separate_;
}

Duration StampClock::offset() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return offset_;
}

}  // namespace coloc::live
