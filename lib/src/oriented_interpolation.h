// Oriented finite elements (paper 2.1, Figure 2): an interior pixel q lies on
// the line through q along the block's direction; the line leaves the block at
// two border points a and b, and L(q) interpolates L(a) and L(b) linearly by
// distance. A border point between two border pixels takes their linear
// interpolation.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

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
  std::array<uint8_t, 4> end{};  ///< which border point (0, 1) each pixel serves
  int count = 0;
};

/// The oriented-element interpolant of interior pixel q (weights sum to 1;
/// zero weights are left out). False when q is not inside the block.
bool OrientedInterpolant(const SampleStore& store, const Block& b, Point2i q, Direction d,
                         Interpolant* out);

/// The oriented elements of one block shape and direction: the interpolant
/// of every interior pixel in block-local coordinates, computed once and
/// shared by all blocks of that shape and direction (the same weights, to
/// the bit, as OrientedInterpolant).
class OrientedElements {
 public:
  /// `width`, `height` in pixel steps (Block::width()).
  OrientedElements(int width, int height, Direction d);
  /// OrientedInterpolant(store, b, q, d, out) for a block `b` of this shape.
  bool At(const SampleStore& store, const Block& b, Point2i q, Interpolant* out) const;

  struct Element {
    int count = -1;  ///< -1: the line through the pixel does not cross the block
    std::array<Point2i, 4> p{};
    std::array<double, 4> weight{};
    std::array<uint8_t, 4> end{};
  };

 private:
  int width_, height_;
  Direction d_;
  std::vector<Element> elements_;  ///< interior pixels, row-major
};

/// True when every pixel of the interpolant serves one border point: the
/// other border point lay on another surface and was left out.
bool OneEnded(const Interpolant& in);

/// The weighted sum of the interpolant's values.
Value Evaluate(const SampleStore& store, const Interpolant& in);

/// The weighted sum of `count` values, with Evaluate's arithmetic (weights
/// in double: a linear ramp is reproduced to float rounding; independent
/// samples: the variances add with the squared weights).
inline Value WeightedSum(const Value* const* values, const double* weights, int count) {
  double a[3] = {0, 0, 0}, bb[3] = {0, 0, 0}, varA = 0, varB = 0;
  for (int k = 0; k < count; ++k) {
    const Value& v = *values[k];
    const double w = weights[k];
    for (int c = 0; c < 3; ++c) {
      a[c] += w * v.a[c];
      bb[c] += w * v.b[c];
    }
    varA += w * w * v.varA;
    varB += w * w * v.varB;
  }
  return {RGB(float(a[0]), float(a[1]), float(a[2])), RGB(float(bb[0]), float(bb[1]), float(bb[2])),
          float(varA), float(varB)};
}

/// Bilinear interpolation of the block's four corners at pixel q.
Value Bilinear(const SampleStore& store, const Block& b, Point2i q);

}  // namespace dcm::detail
