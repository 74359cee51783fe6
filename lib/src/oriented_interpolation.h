// Oriented finite elements (paper 2.1, Figure 2): an interior pixel q lies on
// the line through q along the block's direction; the line leaves the block at
// two border points a and b, and L(q) interpolates L(a) and L(b) linearly by
// distance. A border point between two border pixels takes their linear
// interpolation.
#pragma once

#include <array>
#include <cstdint>

#include "block.h"
#include "sample_store.h"

namespace dcm::detail {

/// Unit direction theta_k = k*pi/K (k = 0: along +x; y grows downwards).
struct Direction {
  double dx = 1, dy = 0;
  static Direction Of(int k, int count);
};

/// Where a ray leaves a block: the border pixels p0, p1 around the exit point
/// and the weight w1 of p1; `t` is the distance along the ray.
struct BorderPoint {
  Point2i p0, p1;
  double w1 = 0;
  double t = 0;
};

/// The first point where the ray from (px, py) along `d` leaves the block,
/// provided the ray runs through the block's interior (not along its border).
bool ExitPoint(const Block& b, double px, double py, Direction d, BorderPoint* out);

/// Up to four border pixels and their weights that interpolate pixel q.
struct Interpolant {
  std::array<int64_t, 4> index{};
  std::array<double, 4> weight{};
  int count = 0;
};

/// The oriented-element interpolant of interior pixel q (weights sum to 1;
/// zero weights are left out). False when q is not inside the block.
bool OrientedInterpolant(const SampleStore& store, const Block& b, Point2i q, Direction d,
                         Interpolant* out);

/// The weighted sum of the interpolant's values.
Value Evaluate(const SampleStore& store, const Interpolant& in);

/// Bilinear interpolation of the block's four corners at pixel q.
Value Bilinear(const SampleStore& store, const Block& b, Point2i q);

}  // namespace dcm::detail
