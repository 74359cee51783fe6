// dcm's checkerboard refinement: of the pixels wanted exact, one colour
// first; the other filled where its exact neighbours agree.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "run_helpers.h"

namespace dcm::testing {
namespace {

// Checkerboard refinement: spindles one and two pixels wide at six slopes,
// shaded linearly along their length and crossed by a shadow band, on a
// shaded wall. Most of their pixels are thin objects. Of those, the ones of
// the second checkerboard colour are filled from their exact neighbours
// along the spindle; at the shadow's edges the neighbours disagree and the
// pixels are evaluated.
TEST(Checkerboard, ASpindleNeedsEveryOtherPixel) {
  const int N = 256;
  constexpr double kGradient = 0.002;  ///< the shading's slope along a spindle, per pixel
  struct Spindle {
    double x0, slope, width;
  };
  const Spindle spindles[] = {{20, 0, 1}, {50, 0.15, 2}, {110, -0.3, 1}, {130, 0.5, 2}, {150, 1.0, 1}, {200, -0.08, 1}};
  auto on = [&](int x, int y) {
    for (int k = 0; k < 6; ++k) {
      const Spindle& s = spindles[k];
      const double d = std::fabs(x + 0.5 - (s.x0 + s.slope * (y + 0.5))) / std::sqrt(1 + s.slope * s.slope);
      if (d < 0.5 * s.width) return k + 2;
    }
    return 0;
  };
  auto inShadow = [](int y) { return y >= 120 && y < 136; };
  AnalyticProvider provider(N, N, [&](int x, int y) {
    PixelTruth t;
    const int id = on(x, y);
    t.objectId = t.shaderId = uint32_t(id ? id : 1);
    const double l = id ? (0.5 + kGradient * y) * (inShadow(y) ? 0.4 : 1.0) : 0.2 + 0.001 * x;
    t.Li = RGB::Gray(float(l));
    return t;
  });
  const auto full = provider.FullRender();
  // One neighbouring direction each side: every direction serves most of
  // the spindles' pixels along their own (ThinObjects.ANeighbouring...),
  // and this test is about the pixels that remain thin objects.
  ReconstructionOptions checker;
  checker.neighbourDirections = 1;
  ReconstructionOptions every = checker;
  every.checkerboard = false;
  const Reconstruction r = ReconstructOrFail(provider, checker), e = ReconstructOrFail(provider, every);
  const auto wanted = [](const Reconstruction& x) {
    return x.stats.byReason[size_t(SampleReason::kThinObject)] + x.stats.byReason[size_t(SampleReason::kFallback)];
  };
  // The pixels filled: exact without the refinement, interpolated with it
  // (every earlier decision is the same).
  int64_t filled = 0, shadowEdge = 0;
  double worst = 0;
  for (int y = 0; y < N; ++y)
    for (int x = 0; x < N; ++x) {
      const size_t i = size_t(y) * N + size_t(x);
      // Deferred (second colour, wanted exact) and evaluated after all, at
      // the shadow's edges.
      const bool atEdge = inShadow(y) != inShadow(y - 1) || inShadow(y) != inShadow(y + 1);
      if (on(x, y) && atEdge && (x + y) % 2 == 1 && e.sampleMap[i] != SampleReason::kInterpolated &&
          r.sampleMap[i] != SampleReason::kInterpolated)
        ++shadowEdge;
      if (e.sampleMap[i] == SampleReason::kInterpolated || r.sampleMap[i] != SampleReason::kInterpolated) continue;
      ++filled;
      worst = std::max(worst, double(std::fabs(Luminance(r.workImage[i]) - Luminance(full[i]))));
    }
  std::printf("spindles: %lld thin-object and fallback samples with the checkerboard, %lld without; %lld filled, "
              "%lld evaluated at the shadow's edges, worst error of the filled %.2e\n",
              (long long)wanted(r), (long long)wanted(e), (long long)filled, (long long)shadowEdge, worst);
  EXPECT_EQ(r.stats.checkerboardFilled, filled);
  // Where a spindle is a thin object, every other pixel has an opposite pair
  // of exact neighbours on it; where a pixel of the second colour is wanted
  // alone (its neighbours along the spindle interpolated), none. Measured:
  // 33 % saved; at least a quarter.
  EXPECT_GT(wanted(e), 300);
  EXPECT_LT(wanted(r), wanted(e) * 3 / 4);
  // The mean of an opposite pair is exact on a linear ramp: what remains is
  // float rounding. A pixel filled across the shadow's edge would be off by
  // 0.3 or more (luminance 0.5-0.77 lit, 0.4 times that in the shadow).
  EXPECT_LT(worst, 1e-5);
  EXPECT_GT(shadowEdge, 0);
}

}  // namespace
}  // namespace dcm::testing
