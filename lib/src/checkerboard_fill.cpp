// dcm's checkerboard refinement: of the pixels the thin-object test or a
// fallback wants exact, one colour first; the other filled where its exact
// neighbours agree.
#include "checkerboard_fill.h"

#include <tbb/parallel_for.h>

#include <algorithm>

#include "engine.h"
#include "oriented_interpolation.h"

namespace dcm::detail {

bool NeighbourEstimate(const SampleStore& store, const ContrastTest& contrast, Point2i q, bool test, Value* out,
                       NeighbourTerms* terms) {
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
  int64_t usedIndex[8];
  double weight[8];
  int n = 0;
  double total = 0;
  for (int pair = 0; pair < 4; ++pair) {
    if (!usable[2 * pair] || !usable[2 * pair + 1]) continue;
    const double w = pair < 2 ? 1.0 : 0.5;
    for (int k = 2 * pair; k <= 2 * pair + 1; ++k)
      used[n] = &v[k], usedIndex[n] = store.Index(q.x + kDx[k], q.y + kDy[k]), weight[n++] = 0.5 * w;
    total += w;
  }
  if (n == 0) return false;
  for (int k = 0; k < n; ++k) weight[k] /= total;
  const Value estimate = WeightedSum(used, weight, n);
  if (test)
    for (int k = 0; k < 8; ++k)
      if (usable[k] && contrast.Misses(v[k], estimate)) return false;
  *out = estimate;
  if (terms) {
    terms->count = n;
    for (int k = 0; k < n; ++k) terms->index[k] = usedIndex[k], terms->weight[k] = weight[k];
  }
  return true;
}

void Engine::RequestOrDefer(int x, int y, SampleReason reason) {
  const int64_t i = store_.Index(x, y);
  if (store_.IsExact(i)) return;  // a probe inside a fallback block, say
  if (opt_.checkerboard && !EvaluatedFirst(x, y)) deferred_[size_t(i)] = reason;
  else store_.Request(x, y, reason);
}

Status Engine::ResolveDeferred(bool write) {
  // The deferred pixels in frame order: found in parallel over fixed chunks,
  // joined in chunk order.
  constexpr size_t kChunk = size_t(1) << 16;
  std::vector<std::vector<int64_t>> found((deferred_.size() + kChunk - 1) / kChunk);
  tbb::parallel_for(size_t(0), found.size(), [&](size_t c) {
    const SampleReason* reason = deferred_.data();
    std::vector<int64_t>& out = found[c];
    for (size_t i = c * kChunk, end = std::min(deferred_.size(), i + kChunk); i < end; ++i)
      if (reason[i] != SampleReason::kInterpolated) out.push_back(int64_t(i));
  });
  std::vector<int64_t> deferred;
  for (const std::vector<int64_t>& f : found) deferred.insert(deferred.end(), f.begin(), f.end());
  std::vector<uint8_t> filled(deferred.size(), 0);
  // The decisions read the exact samples of the first colour only (requests
  // take effect at the flush), so they do not depend on the order.
  ForEach(deferred, [&](int64_t& i, size_t k) {
    const int x = int(i % store_.width()), y = int(i / store_.width());
    Value v;
    NeighbourTerms terms;
    if (NeighbourEstimate(store_, contrast_, {x, y}, true, &v, record_ ? &terms : nullptr)) {
      filled[k] = 1;
      if (write && record_) record_->Weighted(i, terms);
      if (write) store_.SetInterpolated(i, v);
    } else {
      store_.Request(x, y, deferred_[size_t(i)]);
    }
  });
  filledDeferred_.clear();
  for (size_t k = 0; k < deferred.size(); ++k)
    if (filled[k]) filledDeferred_.push_back(deferred[k]);
  stats_.checkerboardFilled = int64_t(filledDeferred_.size());
  return Flush();
}

void Engine::WriteFilledDeferred() {
  ForEach(filledDeferred_, [&](int64_t& i, size_t) {
    Value v;
    NeighbourTerms terms;
    if (NeighbourEstimate(store_, contrast_, {int(i % store_.width()), int(i / store_.width())}, false, &v,
                          record_ ? &terms : nullptr)) {
      if (record_) record_->Weighted(i, terms);
      store_.SetInterpolated(i, v);
    }
  });
}

}  // namespace dcm::detail
