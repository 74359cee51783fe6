// The rivals of DCM in `dcm bench`: a uniform grid of exact samples, upsampled
// bilinearly or with joint bilateral upsampling guided by the provider's cheap
// guides (Kopf, Cohen, Lischinski, Uyttendaele 2007, "Joint Bilateral
// Upsampling"). The exact samples are requested through the same
// SampleProvider, in batches of the same size and in parallel as the engine
// does, so that the time in exact evaluation is measured the same way.
//
// Header-only so that it builds with the `dcm` tool (whose CMake globs only
// cmd_*.cpp) and can be unit-tested on its own (tests/bench).
#pragma once

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "common/elapsed.h"
#include "dcm/color.h"
#include "dcm/geometry.h"
#include "dcm/sample_provider.h"
#include "dcm/status.h"

namespace dcm::bench {

/// The two rival upsamplers.
enum class Upsampler { kBilinear, kJointBilateral };

inline std::string_view ToString(Upsampler u) { return u == Upsampler::kBilinear ? "bilinear" : "jbu"; }

/// A separable uniform grid of sample positions covering [0,w) x [0,h),
/// including the first and last row and column.
struct UniformGrid {
  std::vector<int> xs, ys;
  int64_t count() const { return int64_t(xs.size()) * int64_t(ys.size()); }
};

/// Evenly spaced, strictly increasing positions 0 .. size-1 (n >= 1).
inline std::vector<int> EvenPositions(int size, int n) {
  n = std::clamp(n, 1, std::max(1, size));
  std::vector<int> v(size_t(n), 0);
  if (n == 1) return v;
  for (int i = 0; i < n; ++i) v[size_t(i)] = int(std::lround(double(i) * double(size - 1) / double(n - 1)));
  return v;
}

/// The grid with about `budget` points and spacing about equal along both axes.
inline UniformGrid MakeGrid(int width, int height, int64_t budget) {
  const double b = double(std::max<int64_t>(budget, 1));
  const int minX = std::min(2, width), minY = std::min(2, height);
  int nx = std::clamp(int(std::lround(std::sqrt(b * double(width) / double(height)))), minX, width);
  int ny = std::clamp(int(std::lround(b / double(nx))), minY, height);
  // Re-balance nx for the rounded ny (keeps the count closest to the budget).
  nx = std::clamp(int(std::lround(b / double(ny))), minX, width);
  UniformGrid g;
  g.xs = EvenPositions(width, nx);
  g.ys = EvenPositions(height, ny);
  return g;
}

/// Parameters of joint bilateral upsampling. Distances are in grid spacings
/// (low-resolution pixels): Kopf et al. use a spatial Gaussian of sigma 0.5 on
/// a 5x5 window; here a 4x4 window around the pixel's grid cell, so that the
/// guide can pull values from beyond the nearest grid neighbours.
struct JbuParams {
  double spatialSigma = 0.5;     ///< spatial Gaussian, in grid spacings
  int radius = 2;                ///< window half-size in grid cells (4x4 samples for 2)
  double tauSigma = 0.05;        ///< range Gaussian on the texture value tau (RGB distance)
  double idMismatch = 1e-4;      ///< range weight factor when object or shader ID differs
};

/// One rival reconstruction of the working image.
struct RivalResult {
  int width = 0, height = 0;   ///< working resolution
  std::vector<RGB> workImage;  ///< row-major
  int64_t exactPixels = 0;
  double timeIllumS = 0;   ///< in the provider's Evaluate()
  double timeGuidesS = 0;  ///< in the provider's Guides()
  double timeEngineS = 0;  ///< the upsampling itself
  double wallS = 0;
};

namespace detail {

/// Index i of the grid interval [pos[i], pos[i+1]] that contains p (the last
/// interval for p at the end), and the fraction along it.
inline void Locate(const std::vector<int>& pos, int p, int* i, double* t) {
  if (pos.size() < 2) {
    *i = 0;
    *t = 0;
    return;
  }
  auto it = std::upper_bound(pos.begin(), pos.end(), p);
  int k = int(it - pos.begin()) - 1;
  k = std::clamp(k, 0, int(pos.size()) - 2);
  *i = k;
  *t = double(p - pos[size_t(k)]) / double(pos[size_t(k) + 1] - pos[size_t(k)]);
}

}  // namespace detail

/// Evaluates the grid through `provider` (batches of `batchSize`, in parallel
/// on `threads` threads (0: all) when the provider is thread safe) and
/// upsamples to the provider's working resolution.
inline Status RunRival(SampleProvider& provider, Upsampler kind, int64_t budget, int threads, RivalResult* out,
                       const JbuParams& jp = {}, int batchSize = 4096) {
  using Clock = std::chrono::steady_clock;
  const auto tStart = Clock::now();
  const ProviderCapabilities caps = provider.Capabilities();
  const int W = caps.width, H = caps.height;
  if (W < 1 || H < 1) return Status::Error("provider '" + caps.name + "' reports an empty image");
  const UniformGrid grid = MakeGrid(W, H, budget);
  const int nx = int(grid.xs.size()), ny = int(grid.ys.size());
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);

