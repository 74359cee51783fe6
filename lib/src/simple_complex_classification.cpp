// Simple/complex classification of edge blocks (paper 2.3): the zero-order,
// first-order and object tests, and dcm's rule for small blocks whose border
// changes only at surface changes.
#include "simple_complex_classification.h"

#include <algorithm>
#include <cmath>

#include "engine.h"

namespace dcm::detail {

std::vector<int> SignificantChanges(const SampleStore& store, const ContrastTest& contrast,
                                    std::span<const Point2i> loop) {
  std::vector<int> changes;
  const int n = int(loop.size());
  if (n < 2) return changes;
  for (int k = 0; k < n; ++k) {
    const Point2i p = loop[k], q = loop[(k + 1) % n];
    const int64_t ip = store.Index(p.x, p.y), iq = store.Index(q.x, q.y);
    if (contrast.Differ(store.ValueAt(ip), store.ValueAt(iq)) || !store.surfaces().SameAdjacent(ip, iq))
      changes.push_back(k);
  }
  return changes;
}

int SurfaceChanges(const SampleStore& store, std::span<const Point2i> loop) {
  const int n = int(loop.size());
  int changes = 0;
  if (!store.surfaces().enabled() || n < 2) return 0;
  for (int k = 0; k < n; ++k) {
    const Point2i p = loop[k], q = loop[(k + 1) % n];
    if (!store.surfaces().SameAdjacent(store.Index(p.x, p.y), store.Index(q.x, q.y))) ++changes;
  }
  return changes;
}

namespace {
struct Crossing {
  Point2i p, q;      // border pixels on either side
  Point2i step;      // q - p
  Point2i inward;    // inward normal of the side
};

/// The crossing is a surface change the guides mark, and `fromGuides` asks
/// to read it from them.
bool FromGuides(const SampleStore& store, const Crossing& c, bool fromGuides) {
  return fromGuides && !store.surfaces().SameAdjacent(store.Index(c.p.x, c.p.y), store.Index(c.q.x, c.q.y));
}

Crossing CrossingAt(std::span<const Point2i> loop, int k) {
  const int n = int(loop.size());
  Crossing c;
  c.p = loop[k];
  c.q = loop[(k + 1) % n];
  c.step = {c.q.x - c.p.x, c.q.y - c.p.y};
  // The loop runs clockwise on screen (y down): the inside is to the right.
  c.inward = {-c.step.y, c.step.x};
  return c;
}

bool Inside(const Block& b, Point2i p) { return p.x > b.x0 && p.x < b.x1 && p.y > b.y0 && p.y < b.y1; }
}  // namespace

std::vector<Point2i> FirstOrderProbes(const SampleStore& store, const Block& b, std::span<const Point2i> loop,
                                      std::span<const int> crossings, bool fromGuides) {
  std::vector<Point2i> probes;
  for (int k : crossings) {
    const Crossing c = CrossingAt(loop, k);
    if (FromGuides(store, c, fromGuides)) continue;
    for (Point2i p : {c.p, c.q}) {
      const Point2i in{p.x + c.inward.x, p.y + c.inward.y};
      if (Inside(b, in)) probes.push_back(in);
    }
  }
  return probes;
}

bool FirstOrderConsistent(const SampleStore& store, const ContrastTest& contrast, const Block& b,
                          std::span<const Point2i> loop, std::span<const int> crossings, bool fromGuides) {
  if (crossings.size() != 2) return false;
  double ex[2], ey[2], cx[2], cy[2];
  for (int i = 0; i < 2; ++i) {
    const Crossing c = CrossingAt(loop, crossings[i]);
    const Point2i pin{c.p.x + c.inward.x, c.p.y + c.inward.y};
    const Point2i qin{c.q.x + c.inward.x, c.q.y + c.inward.y};
    if (!Inside(b, pin) || !Inside(b, qin)) return false;
    // Is an inner pixel like p or like q: on its surface, or of its value?
    const int64_t ip = store.Index(c.p.x, c.p.y), iq = store.Index(c.q.x, c.q.y);
    const int64_t ipin = store.Index(pin.x, pin.y), iqin = store.Index(qin.x, qin.y);
    const bool guides = FromGuides(store, c, fromGuides);
    auto like = [&](int64_t inner, int64_t border) {
      return guides ? store.surfaces().Same(inner, border) : !contrast.Differ(store.ValueAt(inner), store.ValueAt(border));
    };
    // Where does the change lie on the inner row: between the same two
    // positions (0), one step back (-1) or one step ahead (+1)?
    const bool pinLikeP = like(ipin, ip), pinLikeQ = like(ipin, iq);
    const bool qinLikeP = like(iqin, ip), qinLikeQ = like(iqin, iq);
    int offset;
    if (pinLikeP && qinLikeQ) offset = 0;
    else if (pinLikeQ && !pinLikeP) offset = -1;
    else if (qinLikeP && !qinLikeQ) offset = 1;
    else return false;  // no clear crossing on the inner row
    ex[i] = c.inward.x + offset * c.step.x;
    ey[i] = c.inward.y + offset * c.step.y;
    cx[i] = c.p.x + 0.5 * c.step.x;
    cy[i] = c.p.y + 0.5 * c.step.y;
  }
  const double chx = cx[1] - cx[0], chy = cy[1] - cy[0];
  const double chord = std::hypot(chx, chy);
  const double kCos = std::cos(40.0 * 3.14159265358979 / 180.0);
  auto parallel = [&](double ax, double ay, double bx, double by) {
    const double na = std::hypot(ax, ay), nb = std::hypot(bx, by);
    return std::fabs(ax * bx + ay * by) >= kCos * na * nb;
  };
  if (!parallel(ex[0], ey[0], ex[1], ey[1])) return false;
  if (chord > 1.5 && (!parallel(ex[0], ey[0], chx, chy) || !parallel(ex[1], ey[1], chx, chy)))
    return false;
  return true;
}

Status Engine::ClassifySimpleOrComplex(std::vector<EdgeBlock>& eb) {
  ForEach(eb, [&](EdgeBlock& e, size_t) {
    const size_t n = e.crossings.size();
    const bool zeroOrder = !opt_.zeroOrderTest || n == 2 || (n == 0 && opt_.gradientBlocksSimple);
    const int surfaceChanges = SurfaceChanges(store_, e.border);
    // Every significant change a surface change (crossings include them all).
    const bool onlySurfaces = int(n) == surfaceChanges;
    const bool small = std::max(e.block.width(), e.block.height()) <= 2 * opt_.minBlock;
    e.simple = e.block.HasInterior() &&
               ((zeroOrder && surfaceChanges <= 2) ||
                (small && onlySurfaces && n > 2 && int(n) <= opt_.simpleSurfaceChanges));
    if (e.simple && opt_.firstOrderTest && n == 2)
      for (Point2i p : FirstOrderProbes(store_, e.block, e.border, e.crossings, opt_.firstOrderFromGuides))
        store_.Request(p.x, p.y, SampleReason::kFirstOrderProbe);
  });
  if (opt_.firstOrderTest) {
    DCM_RETURN_IF_ERROR(Flush());
    ForEach(eb, [&](EdgeBlock& e, size_t) {
      if (e.simple && e.crossings.size() == 2)
        e.simple = FirstOrderConsistent(store_, contrast_, e.block, e.border, e.crossings, opt_.firstOrderFromGuides);
    });
  }
  return Status::Ok();
}

}  // namespace dcm::detail
