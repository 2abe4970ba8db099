#include "stamp_clock.hpp"

namespace coloc::live {

StampClock::StampClock(pipeline::ClockMode mode, double tolerance, double same_within)
    : mode_(mode), tolerance_(fromSeconds(tolerance)), same_within_(fromSeconds(same_within)) {
  reset();
}

void StampClock::reset() {
  std::lock_guard<std::mutex> lock(mutex_);
  decided_ = mode_ != pipeline::ClockMode::kAuto;
  separate_ = mode_ == pipeline::ClockMode::kSeparate;
  have_offset_ = false;
  offset_ = 0;
}

void StampClock::observe(Stamp arrival, Stamp stamp) {
  std::lock_guard<std::mutex> lock(mutex_);
  const Duration delay = arrival - stamp;
  if (!decided_) {
    decided_ = true;
    separate_ = delay < -tolerance_ || delay > same_within_;
  }
  if (!separate_) return;
  if (!have_offset_ || delay < offset_) offset_ = delay;
  have_offset_ = true;
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
