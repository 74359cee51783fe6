// Variance from two independent renders (docs/NOISE.md): the AOV provider's
// --second-render and dcm blender's exact pixels rendered as two halves.
#include "dcm/noise_estimate.h"

#include <algorithm>
#include <cmath>

namespace dcm {

RGB HalvesVariance(RGB a, RGB b, double nA, double nB) {
  const RGB d = a - b;
  const float k = float(nA * nB / ((nA + nB) * (nA + nB)));
  return d * d * k;
}

namespace {

/// The window mean of SurfaceWindowMean; with `L`, the window's sum of v over
/// its sum of |L| + f, times the pixel's own |L| + f.
std::vector<RGB> WindowMean(std::span<const RGB> v, std::span<const RGB> L, int width, int height,
                            std::span<const uint32_t> objectId, std::span<const uint32_t> shaderId, int r,
                            std::span<const Point2i> at) {
  const size_t n = at.empty() ? size_t(width) * size_t(height) : at.size();
  const bool relative = !L.empty();
  const double f = kRelativeVarianceFloor;
  std::vector<RGB> out(n);
  auto same = [&](size_t i, size_t j) {
    return (objectId.empty() || objectId[i] == objectId[j]) && (shaderId.empty() || shaderId[i] == shaderId[j]);
  };
  for (size_t k = 0; k < n; ++k) {
    const int x = at.empty() ? int(k % size_t(width)) : at[k].x;
    const int y = at.empty() ? int(k / size_t(width)) : at[k].y;
    const size_t i = size_t(y) * size_t(width) + size_t(x);
    if (relative && !IsFinite(L[i])) continue;
    double sum[3] = {}, norm[3] = {};
    int count = 0;
    for (int ny = std::max(0, y - r); ny <= std::min(height - 1, y + r); ++ny)
      for (int nx = std::max(0, x - r); nx <= std::min(width - 1, x + r); ++nx) {
        const size_t j = size_t(ny) * size_t(width) + size_t(nx);
        if (!IsFinite(v[j]) || !same(i, j) || (relative && !IsFinite(L[j]))) continue;
        for (int c = 0; c < 3; ++c) {
          sum[c] += double(v[j][c]);
          norm[c] += relative ? std::fabs(double(L[j][c])) + f : 1.0;
        }
        ++count;
      }
    if (!count) continue;
    for (int c = 0; c < 3; ++c)
      out[k][c] = float(sum[c] / norm[c] * (relative ? std::fabs(double(L[i][c])) + f : 1.0));
  }
  return out;
}

}  // namespace

std::vector<RGB> SurfaceWindowMean(std::span<const RGB> v, int width, int height,
                                   std::span<const uint32_t> objectId, std::span<const uint32_t> shaderId,
                                   int r, std::span<const Point2i> at) {
  return WindowMean(v, {}, width, height, objectId, shaderId, r, at);
}

std::vector<RGB> SurfaceWindowRelativeMean(std::span<const RGB> v, std::span<const RGB> L, int width, int height,
                                           std::span<const uint32_t> objectId, std::span<const uint32_t> shaderId,
                                           int r, std::span<const Point2i> at) {
  return WindowMean(v, L, width, height, objectId, shaderId, r, at);
}

}  // namespace dcm