  // Exact samples of the grid, row-major over the grid.
  std::vector<Point2i> pixels;
  pixels.reserve(size_t(grid.count()));
  for (int y : grid.ys)
    for (int x : grid.xs) pixels.push_back({x, y});
  std::vector<ExactSample> samples(pixels.size());
  const size_t batch = size_t(std::max(1, batchSize));
  const size_t nbatches = (pixels.size() + batch - 1) / batch;
  std::vector<Status> results(nbatches);
  auto run = [&](size_t bi) {
    const size_t begin = bi * batch, end = std::min(pixels.size(), begin + batch);
    results[bi] = provider.Evaluate(std::span<const Point2i>(pixels).subspan(begin, end - begin), SampleRequest{},
                                    std::span<ExactSample>(samples).subspan(begin, end - begin));
  };
  auto t0 = Clock::now();
  if (caps.threadSafe && nbatches > 1) {
    arena.execute([&] { tbb::parallel_for(size_t(0), nbatches, run); });
  } else {
    for (size_t bi = 0; bi < nbatches; ++bi) run(bi);
  }
  out->timeIllumS = toolkit::SecondsSince(t0);
  for (const Status& s : results) {
    if (s.pending()) return Status::Error("provider '" + caps.name + "' cannot evaluate pixels now (sparse input)");
    if (!s.ok()) return s;
  }
  auto S = [&](int i, int j) -> const RGB& { return samples[size_t(j) * size_t(nx) + size_t(i)].L; };

  // Guides for joint bilateral upsampling: every pixel (the guide image).
  GuideImage guides;
  out->timeGuidesS = 0;
  const bool jbu = kind == Upsampler::kJointBilateral;
  if (jbu) {
    GuideRequest want;
    want.objectId = caps.objectId;
    want.shaderId = caps.shaderId;
    want.texture = caps.texture;
    if (want.objectId || want.shaderId || want.texture) {
      t0 = Clock::now();
      DCM_RETURN_IF_ERROR(provider.Guides(Bounds2i{{0, 0}, {W, H}}, want, &guides));
      out->timeGuidesS = toolkit::SecondsSince(t0);
      const size_t n = size_t(W) * size_t(H);
      if ((want.objectId && guides.objectId.size() != n) || (want.shaderId && guides.shaderId.size() != n) ||
          (want.texture && guides.texture.size() != n)) {
        return Status::Error("provider '" + caps.name + "' returned guides of the wrong size");
      }
    }
  }

