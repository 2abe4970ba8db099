#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "coloc/sim/ray_noise.hpp"

namespace coloc::sim {
namespace {

double normalCdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

// The ziggurat's layers: every one of the same area, the tail's start where the literature puts it for
// 256 layers (Marsaglia and Tsang, 2000: 3.6541528853610088), closing at the top.
TEST(RayNoise, TheZigguratsLayersHaveEqualAreasAndCloseAtTheTop) {
  const ZigguratLayers& z = ZigguratLayers::get();
  constexpr int n = ZigguratLayers::kLayers;
  EXPECT_NEAR(z.x[1], 3.6541528853610088, 1e-9);
  EXPECT_EQ(z.x[n], 0.0);
  EXPECT_NEAR(z.f[n], 1.0, 0.0);
  const double tail = std::sqrt(M_PI / 2.0) * std::erfc(z.x[1] / std::sqrt(2.0));
  EXPECT_NEAR(z.x[0] * z.f[1], z.x[1] * z.f[1] + tail, 1e-15) << "the base: its rectangle and the tail";
  for (int i = 1; i < n; ++i) EXPECT_NEAR(z.x[i] * (z.f[i + 1] - z.f[i]), z.area, 1e-9 * z.area) << "layer " << i;
  for (int i = 0; i < n; ++i) EXPECT_LT(z.x[i + 1], z.x[i]);
}

// Two million draws against the standard normal: mean and variance within four standard errors, the
// share beyond 1, 2, 3 and 3.65 (the tail's start) within four binomial standard errors, and the
// largest gap between the empirical and the true distribution (Kolmogorov-Smirnov) under its 1 %
// critical value, 1.63 / sqrt(n).
TEST(RayNoise, NormalDrawsFollowTheStandardNormal) {
  const std::size_t n = 2'000'000;
  std::vector<double> draws;
  draws.reserve(n);
  for (std::uint64_t sweep = 0; sweep < 20; ++sweep) {
    const RayNoise noise(0x1234567ULL + sweep * 0x9e3779b9ULL);
    for (std::uint64_t ray = 0; ray < n / 20; ++ray) draws.push_back(noise.normal(ray));
  }
  double sum = 0.0, sum_sq = 0.0, fourth = 0.0;
  for (const double d : draws) sum += d, sum_sq += d * d, fourth += d * d * d * d;
  const double dn = static_cast<double>(n);
  EXPECT_NEAR(sum / dn, 0.0, 4.0 / std::sqrt(dn));
  EXPECT_NEAR(sum_sq / dn, 1.0, 4.0 * std::sqrt(2.0 / dn));
  EXPECT_NEAR(fourth / dn, 3.0, 4.0 * std::sqrt(96.0 / dn));  // the kurtosis: the tails' weight
  for (const double x : {1.0, 2.0, 3.0, 3.6541528853610088}) {
    const double p = 2.0 * (1.0 - normalCdf(x));
    const double share = static_cast<double>(std::count_if(draws.begin(), draws.end(), [&](double d) { return std::abs(d) > x; })) / dn;
    EXPECT_NEAR(share, p, 4.0 * std::sqrt(p * (1.0 - p) / dn)) << "beyond " << x;
  }
  std::sort(draws.begin(), draws.end());
  double gap = 0.0;
  for (std::size_t i = 0; i < n; i += 7) {
    const double c = normalCdf(draws[i]);
    gap = std::max({gap, std::abs(c - static_cast<double>(i) / dn), std::abs(c - static_cast<double>(i + 1) / dn)});
  }
  EXPECT_LT(gap, 1.63 / std::sqrt(dn));
}

// A ray's draws are a function of the key and the ray alone: asked again, in any order, the same; a
// ray's uniform draw does not follow its normal draw, and neighbouring rays' draws do not follow each
// other (correlations within four of their standard errors of 0).
TEST(RayNoise, EachRaysDrawsAreItsOwnAndIndependent) {
  const RayNoise noise(42), other(43);
  const std::size_t n = 400'000;
  std::vector<double> normal(n), uniform(n);
  for (std::size_t i = n; i-- > 0;) normal[i] = noise.normal(i), uniform[i] = noise.uniform(i);
  for (std::size_t i = 0; i < n; i += 997) {
    EXPECT_EQ(noise.normal(i), normal[i]);
    EXPECT_EQ(noise.uniform(i), uniform[i]);
  }
  double mean_u = 0.0;
  for (const double u : uniform) {
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    mean_u += u;
  }
  mean_u /= static_cast<double>(n);
  EXPECT_NEAR(mean_u, 0.5, 4.0 * std::sqrt(1.0 / 12.0 / static_cast<double>(n)));
  // Twenty equal bins: chi-square under its 0.1 % critical value for 19 degrees of freedom (43.8).
  std::vector<double> bins(20, 0.0);
  for (const double u : uniform) bins[static_cast<std::size_t>(u * 20.0)] += 1.0;
  double chi2 = 0.0;
  for (const double b : bins) chi2 += (b - n / 20.0) * (b - n / 20.0) / (n / 20.0);
  EXPECT_LT(chi2, 43.8);
  const auto correlation = [&](const auto& a, const auto& b) {
    double ma = 0, mb = 0, sab = 0, saa = 0, sbb = 0;
    for (std::size_t i = 0; i < n; ++i) ma += a(i), mb += b(i);
    ma /= static_cast<double>(n), mb /= static_cast<double>(n);
    for (std::size_t i = 0; i < n; ++i) sab += (a(i) - ma) * (b(i) - mb), saa += (a(i) - ma) * (a(i) - ma), sbb += (b(i) - mb) * (b(i) - mb);
    return sab / std::sqrt(saa * sbb);
  };
  const double bound = 4.0 / std::sqrt(static_cast<double>(n));
  EXPECT_NEAR(correlation([&](std::size_t i) { return std::abs(normal[i]); }, [&](std::size_t i) { return uniform[i]; }), 0.0, bound);
  EXPECT_NEAR(correlation([&](std::size_t i) { return normal[i]; }, [&](std::size_t i) { return normal[(i + 1) % n]; }), 0.0, bound);
  EXPECT_NEAR(correlation([&](std::size_t i) { return normal[i]; }, [&](std::size_t i) { return other.normal(i); }), 0.0, bound) << "another sweep's key";
}

}  // namespace
}  // namespace coloc::sim
