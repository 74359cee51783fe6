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

/// True when all three channels are finite (no NaN, no infinity).
inline bool IsFinite(RGB c) {
  return std::isfinite(c.r) && std::isfinite(c.g) && std::isfinite(c.b);
}

}  // namespace dcm
