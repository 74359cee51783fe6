#include "least_discrepancy_direction.h"

#include <cmath>
#include <limits>

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
}  // namespace

DirectionChoice LeastDiscrepancyDirection(const SampleStore& store, const Block& b,
                                          std::span<const Point2i> border, int directions) {
  DirectionChoice best{0, std::numeric_limits<double>::infinity()};
  for (int k = 0; k < directions; ++k) {
    const Direction d = Direction::Of(k, directions);
    double sum = 0;
    int pairs = 0;
    for (const Point2i& p : border) {
      const int64_t ip = store.Index(p.x, p.y);
      if (!store.IsFinite(ip)) continue;
      BorderPoint e;
      if (!ExitPoint(b, p.x, p.y, d, &e) && !ExitPoint(b, p.x, p.y, Direction{-d.dx, -d.dy}, &e))
        continue;
      const int64_t i0 = store.Index(e.p0.x, e.p0.y), i1 = store.Index(e.p1.x, e.p1.y);
      if (!store.IsFinite(i0) || !store.IsFinite(i1)) continue;
      Interpolant in;
      in.index = {i0, i1, 0, 0};
      in.weight = {1 - e.w1, e.w1, 0, 0};
      in.count = 2;
      const Value v = store.ValueAt(ip), predicted = Evaluate(store, in);
      // With noisy samples, each difference counts in units of its own
      // standard deviation (a chi-square): noisy pairs do not outvote clean
      // ones, and a direction along which only noise differs scores ~1.
      const double var = double(v.varA) + v.varB + predicted.varA + predicted.varB;
      sum += var > 0 ? SquaredDifference(v, predicted) / var : SquaredDifference(v, predicted);
      ++pairs;
    }
    if (pairs == 0) continue;
    const double mean = sum / pairs;
    if (mean < best.discrepancy) best = {k, mean};
  }
  if (!std::isfinite(best.discrepancy)) best = {0, 0};
  return best;
}

}  // namespace dcm::detail
