// Variance of Monte Carlo samples from two independent renders: the squared
// difference of the two halves, pooled over neighbours on the same surface.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "dcm/color.h"
#include "dcm/geometry.h"

namespace dcm {

/// Samples whose noise alone costs less than this PSNR (dB, display-referred,
/// against the noise-free image) are noisy enough for the engine's noise
/// regime: noise within 2 dB of the 40-dB targets of docs/QUALITY.md decides
/// what a reconstruction from them can reach; below it, weighing the noise
/// pays, above it the regime's denser lattice costs more than it brings
/// (docs/NOISE.md). Used by the AOV provider's noise detection and dcm
/// blender's choice to give the engine its pixels' variance.
inline constexpr double kNoisyPsnr = 42;

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

/// What SurfaceWindowRelativeMean adds to every |value| (linear,
/// scene-referred): a tenth of sRGB's linear segment, where the display no
/// longer tells a value from 0; it keeps a window of black pixels defined.
inline constexpr float kRelativeVarianceFloor = 3e-4f;

/// The variance `v` of values `L` (both width x height, row-major) pooled over
/// the window SurfaceWindowMean pools over, as a share of the value: per
/// channel, the window's sum of v over its sum of |L| + f, times |L| + f at the
/// pixel itself (f: kRelativeVarianceFloor). A Monte Carlo estimate's
/// variance grows with its value; the window mean of the variance itself
/// gives a dark pixel the variance of a bright neighbour (a highlight, a
/// caustic), which the display's steep slope at dark values then magnifies
/// (docs/NOISE.md, "Pooling the variance"). A ratio of sums, not a mean of
/// ratios: no pixel's noisy value near 0 divides. A pixel whose `v` or `L` is
/// not finite gives no value.
std::vector<RGB> SurfaceWindowRelativeMean(std::span<const RGB> v, std::span<const RGB> L, int width, int height,
                                           std::span<const uint32_t> objectId, std::span<const uint32_t> shaderId,
                                           int r, std::span<const Point2i> at = {});

}  // namespace dcm
