// Integer pixel coordinates and half-open pixel regions.
#pragma once

#include <algorithm>
#include <cstdint>

namespace dcm {

/// A pixel position (x to the right, y down), in the working (possibly
/// supersampled) image.
struct Point2i {
  int x = 0;
  int y = 0;
  friend bool operator==(const Point2i&, const Point2i&) = default;
};

/// A direction in 3-D (surface normals of the guides), in any consistent space.
struct Vec3f {
  float x = 0.f, y = 0.f, z = 0.f;
};

/// A half-open pixel region [min.x, max.x) x [min.y, max.y).
struct Bounds2i {
  Point2i min;
  Point2i max;

  int width() const { return std::max(0, max.x - min.x); }
  int height() const { return std::max(0, max.y - min.y); }
  int64_t area() const { return int64_t(width()) * height(); }
  bool empty() const { return width() == 0 || height() == 0; }
  bool contains(Point2i p) const {
    return p.x >= min.x && p.x < max.x && p.y >= min.y && p.y < max.y;
  }
  /// Index of p in a row-major array that covers this region.
  int64_t offset(Point2i p) const {
    return int64_t(p.y - min.y) * width() + (p.x - min.x);
  }
  friend bool operator==(const Bounds2i&, const Bounds2i&) = default;
};

/// Intersection of two regions (empty when they do not overlap).
inline Bounds2i Intersect(const Bounds2i& a, const Bounds2i& b) {
  Bounds2i r{{std::max(a.min.x, b.min.x), std::max(a.min.y, b.min.y)},
             {std::min(a.max.x, b.max.x), std::min(a.max.y, b.max.y)}};
  if (r.max.x < r.min.x) r.max.x = r.min.x;
  if (r.max.y < r.min.y) r.max.y = r.min.y;
  return r;
}

}  // namespace dcm
