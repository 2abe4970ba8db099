#include "coloc/sim/random_engine.hpp"

namespace coloc::sim {

namespace {

// MT19937-64's parameters (Matsumoto and Nishimura; the C++ standard's mt19937_64).
constexpr std::size_t kN = 312, kM = 156;
constexpr std::uint64_t kUpper = 0xFFFFFFFF80000000ULL, kLower = 0x7FFFFFFFULL, kMatrix = 0xB5026F5AA96619E9ULL;
constexpr std::uint64_t kInitMultiplier = 6364136223846793005ULL;

inline std::uint64_t twist(std::uint64_t word, std::uint64_t next, std::uint64_t far) {
  const std::uint64_t y = (word & kUpper) | (next & kLower);
  return far ^ (y >> 1) ^ ((0 - (y & 1)) & kMatrix);  // a mask, not a branch: the loops vectorise
}

inline std::uint64_t temper(std::uint64_t y) {
  y ^= (y >> 29) & 0x5555555555555555ULL;
  y ^= (y << 17) & 0x71D67FFFEDA60000ULL;
  y ^= (y << 37) & 0xFFF7EEE000000000ULL;
  return y ^ (y >> 43);
}

// The next block of the state into `out` and back into `x`, then `out` tempered. In the first half
// every word depends only on the old state, in the second only on the first half's new words: both
// halves are loops without a carried dependence.
#if defined(__GNUC__) && defined(__x86_64__) && !defined(__clang__)
__attribute__((target_clones("avx2", "default")))
#endif
void nextBlock(std::uint64_t* __restrict x, std::uint64_t* __restrict out) {
  for (std::size_t k = 0; k < kN - kM; ++k) out[k] = twist(x[k], x[k + 1], x[k + kM]);
  for (std::size_t k = 0; k < kN - kM; ++k) x[k] = out[k];
  for (std::size_t k = kN - kM; k < kN - 1; ++k) out[k] = twist(x[k], x[k + 1], x[k - (kN - kM)]);
  out[kN - 1] = twist(x[kN - 1], x[0], x[kM - 1]);
  for (std::size_t k = kN - kM; k < kN; ++k) x[k] = out[k];
  for (std::size_t k = 0; k < kN; ++k) out[k] = temper(out[k]);
}

}  // namespace

static_assert(RandomEngine::max() == ~std::uint64_t{0}, "a full 64-bit engine: canonical() takes one number");

void RandomEngine::seed(result_type seed) {
  state_[0] = seed;
  for (std::size_t i = 1; i < kN; ++i) state_[i] = kInitMultiplier * (state_[i - 1] ^ (state_[i - 1] >> 62)) + i;
  next_ = kN;
}

void RandomEngine::refill() {
  static_assert(kStateSize == kN, "the block is the state");
  nextBlock(state_.data(), tempered_.data());
  next_ = 0;
}

}  // namespace coloc::sim
