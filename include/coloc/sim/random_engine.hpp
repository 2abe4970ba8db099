#pragma once
// The twin's random engine: the 64-bit Mersenne Twister, the very sequence std::mt19937_64 gives for the
// same seed (tested), made a block of 312 at a time with the tempering done for the whole block, which
// the compiler vectorises. A sweep draws twice per ray, tens of millions of draws per drive: the
// standard library's engine, one number at a time, was a twentieth of the twin's CPU.
#include <array>
#include <cstddef>
#include <cstdint>

namespace coloc::sim {

class RandomEngine {
 public:
  using result_type = std::uint64_t;
  static constexpr result_type default_seed = 5489u;
  static constexpr result_type min() { return 0; }
  static constexpr result_type max() { return ~result_type{0}; }

  explicit RandomEngine(result_type seed = default_seed) { this->seed(seed); }
  void seed(result_type seed);

  result_type operator()() {
    if (next_ == kStateSize) refill();
    return tempered_[next_++];
  }
  /// A uniform draw in [0, 1) from one number: what std::generate_canonical<double, 53> (and so
  /// std::uniform_real_distribution<double>(0, 1)) gives with libstdc++, on every standard library.
  double canonical() { return canonicalOf((*this)()); }
  static double canonicalOf(result_type number) {
    // number * 2^-64 rounded once, as converting the whole number would round it: both halves convert
    // and scale exactly, and their sum is the one rounding. A 64-bit unsigned conversion branches on
    // the top bit, a coin toss the processor mispredicts every other time.
    const double u = static_cast<double>(static_cast<std::int64_t>(number >> 32)) * 0x1p-32 +
                     static_cast<double>(static_cast<std::int64_t>(number & 0xFFFFFFFFu)) * 0x1p-64;
    return u < 1.0 ? u : 0x1.fffffffffffffp-1;  // the numbers that round up to 2^64: the largest double below 1
  }

 private:
  static constexpr std::size_t kStateSize = 312;
  void refill();

  alignas(64) std::array<std::uint64_t, kStateSize> state_{};
  alignas(64) std::array<std::uint64_t, kStateSize> tempered_{};
  std::size_t next_ = kStateSize;
};

}  // namespace coloc::sim
