#include "checkerboard_fill.h"

#include "oriented_interpolation.h"

namespace dcm::detail {

bool NeighbourEstimate(const SampleStore& store, const ContrastTest& contrast, Point2i q, bool test, Value* out) {
  // Neighbours 2k and 2k + 1 are opposite; the first two pairs are the axes.
  static constexpr int kDx[8] = {1, -1, 0, 0, 1, -1, 1, -1};
  static constexpr int kDy[8] = {0, 0, 1, -1, 1, -1, -1, 1};
  const int64_t iq = store.Index(q.x, q.y);
  const SurfaceTest& s = store.surfaces();
  Value v[8];
  bool usable[8] = {};
  for (int k = 0; k < 8; ++k) {
    const int x = q.x + kDx[k], y = q.y + kDy[k];
    if (x < 0 || y < 0 || x >= store.width() || y >= store.height()) continue;
    const int64_t i = store.Index(x, y);
    if (!store.IsExact(i) || !store.IsFinite(i) || !store.LiKnownFor(i, iq)) continue;
    // Axis neighbours: no crease between them either.
    if (!(k < 4 ? s.SameAdjacent(iq, i) : s.Same(iq, i))) continue;
    usable[k] = true;
    v[k] = store.ValueAt(i);
  }
  const Value* used[8];
  double weight[8];
  int n = 0;
  double total = 0;
  for (int pair = 0; pair < 4; ++pair) {
    if (!usable[2 * pair] || !usable[2 * pair + 1]) continue;
    const double w = pair < 2 ? 1.0 : 0.5;
    for (int k = 2 * pair; k <= 2 * pair + 1; ++k) used[n] = &v[k], weight[n++] = 0.5 * w;
    total += w;
  }
  if (n == 0) return false;
  for (int k = 0; k < n; ++k) weight[k] /= total;
  const Value estimate = WeightedSum(used, weight, n);
  if (test)
    for (int k = 0; k < 8; ++k)
      if (usable[k] && contrast.Misses(v[k], estimate)) return false;
  *out = estimate;
  return true;
}

}  // namespace dcm::detail
