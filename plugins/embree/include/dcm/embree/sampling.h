// Deterministic per-pixel random numbers and the sample warps of the
// integrator. Every exact sample seeds its own generator from the pixel
// coordinates, so a pixel gives the same bits in any batch, order or thread.
#pragma once

#include <cstdint>

#include "dcm/embree/vec3.h"

namespace dcm::embree {

/// A 32-bit integer hash with good avalanche (Jarzynski & Olano 2020, "pcg").
inline uint32_t HashU32(uint32_t v) {
  uint32_t state = v * 747796405u + 2891336453u;
  uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

/// Combines a pixel position and a scene seed into one 64-bit stream seed.
inline uint64_t PixelSeed(int x, int y, uint32_t seed) {
  uint32_t a = HashU32(uint32_t(x) ^ HashU32(uint32_t(y) ^ HashU32(seed)));
  uint32_t b = HashU32(a ^ 0x9e3779b9u);
  return (uint64_t(a) << 32) | b;
}

/// PCG32 (O'Neill 2014): small state, statistically solid, fully deterministic.
class Pcg32 {
 public:
  explicit Pcg32(uint64_t seed, uint64_t stream = 0x14057b7ef767814fULL) {
    inc_ = (stream << 1u) | 1u;
    state_ = 0;
    NextU32();
    state_ += seed;
    NextU32();
  }
  uint32_t NextU32() {
    uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + inc_;
    uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31u));
  }
  /// Uniform in [0, 1).
  float Next() { return float(NextU32() >> 8) * 0x1p-24f; }

 private:
  uint64_t state_;
  uint64_t inc_;
};

/// Van der Corput radical inverse in base 2, in [0, 1).
inline float RadicalInverse2(uint32_t i) {
  i = (i << 16u) | (i >> 16u);
  i = ((i & 0x00ff00ffu) << 8u) | ((i & 0xff00ff00u) >> 8u);
  i = ((i & 0x0f0f0f0fu) << 4u) | ((i & 0xf0f0f0f0u) >> 4u);
  i = ((i & 0x33333333u) << 2u) | ((i & 0xccccccccu) >> 2u);
  i = ((i & 0x55555555u) << 1u) | ((i & 0xaaaaaaaau) >> 1u);
  return float(i >> 8) * 0x1p-24f;
}

/// Sample `i` of `n` of a Hammersley set shifted by (`rx`, `ry`) modulo 1
/// (Cranley-Patterson rotation): stratified in both axes for any n.
inline Vec2 StratifiedSample2D(uint32_t i, uint32_t n, float rx, float ry) {
  float u = (float(i) + 0.5f) / float(n) + rx;
  float v = RadicalInverse2(i) + ry;
  u -= std::floor(u);
  v -= std::floor(v);
  return {std::min(u, 0x1.fffffep-1f), std::min(v, 0x1.fffffep-1f)};
}

/// Cosine-weighted direction around +z; pdf = cos(theta) / pi.
inline Vec3 SampleCosineHemisphere(Vec2 u) {
  float r = std::sqrt(u.x);
  float phi = 2.f * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.f, 1.f - u.x))};
}

/// Direction around +z distributed as cos^e(alpha); pdf = (e+1)/(2 pi) cos^e(alpha).
inline Vec3 SamplePhongLobe(Vec2 u, float exponent) {
  float cosA = std::pow(u.x, 1.f / (exponent + 1.f));
  float sinA = std::sqrt(std::max(0.f, 1.f - cosA * cosA));
  float phi = 2.f * kPi * u.y;
  return {sinA * std::cos(phi), sinA * std::sin(phi), cosA};
}

}  // namespace dcm::embree
