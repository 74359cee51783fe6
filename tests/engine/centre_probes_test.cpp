// dcm's centre probes of the finest edge blocks: the centre is evaluated
// where its interpolation may miss a highlight or a shading edge.
#include <gtest/gtest.h>

#include <cstdio>

#include "run_helpers.h"

namespace dcm::testing {
namespace {

// The centre probe of the finest edge blocks looks for detail the border
// does not show. Where the border changes only at surface changes, it stays
// where glossy light (L_c) is more than half of L at some pixel of the
// border (a highlight or a reflection can hide inside the block) and is
// skipped on diffuse surfaces: the surfaces explain the border there.
// (Where a change is no surface change, the probe stays:
// ReconstructionQuality.PureNoiseFallsBackToTheFullRender.) Two halves of
// one picture: the same stripes of objects with equal radiance (so the
// blocks along their boundaries are edge blocks whose borders change only
// at surface changes), diffuse on the left, glossy on the right (L_c 0.8
// against L_i tau 0.4 to 0.6).
TEST(TextureSplit, CentreProbesOnlyWhereAHighlightCanHide) {
  const int N = 128;
  // Stripes about 10 pixels apart: two boundaries cross many 8x8 blocks,
  // which split into 4x4 children, finest edge blocks.
  const int kPeriod = 23;
  AnalyticProvider provider(N, N, [&](int x, int y) {
    PixelTruth t;
    t.objectId = t.shaderId = 1 + uint32_t((x + 2 * y) / kPeriod) % 4;  // diagonal stripes, one shading
    t.tau = RGB::Gray(0.8f);
    t.Li = RGB::Gray(float(0.5 + 0.001 * x + 0.002 * y));
    t.Lc = RGB::Gray(x < N / 2 ? 0.f : 0.8f);
    return t;
  });
  // Probes of blocks wholly on one side (a 4x4 block whose border reaches
  // x = N/2 has its centre at N/2 - 2 or beyond).
  auto probesIn = [&](const Reconstruction& r, bool glossy) {
    int n = 0;
    for (int y = 0; y < N; ++y)
      for (int x = 0; x < N; ++x)
        n += (glossy ? x >= N / 2 : x < N / 2 - 2) && r.sampleMap[size_t(y * N + x)] == SampleReason::kCentreProbe;
    return n;
  };
  ReconstructionOptions everywhere;
  everywhere.probeLcShare = 0.f;
  const Reconstruction all = ReconstructOrFail(provider, everywhere);
  const Reconstruction r = ReconstructOrFail(provider, ReconstructionOptions{});
  std::printf("centre probes: diffuse %d of %d, glossy %d of %d\n", probesIn(r, false), probesIn(all, false),
              probesIn(r, true), probesIn(all, true));
  ASSERT_GT(probesIn(all, false), 100);
  EXPECT_EQ(probesIn(r, false), 0);
  EXPECT_GT(probesIn(r, true), 100);
  EXPECT_EQ(probesIn(r, true), probesIn(all, true));
  // Nothing was hidden, so the skipped centres interpolate as well as the
  // rest: the field is linear on each surface, and the only error is where a
  // snapped border point (end-differs) lies, less than a pixel from the
  // exit point: below one pixel's step of the shading (0.002 * 0.8).
  const auto full = provider.FullRender();
  auto diffuse = [&](int x, int) { return x < N / 2; };
  EXPECT_LT(MeanLuminanceError(r, full, diffuse), 0.0016);
}

}  // namespace
}  // namespace dcm::testing
