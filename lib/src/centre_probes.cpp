// dcm's centre probes of the finest edge blocks: the centre is evaluated and
// compared with its oriented interpolation, an error estimate that refines
// below the finest block size (the block falls back where it misses).
#include "engine.h"

namespace dcm::detail {

bool Engine::LooksDiffuse(std::span<const Point2i> border) const {
  if (!settings_.split || !(opt_.probeLcShare > 0)) return false;
  for (Point2i p : border) {
    if (!store_.IsFinite(store_.Index(p.x, p.y))) continue;
    const Value v = At(p);
    const double lc = Luminance(v.b), l = Luminance(v.a) * v.tau + lc;
    if (!(lc <= opt_.probeLcShare * l)) return false;
  }
  return true;
}

Status Engine::ProbeCentres(std::vector<EdgeBlock>& eb, std::vector<uint8_t>& fallback) {
  DCM_RETURN_IF_ERROR(Flush());
  ForEach(eb, [&](EdgeBlock& e, size_t i) {
    if (!e.probe) return;
    const Point2i c = e.block.Centre();
    Interpolant in;
    if (!OrientedInterpolant(store_, e.block, c, Direction::Of(e.direction.index, settings_.directions), &in))
      return;
    // A centre on another surface than its interpolants is the thin object
    // test's business, not a miss.
    if (ResolveInterpolant(c, &in) != SampleReason::kInterpolated) return;
    fallback[i] = !store_.IsFinite(store_.Index(c.x, c.y)) || contrast_.Misses(At(c), Evaluate(store_, in));
  });
  return Status::Ok();
}

}  // namespace dcm::detail
