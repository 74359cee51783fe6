// dcm's finest fallback (after the paper's "switching back to a full sampling
// for these few critical cases", 4): a finest edge block with more
// discontinuities than one direction can serve, or whose centre probe the
// interpolation misses, has its interior evaluated exactly.
#include "engine.h"
#include "simple_complex_classification.h"

namespace dcm::detail {

Status Engine::SettleFinest(std::vector<EdgeBlock>& eb) {
  std::vector<uint8_t> fallback(eb.size(), 0);
  ForEach(eb, [&](EdgeBlock& e, size_t i) {
    // The changes no surface change explains: shading edges.
    const int shading = int(e.crossings.size()) - SurfaceChanges(store_, e.border);
    fallback[i] = opt_.fallback && int(e.crossings.size()) > opt_.fallbackMaxChanges &&
                  (opt_.fallbackShadingChanges < 0 || shading > opt_.fallbackShadingChanges);
    e.probe = !fallback[i] && opt_.fallback && opt_.finestCentreProbe && e.block.HasInterior() &&
              ProbeWanted(e, shading);
    if (e.probe) store_.Request(e.block.Centre().x, e.block.Centre().y, SampleReason::kCentreProbe);
  });
  if (opt_.fallback && opt_.finestCentreProbe) DCM_RETURN_IF_ERROR(ProbeCentres(eb, fallback));
  for (size_t i = 0; i < eb.size(); ++i) {
    const EdgeBlock& e = eb[i];
    const BlockType type = fallback[i] ? BlockType::kFallback
                           : e.crossings.size() <= 2 ? BlockType::kSimpleEdge : BlockType::kComplexEdge;
    (fallback[i] ? fallbackLeaves_ : orientedLeaves_).push_back(MakeLeaf(e.block, type, e.direction.index));
  }
  return Status::Ok();
}

void Engine::RequestFallbackInteriors() {
  // Every interior pixel exactly, and the border pixels not evaluated yet
  // unless adaptive borders filled them (or the options ask for those too).
  ForEach(fallbackLeaves_, [&](Leaf& l, size_t) {
    const Block& b = l.block;
    for (int y = b.y0; y <= b.y1; ++y)
      for (int x = b.x0; x <= b.x1; ++x) {
        const bool border = x == b.x0 || x == b.x1 || y == b.y0 || y == b.y1;
        if (border && !opt_.fallbackFilledBorders && store_.IsFilled(store_.Index(x, y))) continue;
        if (border) store_.Request(x, y, SampleReason::kFallback);
        else RequestOrDefer(x, y, SampleReason::kFallback);
      }
  });
}

}  // namespace dcm::detail
