#include "sample_denoising.h"

#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>
#include <vector>

namespace dcm::detail {

namespace {

struct Neighbour {
  int64_t index;
  double x, y, w;  ///< offset in units of the radius, weight
};

/// Solves the symmetric 3x3 system M g = e0; false when M is singular.
bool SolveFirstColumn(const double M[3][3], double g[3]) {
  const double c00 = M[1][1] * M[2][2] - M[1][2] * M[2][1];
  const double c01 = M[1][2] * M[2][0] - M[1][0] * M[2][2];
  const double c02 = M[1][0] * M[2][1] - M[1][1] * M[2][0];
  const double det = M[0][0] * c00 + M[0][1] * c01 + M[0][2] * c02;
  if (!(std::fabs(det) > 1e-12)) return false;
  // First column of the inverse (M is symmetric: first row of cofactors / det).
  g[0] = c00 / det, g[1] = c01 / det, g[2] = c02 / det;
  return true;
}

/// Every channel within k times kColourGate luminance standard deviations:
/// the luminance test alone averages colours of equal luminance (a red and a
/// blue texel). 2 lies above the 1.33 sd of a channel whose noise is
/// independent of the others' (grey noise does not trip it).
constexpr float kColourGate = 2.f;

bool SameColour(const Value& p, const Value& q, float k) {
  const float sa = k * kColourGate * std::sqrt(p.varA + q.varA), sb = k * kColourGate * std::sqrt(p.varB + q.varB);
  for (int c = 0; c < 3; ++c)
    if (std::fabs(p.a[c] - q.a[c]) > sa || std::fabs(p.b[c] - q.b[c]) > sb) return false;
  return true;
}

}  // namespace

int64_t DenoiseExactSamples(SampleStore& store, int radius, const ContrastTest& noise, float gate) {
  if (!store.hasVariance() || radius < 1) return 0;
  const int W = store.width(), H = store.height();
  const SurfaceTest& surfaces = store.surfaces();
  const double sd = 0.5 * radius;
  std::vector<std::vector<std::pair<int64_t, Value>>> rows(static_cast<size_t>(H));
  std::atomic<int64_t> replaced{0};

  tbb::parallel_for(0, H, [&](int y) {
    std::vector<Neighbour> near;
    for (int x = 0; x < W; ++x) {
      const int64_t i = store.Index(x, y);
      if (!store.IsExact(i) || !store.IsFinite(i)) continue;
      const Value vi = store.ValueAt(i);
      if (!(vi.varA > 0.f || vi.varB > 0.f)) continue;
      near.clear();
      double M[3][3] = {};
      for (int ny = std::max(0, y - radius); ny <= std::min(H - 1, y + radius); ++ny)
        for (int nx = std::max(0, x - radius); nx <= std::min(W - 1, x + radius); ++nx) {
          const int64_t j = store.Index(nx, ny);
          if (!store.IsExact(j) || !store.IsFinite(j) || !surfaces.Same(i, j)) continue;
          if (j != i) {
            const Value vj = store.ValueAt(j);
            if (!noise.WithinNoise(vi, vj, gate) || !SameColour(vi, vj, gate)) continue;
          }
          const double dx = double(nx - x), dy = double(ny - y);
          const Neighbour n{j, dx / radius, dy / radius, std::exp(-(dx * dx + dy * dy) / (2 * sd * sd))};
          const double v[3] = {1, n.x, n.y};
          for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) M[r][c] += n.w * v[r] * v[c];
          near.push_back(n);
        }
      if (near.size() < 2) continue;
      // A small ridge on the slopes: samples along one line (an edge-block
      // side) determine one slope only; the other is then taken as zero.
      M[1][1] += 1e-3 * M[0][0];
      M[2][2] += 1e-3 * M[0][0];
      double g[3];
      if (!SolveFirstColumn(M, g)) continue;
      // The fit at the pixel is sum_j l_j v_j with l_j = w_j (g . x_j);
      // normalised so that a constant is reproduced exactly.
      double sumL = 0;
      for (Neighbour& n : near) {
        n.w *= g[0] + g[1] * n.x + g[2] * n.y;
        sumL += n.w;
      }
      if (!(std::fabs(sumL) > 1e-9)) continue;
      double a[3] = {}, b[3] = {}, varA = 0, varB = 0;
      for (const Neighbour& n : near) {
        const double l = n.w / sumL;
        const Value v = store.ValueAt(n.index);
        for (int c = 0; c < 3; ++c) a[c] += l * v.a[c], b[c] += l * v.b[c];
        varA += l * l * v.varA, varB += l * l * v.varB;
      }
      Value out{RGB(float(a[0]), float(a[1]), float(a[2])), RGB(float(b[0]), float(b[1]), float(b[2])),
                float(varA), float(varB)};
      if (!IsFinite(out.a) || !IsFinite(out.b)) continue;
      rows[size_t(y)].push_back({i, out});
    }
    replaced += int64_t(rows[size_t(y)].size());
  });
  for (const auto& row : rows)
    for (const auto& [i, v] : row) store.ReplaceExact(i, v);
  return replaced;
}

}  // namespace dcm::detail