  t0 = Clock::now();
  out->width = W;
  out->height = H;
  out->workImage.assign(size_t(W) * size_t(H), RGB{});
  // Per column and row: the grid interval and the fraction along it.
  std::vector<int> ix(static_cast<size_t>(W)), iy(static_cast<size_t>(H));
  std::vector<double> tx(static_cast<size_t>(W)), ty(static_cast<size_t>(H));
  for (int x = 0; x < W; ++x) detail::Locate(grid.xs, x, &ix[size_t(x)], &tx[size_t(x)]);
  for (int y = 0; y < H; ++y) detail::Locate(grid.ys, y, &iy[size_t(y)], &ty[size_t(y)]);
  const double spacingX = nx > 1 ? double(W - 1) / double(nx - 1) : 1.0;
  const double spacingY = ny > 1 ? double(H - 1) / double(ny - 1) : 1.0;
  const bool haveObj = !guides.objectId.empty(), haveShader = !guides.shaderId.empty();
  const bool haveTau = !guides.texture.empty();
  const double inv2ss = 1.0 / (2.0 * jp.spatialSigma * jp.spatialSigma);
  const double inv2ts = 1.0 / (2.0 * jp.tauSigma * jp.tauSigma);

  auto bilinear = [&](int x, int y) {
    const int i = ix[size_t(x)], j = iy[size_t(y)];
    const double u = tx[size_t(x)], v = ty[size_t(y)];
    const int i1 = std::min(i + 1, nx - 1), j1 = std::min(j + 1, ny - 1);
    double c[3];
    for (int k = 0; k < 3; ++k) {
      c[k] = (1 - u) * (1 - v) * double(S(i, j)[k]) + u * (1 - v) * double(S(i1, j)[k]) +
             (1 - u) * v * double(S(i, j1)[k]) + u * v * double(S(i1, j1)[k]);
    }
    return RGB(float(c[0]), float(c[1]), float(c[2]));
  };
  auto jointBilateral = [&](int x, int y) {
    const size_t p = size_t(y) * size_t(W) + size_t(x);
    const int i0 = ix[size_t(x)], j0 = iy[size_t(y)];
    double acc[3] = {0, 0, 0}, wsum = 0;
    for (int j = std::max(0, j0 - jp.radius + 1); j <= std::min(ny - 1, j0 + jp.radius); ++j) {
      const int gy = grid.ys[size_t(j)];
      const double dy = double(y - gy) / spacingY;
      for (int i = std::max(0, i0 - jp.radius + 1); i <= std::min(nx - 1, i0 + jp.radius); ++i) {
        const int gx = grid.xs[size_t(i)];
        const double dx = double(x - gx) / spacingX;
        double w = std::exp(-(dx * dx + dy * dy) * inv2ss);
        const size_t q = size_t(gy) * size_t(W) + size_t(gx);
        if (haveObj && guides.objectId[q] != guides.objectId[p]) w *= jp.idMismatch;
        if (haveShader && guides.shaderId[q] != guides.shaderId[p]) w *= jp.idMismatch;
        if (haveTau) {
          const RGB d = guides.texture[q] - guides.texture[p];
          const double d2 = double(d.r) * d.r + double(d.g) * d.g + double(d.b) * d.b;
          w *= std::exp(-d2 * inv2ts);
        }
        const RGB& s = S(i, j);
        acc[0] += w * s.r;
        acc[1] += w * s.g;
        acc[2] += w * s.b;
        wsum += w;
      }
    }
    if (!(wsum > 1e-300)) return bilinear(x, y);
    return RGB(float(acc[0] / wsum), float(acc[1] / wsum), float(acc[2] / wsum));
  };

  arena.execute([&] {
    tbb::parallel_for(0, H, [&](int y) {
      for (int x = 0; x < W; ++x) {
        out->workImage[size_t(y) * size_t(W) + size_t(x)] = jbu ? jointBilateral(x, y) : bilinear(x, y);
      }
    });
  });
  // Grid pixels are exact: keep their bits.
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      out->workImage[size_t(grid.ys[size_t(j)]) * size_t(W) + size_t(grid.xs[size_t(i)])] = S(i, j);
  out->timeEngineS = toolkit::SecondsSince(t0);
  out->exactPixels = grid.count();
  out->wallS = toolkit::SecondsSince(tStart);
  return Status::Ok();
}

}  // namespace dcm::bench
