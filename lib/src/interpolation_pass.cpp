// The final interpolation of the leaves: smooth blocks bilinear from their
// corners, oriented leaves along their direction (oriented elements, paper
// 2.1) where the thin-object test (3.1) lets a pixel be interpolated, lazy
// leaves corrected by their centre; noisy samples are denoised first.
#include <algorithm>
#include <cmath>

#include "checkerboard_fill.h"
#include "engine.h"
#include "sample_denoising.h"

namespace dcm::detail {

void Engine::PrepareElements(const std::vector<Leaf>& leaves) {
  for (const Leaf& l : leaves)
    for (int step = -NeighbourSteps(); step <= NeighbourSteps(); ++step) {
      const int k = Turned(l.direction, step);
      const auto key = std::tuple(l.block.width(), l.block.height(), k);
      if (!elements_.contains(key))
        elements_.try_emplace(key, l.block.width(), l.block.height(), Direction::Of(k, settings_.directions));
    }
}

void Engine::InterpolateOriented(const Leaf& leaf, OrientedPass pass) {
  const Block& b = leaf.block;
  const OrientedElements* elements = ElementsOf(b, leaf.direction);
  const bool lazy = leaf.type == BlockType::kLazy;
  const double hx = 0.5 * (b.x1 - b.x0), hy = 0.5 * (b.y1 - b.y0);
  for (int y = b.y0 + 1; y < b.y1; ++y)
    for (int x = b.x0 + 1; x < b.x1; ++x) {
      const int64_t i = store_.Index(x, y);
      if (store_.IsExact(i) || IsDeferred(i)) continue;
      Interpolant in;
      const bool found = InterpolantAlong(elements, b, {x, y}, leaf.direction, &in);
      SampleReason r = found ? ResolveInterpolant({x, y}, &in) : SampleReason::kFallback;
      if (r == SampleReason::kThinObject) {
        r = ResolveAlongNeighbours(leaf, {x, y}, &in, pass == OrientedPass::kDenoised);
      } else if (r == SampleReason::kInterpolated && NeighbourSteps() > 0 && OneEnded(in)) {
        // One border point on q's surface (the thin-object test lets it
        // pass): its value would reach across the block unchanged. A
        // direction with two ends on q's surface interpolates instead,
        // where there is one (dcm's: the published methods try no other
        // direction, neighbourDirections 0).
        LeastDifferentTwoEnded(leaf, {x, y}, &in);
      }
      if (r != SampleReason::kInterpolated) {
        // Deferred pixels were resolved before denoising: none may be added now.
        if (pass == OrientedPass::kDenoised) store_.Request(x, y, r);
        else if (pass != OrientedPass::kPreview) RequestOrDefer(x, y, r);
        continue;
      }
      if (pass == OrientedPass::kThinObjects) continue;
      Value v = Evaluate(store_, in);
      const bool record = record_ && (pass == OrientedPass::kFinal || pass == OrientedPass::kDenoised);
      if (record && !lazy) record_->Weighted(i, in);
      if (lazy) {
        // The centre sample corrects the parent's interpolation with a tent
        // that is 1 at the centre and 0 on the border; the result stays in
        // the range of the samples used.
        const double w = std::max(0.0, 1 - std::fabs(x - leaf.centre.x) / hx) *
                         std::max(0.0, 1 - std::fabs(y - leaf.centre.y) / hy);
        if (record) record_->Lazy(i, in, leaf.centre, w);
        for (int c = 0; c < 3; ++c) {
          v.a[c] = std::clamp(float(v.a[c] + w * leaf.delta.a[c]), leaf.lo.a[c], leaf.hi.a[c]);
          v.b[c] = std::clamp(float(v.b[c] + w * leaf.delta.b[c]), leaf.lo.b[c], leaf.hi.b[c]);
        }
      }
      store_.SetInterpolated(i, v);
    }
}

Status Engine::InterpolateLeaves() {
  // Thin objects (3.1): interior pixels whose interpolants lie on another
  // surface are evaluated exactly. The interpolation reads block borders
  // only, which are final now, unless the samples are to be denoised first:
  // then the pass only requests, and the interpolation follows denoising.
  const bool denoise = settings_.denoise;
  Progress(0.9f, "thin objects and interpolation");
  PrepareElements(orientedLeaves_);
  auto writeSmooth = [&](Leaf& l, size_t) {
    WriteSmooth(l);
    if (record_) record_->Smooth(l.block);
  };
  if (!denoise) ForEach(smoothLeaves_, writeSmooth);
  ForEach(orientedLeaves_, [&](Leaf& l, size_t) {
    InterpolateOriented(l, denoise ? OrientedPass::kThinObjects : OrientedPass::kFinal);
  });
  DCM_RETURN_IF_ERROR(Flush());
  if (opt_.checkerboard) DCM_RETURN_IF_ERROR(ResolveDeferred(!denoise));
  if (denoise) {
    Progress(0.93f, "denoising samples");
    // Counted apart from the interpolation that encloses it.
    double denoising = 0;
    Timed(&denoising, [&] {
      stats_.denoisedSamples = DenoiseExactSamples(store_, settings_.denoiseRadius, contrast_, settings_.denoiseGate);
    });
    stats_.stageTimes.denoising += denoising;
    stats_.stageTimes.interpolation -= denoising;
    Progress(0.95f, "interpolation");
    ForEach(smoothLeaves_, writeSmooth);
    ForEach(orientedLeaves_, [&](Leaf& l, size_t) { InterpolateOriented(l, OrientedPass::kDenoised); });
    // Nothing to evaluate unless the thin-object pass missed a pixel.
    DCM_RETURN_IF_ERROR(Flush());
    WriteFilledDeferred();
  }
  return Status::Ok();
}

}  // namespace dcm::detail
