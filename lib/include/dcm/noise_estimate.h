// Variance of Monte Carlo samples: from two independent renders (the squared
// difference of the two halves, pooled over neighbours on the same surface)
// or from one render alone.
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

/// The variance of noisy values `v` (width x height, row-major, in v's units)
/// estimated from the one image alone, for a render without a variance
/// channel; IDs as SurfaceWindowMean's. Per pixel and channel, the residual
/// against the mean of its two neighbours along one of four directions
/// (horizontal, vertical, both diagonals; both on its surface): the direction
/// along which a 3x3 box blur of the image changes least over the pixel's 3x3
/// neighbourhood, relative to |v| + f (f: kRelativeVarianceFloor). An edge or
/// a line has a direction along which it does not change, noise has none,
/// and the blur's own noise (a ninth of the variance) hardly decides which:
/// the residual keeps the variance of noise alone, beside an edge as
/// elsewhere. Then the median over the 7x7 window on the pixel's surface of
/// the squared residual relative to |v| + f, over kOneRenderMedian, times the
/// pixel's |v| + f: detail that covers less than half of a window (a corner,
/// a highlight of a few pixels) does not move a median, noise over an area
/// does, and a noise level that changes across the image is followed window
/// by window. Each channel alone. Not seen: noise in single pixels
/// (fireflies); and texture at the pixel scale is taken for noise (pass the
/// texture-free part, e.g. L_i of the texture split). A pixel that is not
/// finite, or has no value in its window, gets 0.
std::vector<RGB> VarianceFromOneRender(std::span<const RGB> v, int width, int height,
                                       std::span<const uint32_t> objectId, std::span<const uint32_t> shaderId);

/// The mean, per unit variance, of VarianceFromOneRender's window median of
/// the squared relative residual over an image of white noise: about the
/// median of a chi-square of one degree of freedom (0.455) a little raised
/// by the median of 49 values and lowered by the choice of direction
/// (simulated on 3.5 10^4 pixels with R, G and B correlated by 0.9, as a
/// renderer's are: 0.93 between R and G in the difference of two Cycles
/// renders of the tuning room; identical channels give the same, independent
/// ones 6 % more).
/// NoiseEstimate.VarianceFromOneRenderOfWhiteNoise checks it.
inline constexpr double kOneRenderMedian = 0.42;

}  // namespace dcm
