// A linear RGB triple and the few operations the engine needs on it.
#pragma once

#include <cmath>

namespace dcm {

/// Linear, scene-referred RGB radiance (or a texture value, or a variance).
struct RGB {
  float r = 0.f, g = 0.f, b = 0.f;

  RGB() = default;
  constexpr RGB(float r_, float g_, float b_) : r(r_), g(g_), b(b_) {}
  static constexpr RGB Gray(float v) { return {v, v, v}; }

  float& operator[](int i) { return i == 0 ? r : (i == 1 ? g : b); }
  float operator[](int i) const { return i == 0 ? r : (i == 1 ? g : b); }

  friend RGB operator+(RGB a, RGB b) { return {a.r + b.r, a.g + b.g, a.b + b.b}; }
  friend RGB operator-(RGB a, RGB b) { return {a.r - b.r, a.g - b.g, a.b - b.b}; }
  friend RGB operator*(RGB a, RGB b) { return {a.r * b.r, a.g * b.g, a.b * b.b}; }
  friend RGB operator*(RGB a, float s) { return {a.r * s, a.g * s, a.b * s}; }
  friend RGB operator*(float s, RGB a) { return a * s; }
  RGB& operator+=(RGB o) { r += o.r; g += o.g; b += o.b; return *this; }
  friend bool operator==(const RGB&, const RGB&) = default;
};

/// Rec. 709 luminance of linear RGB.
inline float Luminance(RGB c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }

/// sRGB encoding (IEC 61966-2-1) of a linear value clipped to [0,1]; NaN
/// encodes as 0. The display units of tolerances and PSNR.
inline float SrgbEncode(float linear) {
  if (!(linear > 0.f)) return 0.f;
  if (linear >= 1.f) return 1.f;
  if (linear <= 0.0031308f) return 12.92f * linear;
  return 1.055f * std::pow(linear, 1.f / 2.4f) - 0.055f;
}

/// How much a relative change of a linear value moves its sRGB encoding:
/// x * d(SrgbEncode)/dx at x clipped to [0,1] (0 at and below 0; above 1
/// the slope at 1, the brightest value a display shows).
inline float SrgbRelativeSlope(float linear) {
  if (!(linear > 0.f)) return 0.f;
  if (linear > 1.f) linear = 1.f;
  if (linear <= 0.0031308f) return 12.92f * linear;
  return 1.055f / 2.4f * std::pow(linear, 1.f / 2.4f);
}

/// True when all three channels are finite (no NaN, no infinity). `&`, not
/// `&&`: three compares without branches, which loops over pixels vectorise.
inline bool IsFinite(RGB c) {
  return std::isfinite(c.r) & std::isfinite(c.g) & std::isfinite(c.b);
}

}  // namespace dcm
