// Lazy boundary evaluation of simple edge blocks (paper 2.1): only the centre
// pixel is evaluated; where the parent's oriented interpolation predicts it,
// the block keeps the parent's direction and the centre corrects the
// interpolation, otherwise its children get a full boundary evaluation.
#include <algorithm>

#include "engine.h"

namespace dcm::detail {

Status Engine::EvaluateLazily(std::vector<EdgeBlock>& eb, int size, std::vector<Block>* nextEdges) {
  if (opt_.lazyEvaluation) {
    ForEach(eb, [&](EdgeBlock& e, size_t) {
      if (e.simple) store_.Request(e.block.Centre().x, e.block.Centre().y, SampleReason::kLazyCentre);
    });
    DCM_RETURN_IF_ERROR(Flush());
  }
  std::vector<Leaf> lazy(eb.size());
  std::vector<uint8_t> accepted(eb.size(), 0);
  ForEach(eb, [&](EdgeBlock& e, size_t i) {
    if (!e.simple || !opt_.lazyEvaluation) return;
    const Block& b = e.block;
    const Point2i c = b.Centre();
    Interpolant in;
    if (!OrientedInterpolant(store_, b, c, Direction::Of(e.direction.index, settings_.directions), &in) ||
        ResolveInterpolant(c, &in) != SampleReason::kInterpolated)
      return;
    const Value predicted = Evaluate(store_, in), exact = At(c);
    if (!store_.IsFinite(store_.Index(c.x, c.y)) || contrast_.Misses(exact, predicted)) return;
    Leaf& leaf = lazy[i];
    leaf = MakeLeaf(b, BlockType::kLazy, e.direction.index);
    leaf.centre = c;
    // A correction the noise may explain is noise: spread over the block by
    // the tent, it would move both sides of the edge (kLazyCorrectionMinSd).
    const bool corrected = !contrast_.WithinNoise(exact, predicted, settings_.lazyCorrectionGate);
    if (corrected)
      leaf.delta = {exact.a - predicted.a, exact.b - predicted.b};
    leaf.lo = leaf.hi = exact;
    for (Point2i p : e.border) {
      const int64_t ip = store_.Index(p.x, p.y);
      if (!store_.IsFinite(ip)) continue;
      const Value v = store_.ValueAt(ip);
      for (int ch = 0; ch < 3; ++ch) {
        leaf.lo.a[ch] = std::min(leaf.lo.a[ch], v.a[ch]), leaf.hi.a[ch] = std::max(leaf.hi.a[ch], v.a[ch]);
        leaf.lo.b[ch] = std::min(leaf.lo.b[ch], v.b[ch]), leaf.hi.b[ch] = std::max(leaf.hi.b[ch], v.b[ch]);
      }
    }
    if (record_) record_->LazyLeaf(c, in, e.border, !corrected);
    accepted[i] = 1;
  });
  for (size_t i = 0; i < eb.size(); ++i) {
    const EdgeBlock& e = eb[i];
    if (accepted[i]) {
      orientedLeaves_.push_back(lazy[i]);
      ++stats_.lazyAccepted;
    } else if (!e.block.HasInterior()) {
      orientedLeaves_.push_back(MakeLeaf(e.block, BlockType::kComplexEdge, e.direction.index));
    } else {
      if (e.simple && opt_.lazyEvaluation) ++stats_.lazyRejected;
      e.simple ? ++stats_.simpleEdgeBlocks : ++stats_.complexEdgeBlocks;
      ChildBlocks(e.block, size / 2, store_.width(), store_.height(), nextEdges);
    }
  }
  return Status::Ok();
}

}  // namespace dcm::detail
