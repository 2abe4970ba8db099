#include <gtest/gtest.h>

#include <cmath>
#include <initializer_list>
#include <random>

#include "coloc/sim/random_engine.hpp"

namespace coloc::sim {
namespace {

TEST(RandomEngine, GivesStdMt19937_64sSequenceForAnySeed) {
  for (const std::uint64_t seed : {std::uint64_t{0}, std::uint64_t{1}, std::uint64_t{5489}, std::uint64_t{0x8000000000000007ULL}, ~std::uint64_t{0}}) {
    std::mt19937_64 reference(seed);
    RandomEngine engine(seed);
    // A hundred thousand numbers: over three hundred blocks of the state.
    for (int i = 0; i < 100000; ++i) ASSERT_EQ(engine(), reference()) << "seed " << seed << ", number " << i;
  }
  RandomEngine reseeded(3);
  for (int i = 0; i < 1000; ++i) reseeded();
  reseeded.seed(42);
  std::mt19937_64 reference(42);
  for (int i = 0; i < 1000; ++i) ASSERT_EQ(reseeded(), reference()) << "number " << i << " after seed()";
  EXPECT_EQ(RandomEngine()(), std::mt19937_64()());
}

TEST(RandomEngine, CanonicalDrawsTakeOneNumberEachAndStayBelowOne) {
  EXPECT_EQ(RandomEngine::canonicalOf(0), 0.0);
  EXPECT_EQ(RandomEngine::canonicalOf(std::uint64_t{1} << 63), 0.5);
  // The numbers within 2^10 of 2^64 round up to 2^64 as doubles: the draw stays below 1.
  EXPECT_EQ(RandomEngine::canonicalOf(~std::uint64_t{0}), std::nextafter(1.0, 0.0));
  EXPECT_LT(RandomEngine::canonicalOf(~std::uint64_t{0} - 1000), 1.0);
  RandomEngine a(7), b(7);
  for (int i = 0; i < 1000; ++i) ASSERT_EQ(a.canonical(), RandomEngine::canonicalOf(b()));
  EXPECT_EQ(a(), b());
}

// The draw converts the number in two halves; their sum must round as converting the whole number
// does, where it matters: at every magnitude, on a tie (to even), one off either side, and at the
// halves' seam.
TEST(RandomEngine, CanonicalRoundsTheWholeNumberOnceAtEveryMagnitudeAndTie) {
  const auto whole = [](std::uint64_t n) {
    const double u = static_cast<double>(n) * 0x1p-64;
    return u < 1.0 ? u : std::nextafter(1.0, 0.0);
  };
  std::mt19937_64 bits(3);
  int checked = 0;
  for (int top = 0; top < 64; ++top)
    for (int k = 0; k < 200; ++k) {
      const std::uint64_t lead = std::uint64_t{1} << top;
      const std::uint64_t mantissa = top > 0 ? bits() & (lead - 1) : 0;
      const int dropped = top > 52 ? top - 52 : 0;  // the bits below the double's precision
      const std::uint64_t kept = dropped > 0 ? mantissa >> dropped << dropped : mantissa;
      const std::uint64_t half = dropped > 0 ? std::uint64_t{1} << (dropped - 1) : 0;
      for (const std::uint64_t n : std::initializer_list<std::uint64_t>{lead | mantissa, lead | kept, lead | kept | half, (lead | kept | half) - 1, (lead | kept | half) + 1,
                                    lead | (mantissa & 0xFFFFFFFF00000000ULL), lead | (mantissa | 0xFFFFFFFFULL)}) {
        ASSERT_EQ(RandomEngine::canonicalOf(n), whole(n)) << "number " << n;
        ++checked;
      }
    }
  EXPECT_EQ(checked, 64 * 200 * 7);
  for (std::uint64_t n = ~std::uint64_t{0}; n > ~std::uint64_t{0} - 5000; --n) ASSERT_EQ(RandomEngine::canonicalOf(n), whole(n)) << "number " << n;
}

#if defined(__GLIBCXX__)
// The twin's results were made with libstdc++'s distributions; the engine's own draw must be theirs.
TEST(RandomEngine, CanonicalIsWhatLibstdcxxsUniformDistributionGives) {
  std::mt19937_64 reference(11);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  RandomEngine engine(11);
  for (int i = 0; i < 100000; ++i) ASSERT_EQ(engine.canonical(), uniform(reference)) << "draw " << i;
}
#endif

}  // namespace
}  // namespace coloc::sim
