// Small 3-vector and 2-vector math for the internal ray tracer.
#pragma once

#include <algorithm>
#include <cmath>

namespace dcm::embree {

inline constexpr float kPi = 3.14159265358979323846f;

/// A 3-vector of floats: points, directions, normals.
struct Vec3 {
  float x = 0.f, y = 0.f, z = 0.f;

  Vec3() = default;
  constexpr Vec3(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}

  float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }

  friend Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
  friend Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
  friend Vec3 operator-(Vec3 a) { return {-a.x, -a.y, -a.z}; }
  friend Vec3 operator*(Vec3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
  friend Vec3 operator*(float s, Vec3 a) { return a * s; }
  friend Vec3 operator*(Vec3 a, Vec3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
  friend Vec3 operator/(Vec3 a, float s) { return a * (1.f / s); }
  Vec3& operator+=(Vec3 o) { x += o.x; y += o.y; z += o.z; return *this; }
  friend bool operator==(const Vec3&, const Vec3&) = default;
};

inline float Dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 Cross(Vec3 a, Vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float Length(Vec3 a) { return std::sqrt(Dot(a, a)); }
/// Unit vector along `a`; the zero vector stays zero.
inline Vec3 Normalize(Vec3 a) {
  float l = Length(a);
  return l > 0.f ? a / l : a;
}
inline Vec3 Min(Vec3 a, Vec3 b) { return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)}; }
inline Vec3 Max(Vec3 a, Vec3 b) { return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)}; }
/// Mirror reflection of the direction `d` (pointing at the surface) about `n`.
inline Vec3 Reflect(Vec3 d, Vec3 n) { return d - n * (2.f * Dot(d, n)); }

/// An orthonormal frame around a unit vector `n` (Duff et al. 2017).
struct Frame {
  Vec3 s, t, n;
  explicit Frame(Vec3 n_) : n(n_) {
    float sign = std::copysign(1.f, n.z);
    float a = -1.f / (sign + n.z);
    float b = n.x * n.y * a;
    s = {1.f + sign * n.x * n.x * a, sign * b, -sign * n.x};
    t = {b, sign + n.y * n.y * a, -n.y};
  }
  Vec3 ToWorld(Vec3 v) const { return s * v.x + t * v.y + n * v.z; }
};

/// A 2-vector of floats (texture coordinates).
struct Vec2 {
  float x = 0.f, y = 0.f;
  friend Vec2 operator+(Vec2 a, Vec2 b) { return {a.x + b.x, a.y + b.y}; }
  friend Vec2 operator-(Vec2 a, Vec2 b) { return {a.x - b.x, a.y - b.y}; }
  friend Vec2 operator*(Vec2 a, float s) { return {a.x * s, a.y * s}; }
};

}  // namespace dcm::embree
