#pragma once
// Each LiDAR ray's own random draws: a pure function of the sweep's key and the ray's index, so that a
// ray's noise depends neither on what the other rays hit nor on how many draws they took, and a ray
// into the sky costs nothing. The bits are SplitMix64's output of the ray's index from a start set by
// the key and the draw's number; the normal draws are a ziggurat of 256 layers on them.
//
// Why not one engine's stream, ray after ray: a sweep of a 32-beam LiDAR is 57,600 rays, and the
// stream had to be drawn for every one of them (hit or not) and a polar method's log and square root
// paid for every point; the noise was a tenth of the twin's CPU.
#include <cmath>
#include <cstdint>

namespace coloc::sim {

/// The ziggurat's layers for the standard normal density's kernel f(x) = exp(-x^2/2): layer i spans
/// heights f(x[i])..f(x[i+1]) at width x[i]; x[0] is the base's width that adds the tail's area,
/// x[1] the tail's start R, x[256] = 0. Every layer has the same area.
struct ZigguratLayers {
  static constexpr int kLayers = 256;
  double x[kLayers + 1];
  double f[kLayers + 1];      ///< f(x[i])
  double inner[kLayers];      ///< x[i+1] / x[i]: a draw below it in magnitude lies under the curve
  double area = 0.0;          ///< each layer's
  /// The layers, computed once (R found by bisection so that the top layer closes at x = 0).
  static const ZigguratLayers& get();
};

class RayNoise {
 public:
  /// `key`: the sweep's, one draw of the drive's own engine.
  explicit RayNoise(std::uint64_t key) : key_(key), layers_(&ZigguratLayers::get()) {}

  /// 64 random bits for `ray`'s draw number `draw` (0..254 for its normal draw, 255 its uniform): the
  /// rays' sequence of each draw number is SplitMix64's from a start of its own.
  std::uint64_t bits(std::uint64_t ray, unsigned draw) const {
    std::uint64_t z = (key_ ^ (draw * 0xd1b54a32d192ed03ULL)) + ray * 0x9e3779b97f4a7c15ULL;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }

  /// A standard normal draw for `ray`: the same for the same key and ray, whatever else is drawn.
  double normal(std::uint64_t ray) const {
    const std::uint64_t h = bits(ray, 0);
    const unsigned layer = static_cast<unsigned>(h & 0xffu);
    // Bits 11-63 the magnitude, bit 8 the sign: apart from the layer's bits, so nothing ties them.
    const double u = static_cast<double>(static_cast<std::int64_t>(h >> 11)) * 0x1p-53;
    if (u < layers_->inner[layer]) {
      const double z = u * layers_->x[layer];
      return (h & 0x100u) ? -z : z;
    }
    return edge(ray, h);
  }

  /// A uniform draw in [0, 1) for `ray`, independent of its normal draw.
  double uniform(std::uint64_t ray) const { return static_cast<double>(static_cast<std::int64_t>(bits(ray, 255) >> 11)) * 0x1p-53; }

 private:
  /// The rare draws outside a layer's inner rectangle: the wedge's test, the tail, another try.
  double edge(std::uint64_t ray, std::uint64_t first) const;

  std::uint64_t key_;
  const ZigguratLayers* layers_;
};

}  // namespace coloc::sim
