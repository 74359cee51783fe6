// Variance from two independent renders (docs/NOISE.md): the AOV provider's
// --second-render and dcm blender's exact pixels rendered as two halves; and
// from one render alone (--estimate-variance, detected noise).
#include "dcm/noise_estimate.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <tbb/parallel_for.h>

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

std::vector<RGB> VarianceFromOneRender(std::span<const RGB> v, int width, int height,
                                       std::span<const uint32_t> objectId, std::span<const uint32_t> shaderId) {
  const size_t n = size_t(width) * size_t(height);
  const float f = kRelativeVarianceFloor;
  auto at = [&](int x, int y) { return size_t(y) * size_t(width) + size_t(x); };
  auto same = [&](size_t i, size_t j) {
    return (objectId.empty() || objectId[i] == objectId[j]) && (shaderId.empty() || shaderId[i] == shaderId[j]);
  };
  auto scale = [&](size_t i) { return RGB{std::fabs(v[i].r) + f, std::fabs(v[i].g) + f, std::fabs(v[i].b) + f}; };
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  constexpr std::array<std::array<int, 2>, 4> kDirections{{{1, 0}, {0, 1}, {1, 1}, {1, -1}}};
  // The neighbours (a, b) of (x, y) along direction k, both on its surface
  // and finite with it; false where there are none.
  auto pair = [&](int x, int y, size_t k, size_t* a, size_t* b) {
    const auto [dx, dy] = kDirections[k];
    const int ax = x - dx, ay = y - dy, bx = x + dx, by = y + dy;
    if (ax < 0 || bx >= width || ay < 0 || ay >= height || by < 0 || by >= height) return false;
    const size_t i = at(x, y);
    *a = at(ax, ay), *b = at(bx, by);
    return IsFinite(v[i]) && IsFinite(v[*a]) && IsFinite(v[*b]) && same(i, *a) && same(i, *b);
  };
  // The structure: a 3x3 box blur, whose directions of change are the
  // image's (an edge, a line) while its noise, a ninth of the pixel's own
  // variance, hardly decides them.
  std::vector<RGB> blur(n, RGB::Gray(kNaN));
  tbb::parallel_for(0, height, [&](int y) {
    for (int x = 0; x < width; ++x) {
      RGB sum;
      int count = 0;
      for (int ny = std::max(0, y - 1); ny <= std::min(height - 1, y + 1); ++ny)
        for (int nx = std::max(0, x - 1); nx <= std::min(width - 1, x + 1); ++nx)
          if (IsFinite(v[at(nx, ny)])) sum += v[at(nx, ny)], ++count;
      if (count) blur[at(x, y)] = sum * (1.f / float(count));
    }
  });
  // Per direction, the blur's residual squared relative to |v| + f, summed
  // over the channels (NaN where the pixel has no such pair).
  std::array<std::vector<float>, 4> energy;
  for (size_t k = 0; k < kDirections.size(); ++k) {
    energy[k].assign(n, kNaN);
    tbb::parallel_for(0, height, [&](int y) {
      for (int x = 0; x < width; ++x) {
        size_t a, b;
        if (!pair(x, y, k, &a, &b)) continue;
        const size_t i = at(x, y);
        const RGB r = blur[i] - (blur[a] + blur[b]) * 0.5f, s = scale(i);
        energy[k][i] = r.r * r.r / s.r + r.g * r.g / s.g + r.b * r.b / s.b;
      }
    });
  }
  blur = {};
  // Per pixel, the residual along the direction of the blur's smallest mean
  // energy over the 3x3 neighbourhood, squared relative to |v| + f over 1.5
  // (the variance of one residual of white noise, per unit variance).
  std::vector<RGB> q(n, RGB::Gray(kNaN));
  tbb::parallel_for(0, height, [&](int y) {
    for (int x = 0; x < width; ++x) {
      const size_t i = at(x, y);
      double best = std::numeric_limits<double>::infinity();
      size_t chosen = kDirections.size();
      for (size_t k = 0; k < kDirections.size(); ++k) {
        if (std::isnan(energy[k][i])) continue;
        double sum = 0;
        int count = 0;
        for (int ny = std::max(0, y - 1); ny <= std::min(height - 1, y + 1); ++ny)
          for (int nx = std::max(0, x - 1); nx <= std::min(width - 1, x + 1); ++nx) {
            const float e = energy[k][at(nx, ny)];
            if (!std::isnan(e)) sum += e, ++count;
          }
        if (sum / count < best) best = sum / count, chosen = k;
      }
      size_t a, b;
      if (chosen == kDirections.size() || !pair(x, y, chosen, &a, &b)) continue;
      const RGB r = v[i] - (v[a] + v[b]) * 0.5f, s = scale(i);
      for (int c = 0; c < 3; ++c) q[i][c] = r[c] * r[c] / (1.5f * s[c]);
    }
  });
  energy = {};
  constexpr int kRadius = 3;  // the 7x7 window of kOneRenderMedian
  std::vector<RGB> out(n);
  tbb::parallel_for(0, height, [&](int y) {
    std::vector<float> window;
    window.reserve((2 * kRadius + 1) * (2 * kRadius + 1));
    for (int x = 0; x < width; ++x) {
      const size_t i = at(x, y);
      if (!IsFinite(v[i])) continue;
      const RGB s = scale(i);
      for (int c = 0; c < 3; ++c) {
        window.clear();
        for (int ny = std::max(0, y - kRadius); ny <= std::min(height - 1, y + kRadius); ++ny)
          for (int nx = std::max(0, x - kRadius); nx <= std::min(width - 1, x + kRadius); ++nx) {
            const size_t j = at(nx, ny);
            if (same(i, j) && !std::isnan(q[j][c])) window.push_back(q[j][c]);
          }
        if (window.empty()) continue;
        const auto mid = window.begin() + std::ptrdiff_t(window.size() / 2);
        std::nth_element(window.begin(), mid, window.end());
        double median = *mid;
        if (window.size() % 2 == 0) median = 0.5 * (median + double(*std::max_element(window.begin(), mid)));
        out[i][c] = float(median / kOneRenderMedian * double(s[c]));
      }
    }
  });
  return out;
}

}  // namespace dcm
