#include "coloc/sim/ray_noise.hpp"

namespace coloc::sim {

namespace {

double kernel(double x) { return std::exp(-0.5 * x * x); }

// The layers from a tail's start r; `closes` says whether the top layer's height reached 1 before the
// last layer (r too small) or not.
void build(double r, ZigguratLayers& z, bool& too_small) {
  constexpr int n = ZigguratLayers::kLayers;
  const double tail = std::sqrt(M_PI / 2.0) * std::erfc(r / std::sqrt(2.0));
  z.area = r * kernel(r) + tail;
  z.x[0] = z.area / kernel(r);
  z.x[1] = r;
  too_small = false;
  for (int i = 1; i < n; ++i) {
    const double height = kernel(z.x[i]) + z.area / z.x[i];
    if (height >= 1.0) {  // the curve's top reached before the last layer
      too_small = true;
      for (int j = i + 1; j <= n; ++j) z.x[j] = 0.0;
      return;
    }
    z.x[i + 1] = std::sqrt(-2.0 * std::log(height));
  }
  z.x[n] = 0.0;
}

ZigguratLayers makeLayers() {
  ZigguratLayers z;
  constexpr int n = ZigguratLayers::kLayers;
  // A larger r makes every layer thinner; the one that closes the last layer at the top is between.
  double lo = 2.0, hi = 5.0;
  bool too_small = false;
  for (int k = 0; k < 200; ++k) {
    const double mid = 0.5 * (lo + hi);
    build(mid, z, too_small);
    (too_small ? lo : hi) = mid;
  }
  build(hi, z, too_small);
  z.x[n] = 0.0;
  for (int i = 0; i <= n; ++i) z.f[i] = kernel(z.x[i]);
  z.f[0] = kernel(z.x[1]);  // the base's height is the tail's start's
  for (int i = 0; i < n; ++i) z.inner[i] = z.x[i + 1] / z.x[i];
  return z;
}

}  // namespace

const ZigguratLayers& ZigguratLayers::get() {
  static const ZigguratLayers layers = makeLayers();
  return layers;
}

double RayNoise::edge(std::uint64_t ray, std::uint64_t first) const {
  const ZigguratLayers& z = *layers_;
  const auto open = [](std::uint64_t h) { return (static_cast<double>(static_cast<std::int64_t>(h >> 11)) + 0.5) * 0x1p-53; };
  std::uint64_t h = first;
  unsigned draw = 0;
  // Draws 1..254 serve the retries; one try in a hundred needs any, so the counter never runs out in
  // practice (it wraps within the ray's own draws if it did).
  const auto next = [&] { return bits(ray, 1 + (draw++ % 254)); };
  for (;;) {
    const unsigned layer = static_cast<unsigned>(h & 0xffu);
    const bool negative = (h & 0x100u) != 0;
    const double u = static_cast<double>(static_cast<std::int64_t>(h >> 11)) * 0x1p-53;
    const double x = u * z.x[layer];
    if (u < z.inner[layer]) return negative ? -x : x;
    if (layer == 0) {
      // Beyond R: Marsaglia's exponential test on the tail.
      const double r = z.x[1];
      double a, b;
      do {
        a = -std::log(open(next())) / r;
        b = -std::log(open(next()));
      } while (b + b < a * a);
      return negative ? -(r + a) : r + a;
    }
    // In the wedge between the layer's inner rectangle and its outer: under the curve, or try again.
    const double y = z.f[layer] + open(next()) * (z.f[layer + 1] - z.f[layer]);
    if (y < kernel(x)) return negative ? -x : x;
    h = next();
  }
}

}  // namespace coloc::sim
