// Variance of Monte Carlo samples from two independent renders: the squared
// difference of the two halves, pooled over neighbours on the same surface.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "dcm/color.h"
#include "dcm/geometry.h"

namespace dcm {

/// The variance of the weighted mean (nA a + nB b) / (nA + nB) of two
/// independent estimates of one pixel made with nA and nB samples, from that
/// pixel alone: (a - b)^2 nA nB / (nA + nB)^2 ((a - b)^2 / 4 for equal halves).
/// Unbiased but of one degree of freedom per channel: pool it
/// (SurfaceWindowMean) before a test weighs it.
RGB HalvesVariance(RGB a, RGB b, double nA, double nB);

/// The mean of the finite values of `v` (width x height, row-major; NaN or
/// Inf: no value, e.g. a pixel not rendered) over the (2r+1)^2 window around
/// each pixel of `at`, counting only pixels on its surface: equal object and
/// shader IDs where they are given (empty spans: no such guide). Empty `at`:
/// every pixel, in row-major order. A pixel without a finite value in its
/// window gets 0.
std::vector<RGB> SurfaceWindowMean(std::span<const RGB> v, int width, int height,
                                   std::span<const uint32_t> objectId, std::span<const uint32_t> shaderId,
                                   int r, std::span<const Point2i> at = {});

}  // namespace dcm
