// The least-discrepancy direction of each edge block (paper 2.1, Figure 2).
#include "least_discrepancy_direction.h"

#include <cmath>
#include <limits>

#include "engine.h"
#include "simple_complex_classification.h"

namespace dcm::detail {

namespace {
double SquaredDifference(const Value& p, const Value& q) {
  double s = 0;
  for (int c = 0; c < 3; ++c) {
    const double da = double(p.a[c]) - q.a[c], db = double(p.b[c]) - q.b[c];
    s += da * da + db * db;
  }
  return s;
}

/// The term of one pair: |L(p) - L(p')|^2, in units of its variance when the
/// samples carry one. `kOnlyA`: no split and no variance, so the second
/// channel and the variances are zero and left out (the same sums: adding
/// zeros changes no bit).
template <bool kOnlyA>
double PairTerm(const Value& v, const Value& e0, const Value& e1, double w1) {
  if constexpr (kOnlyA) {
    double s = 0;
    for (int c = 0; c < 3; ++c) {
      double a = 0;  // WeightedSum's arithmetic
      a += (1 - w1) * e0.a[c];
      a += w1 * e1.a[c];
      const double d = double(v.a[c]) - float(a);
      s += d * d;
    }
    return s;
  } else {
    const Value* ends[2] = {&e0, &e1};
    const double weights[2] = {1 - w1, w1};
    const Value predicted = WeightedSum(ends, weights, 2);
    // With noisy samples, each difference counts in units of its own
    // standard deviation (a chi-square): noisy pairs do not outvote clean
    // ones, and a direction along which only noise differs scores ~1.
    const double var = double(v.varA) + v.varB + predicted.varA + predicted.varB;
    return var > 0 ? SquaredDifference(v, predicted) / var : SquaredDifference(v, predicted);
  }
}

template <bool kOnlyA>
DirectionChoice Search(std::span<const Value> value, std::span<const uint8_t> finite, bool allFinite,
                       const BorderPairs& pairs) {
  auto valid = [&](const BorderPairs::Pair& q) {
    return allFinite || (finite[size_t(q.p)] && finite[size_t(q.e0)] && finite[size_t(q.e1)]);
  };
  DirectionChoice best{0, std::numeric_limits<double>::infinity()};
  for (int k = 0; k < pairs.directions(); ++k) {
    const std::span<const BorderPairs::Pair> all = pairs.Of(k);
    int count = 0;
    for (const BorderPairs::Pair& q : all) count += valid(q);
    if (count == 0) continue;
    // The sum only grows: once its mean over all `count` pairs reaches the
    // best so far, this direction cannot win (ties go to the smaller k), and
    // the rest of its pairs are skipped. The choice is that of the full sums.
    double sum = 0;
    int done = 0;
    for (const BorderPairs::Pair& q : all) {
      if (!valid(q)) continue;
      sum += PairTerm<kOnlyA>(value[size_t(q.p)], value[size_t(q.e0)], value[size_t(q.e1)], q.w1);
      if ((++done & 7) == 0 && sum / count >= best.discrepancy) break;
    }
    if (done < count) continue;
    const double mean = sum / count;
    if (mean < best.discrepancy) best = {k, mean};
  }
  if (!std::isfinite(best.discrepancy)) best = {0, 0};
  return best;
}
}  // namespace

BorderPairs::BorderPairs(int width, int height, int directions) : directions_(directions) {
  const Block local{0, 0, width, height};
  std::vector<Point2i> loop;
  BorderLoop(local, &loop);
  // Border index of each pixel of the block's bounding grid.
  std::vector<int> index(size_t(width + 1) * size_t(height + 1), -1);
  for (size_t i = 0; i < loop.size(); ++i) index[size_t(loop[i].y) * size_t(width + 1) + size_t(loop[i].x)] = int(i);
  auto at = [&](Point2i p) { return index[size_t(p.y) * size_t(width + 1) + size_t(p.x)]; };
  start_.push_back(0);
  for (int k = 0; k < directions; ++k) {
    const Direction d = Direction::Of(k, directions);
    for (size_t i = 0; i < loop.size(); ++i) {
      const Point2i p = loop[i];
      BorderPoint e;
      if (!ExitPoint(local, p.x, p.y, d, &e) && !ExitPoint(local, p.x, p.y, Direction{-d.dx, -d.dy}, &e))
        continue;
      pairs_.push_back({int(i), at(e.p0), at(e.p1), e.w1});
    }
    start_.push_back(pairs_.size());
  }
}

DirectionChoice LeastDiscrepancyDirection(const SampleStore& store, std::span<const Point2i> border,
                                          const BorderPairs& pairs) {
  // The border's samples, read once for all directions (into per-thread
  // scratch: blocks are searched in parallel, thousands per level).
  thread_local std::vector<Value> value;
  thread_local std::vector<uint8_t> finite;
  value.resize(border.size());
  finite.resize(border.size());
  bool allFinite = true;
  for (size_t i = 0; i < border.size(); ++i) {
    const int64_t index = store.Index(border[i].x, border[i].y);
    finite[i] = store.IsFinite(index);
    allFinite = allFinite && finite[i];
    value[i] = store.ValueAt(index);
  }
  const std::span<const Value> v(value);
  const std::span<const uint8_t> f(finite);
  return store.split() || store.hasVariance() ? Search<false>(v, f, allFinite, pairs) : Search<true>(v, f, allFinite, pairs);
}

void Engine::OrientEdgeBlocks(std::vector<EdgeBlock>& eb) {
  // The geometry per block shape, built before the blocks run in parallel.
  for (const EdgeBlock& e : eb) {
    const auto shape = std::pair(e.block.width(), e.block.height());
    if (!borderPairs_.contains(shape)) borderPairs_.try_emplace(shape, shape.first, shape.second, settings_.directions);
  }
  ForEach(eb, [&](EdgeBlock& e, size_t) {
    e.direction = LeastDiscrepancyDirection(store_, e.border,
                                            borderPairs_.at(std::pair(e.block.width(), e.block.height())));
    e.crossings = SignificantChanges(store_, contrast_, e.border);
  });
}

}  // namespace dcm::detail
