#include <gtest/gtest.h>

#include <cmath>
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
