// The thin-object test (paper 3.1): an interior pixel whose interpolants lie
// on another surface is evaluated exactly. dcm's variants (ThinObjectTest)
// and its neighbouring directions, which serve such a pixel along another
// direction where both ends agree, live here too.
#include <array>
#include <limits>

#include "engine.h"

namespace dcm::detail {

SampleReason Engine::ResolveInterpolant(Point2i q, Interpolant* in) const {
  const int64_t iq = store_.Index(q.x, q.y);
  const SurfaceTest& s = store_.surfaces();
  // The common case: every interpolant is finite and on q's surface, so it is
  // used as it is (what the general case below would keep, in its order).
  bool allUsable = in->count > 0;
  for (int k = 0; k < in->count && allUsable; ++k) {
    const int64_t i = in->index[k];
    allUsable = store_.IsFinite(i) && store_.LiKnownFor(i, iq) && s.Same(iq, i);
  }
  if (allUsable) {
    double sum = 0;
    for (int k = 0; k < in->count; ++k) sum += in->weight[k];
    for (int k = 0; k < in->count; ++k) in->weight[k] /= sum;
    return SampleReason::kInterpolated;
  }
  // The finite weight per border point on q's surface and off it (weights
  // are > 0: an interpolant leaves zero weights out).
  double sameAt[2] = {0, 0}, otherAt[2] = {0, 0};
  Interpolant kept;
  Interpolant finite;
  for (int k = 0; k < in->count; ++k) {
    const int64_t i = in->index[k];
    const uint8_t end = in->end[k];
    if (!store_.IsFinite(i)) continue;  // non-finite samples never spread
    if (!store_.LiKnownFor(i, iq)) {  // tau = 0 there: its L_i is unknown here
      otherAt[end] += in->weight[k];   // (and it is another surface)
      continue;
    }
    finite.index[finite.count] = i, finite.end[finite.count] = end, finite.weight[finite.count++] = in->weight[k];
    if (s.Same(iq, i)) {
      sameAt[end] += in->weight[k];
      kept.index[kept.count] = i, kept.end[kept.count] = end, kept.weight[kept.count++] = in->weight[k];
    } else {
      otherAt[end] += in->weight[k];
    }
  }
  const bool anySame = sameAt[0] + sameAt[1] > 0, anyOther = otherAt[0] + otherAt[1] > 0;
  switch (settings_.thinObjects) {
    case ThinObjectTest::kOff: break;
    case ThinObjectTest::kNoneMatches:
      if (!anySame && s.enabled()) return SampleReason::kThinObject;
      break;
    case ThinObjectTest::kAnyDiffers:
      if (anyOther) return SampleReason::kThinObject;
      break;
    case ThinObjectTest::kEndDiffers:
      for (int end = 0; end < 2; ++end)
        if (otherAt[end] > 0 && sameAt[end] == 0) return SampleReason::kThinObject;
      // A border point between a pixel on q's surface and one on another
      // snaps to the one on q's: the edge passes between them.
      for (int k = 0; k < kept.count; ++k) {
        const int end = kept.end[k];
        kept.weight[k] *= (sameAt[end] + otherAt[end]) / sameAt[end];
      }
      break;
  }
  Interpolant& use = (opt_.surfaceAware && kept.count > 0) ? kept : finite;
  if (use.count == 0) return SampleReason::kFallback;
  double sum = 0;
  for (int k = 0; k < use.count; ++k) sum += use.weight[k];
  for (int k = 0; k < use.count; ++k) use.weight[k] /= sum;
  *in = use;
  return SampleReason::kInterpolated;
}

namespace {

/// The values of the interpolant's two border points, each from its own
/// pixels; false when one has none.
bool EndValues(const SampleStore& store, const Interpolant& in, std::array<Value, 2>* values) {
  Interpolant end[2];
  for (int k = 0; k < in.count; ++k) {
    Interpolant& e = end[in.end[k]];
    e.index[e.count] = in.index[k], e.weight[e.count++] = in.weight[k];
  }
  if (end[0].count == 0 || end[1].count == 0) return false;
  for (int i = 0; i < 2; ++i) {
    Interpolant& e = end[i];
    double sum = 0;
    for (int k = 0; k < e.count; ++k) sum += e.weight[k];
    for (int k = 0; k < e.count; ++k) e.weight[k] /= sum;
    (*values)[size_t(i)] = Evaluate(store, e);
  }
  return true;
}

}  // namespace

bool Engine::EndsAgree(const Interpolant& in) const {
  std::array<Value, 2> ends;
  return EndValues(store_, in, &ends) && !contrast_.Differ(ends[0], ends[1]);
}

bool Engine::LeastDifferentTwoEnded(const Leaf& leaf, Point2i q, Interpolant* in) const {
  float least = std::numeric_limits<float>::infinity();
  for (int k = 0; k < settings_.directions; ++k) {
    Interpolant alt;
    std::array<Value, 2> ends;
    if (!InterpolantAlong(ElementsOf(leaf.block, k), leaf.block, q, k, &alt) ||
        ResolveInterpolant(q, &alt) != SampleReason::kInterpolated || !EndValues(store_, alt, &ends))
      continue;
    const float c = contrast_.Contrast(ends);
    if (c < least) least = c, *in = alt;
  }
  return least < std::numeric_limits<float>::infinity();
}

SampleReason Engine::ResolveAlongNeighbours(const Leaf& leaf, Point2i q, Interpolant* in, bool anyEnds) const {
  const Block& b = leaf.block;
  Interpolant nearest;
  bool passed = false;
  for (int step = 1; step <= NeighbourSteps(); ++step)
    for (int sign : {1, -1}) {
      if (sign < 0 && 2 * step == settings_.directions) continue;  // the perpendicular, tried once
      const int k = Turned(leaf.direction, sign * step);
      Interpolant alt;
      if (!InterpolantAlong(ElementsOf(b, k), b, q, k, &alt) || ResolveInterpolant(q, &alt) != SampleReason::kInterpolated)
        continue;
      if (EndsAgree(alt)) {
        *in = alt;
        return SampleReason::kInterpolated;
      }
      if (!passed) nearest = alt, passed = true;
    }
  if (anyEnds && passed) {
    *in = nearest;
    return SampleReason::kInterpolated;
  }
  return SampleReason::kThinObject;
}

}  // namespace dcm::detail
