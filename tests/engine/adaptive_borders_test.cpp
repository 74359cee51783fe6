// dcm's adaptive borders: surface changes and bisection along each side of
// an edge block, and the crossing fill between lattice lines.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "noisy_provider.h"
#include "run_helpers.h"

namespace dcm::testing {
namespace {

// Interleaved crossings (supersampled input): spindles two pixels wide,
// leaning 1 in 4, every 6 pixels, so that the finest level is reached. Each
// surface is shaded linearly; a deferred pixel at a surface change on a line
// a level below the elementary block adds takes the mean of its surface's
// exact pixels on the neighbouring lines. On the right half, bands of shadow
// 8 rows high start on the rows the finest level adds: there the rows above
// and below a deferred pixel are one lit, one shadowed, and the pixel is
// evaluated; the rows of the 8-pixel level run inside the bands, between lit
// rows, and their pixels are evaluated when the finest level splits the
// blocks at the bands' edges.
TEST(CrossingFill, AnEdgeAcrossThreeLatticeLinesIsSampledOnTheOuterTwo) {
  const int N = 256;  // working pixels; 128 after the box filter
  constexpr double kGradient = 0.002;  ///< the gentle shading's slope, per pixel
  // Rows 8k+4 to 8k+11 of odd k are in shadow on the right half.
  auto shadowed = [](int x, int y) { return x >= N / 2 && ((y + 4) / 8) % 2 == 1; };
  auto onSpindle = [](int x, int y) { return ((int(std::floor(x + 0.5 - 0.25 * (y + 0.5))) % 6) + 6) % 6 < 2; };
  AnalyticProvider provider(N, N, [&](int x, int y) {
    PixelTruth t;
    const bool spindle = onSpindle(x, y);
    t.objectId = t.shaderId = spindle ? 2u : 1u;
    const double lit = spindle ? 0.3 + kGradient * y : 0.15 + kGradient * (x + y);
    t.Li = RGB::Gray(float(lit * (shadowed(x, y) ? 0.4 : 1.0)));
    return t;
  });
  const auto full = provider.FullRender();
  ReconstructionOptions fill;
  fill.downsample = 2;
  ReconstructionOptions none = fill;
  none.crossingFillReach = 0;
  const Reconstruction r = ReconstructOrFail(provider, fill), e = ReconstructOrFail(provider, none);
  // The candidates: pixels beside a surface change along a line a level
  // below the elementary block adds (4 mod 8, the finest; 8 mod 16), not at
  // a corner of that level's blocks.
  int64_t filledLeft = 0, filledRight = 0, candidatesRight = 0;  // right: the rows between shadow bands
  double worst = 0;
  for (int y = 0; y < N; ++y)
    for (int x = 0; x < N; ++x) {
      auto added = [](int across, int along) {
        return (across % 8 == 4 && along % 4 != 0) || (across % 16 == 8 && along % 8 != 0);
      };
      const bool row = added(y, x), column = added(x, y);
      auto change = [&](int dx, int dy) {
        const int u = x + dx, v = y + dy;
        return u >= 0 && v >= 0 && u < N && v < N && onSpindle(u, v) != onSpindle(x, y);
      };
      const bool candidate = (row && (change(-1, 0) || change(1, 0))) || (column && (change(0, -1) || change(0, 1)));
      const size_t i = size_t(y) * N + size_t(x);
      if (!candidate || e.sampleMap[i] == SampleReason::kInterpolated) continue;
      const bool across = row && x >= N / 2;
      candidatesRight += across;
      if (r.sampleMap[i] != SampleReason::kInterpolated) continue;
      (across ? filledRight : filledLeft) += 1;
      worst = std::max(worst, double(std::fabs(Luminance(r.workImage[i]) - Luminance(full[i]))));
    }
  const auto border = size_t(SampleReason::kBorder);
  std::printf("spindles at 4x: border samples %lld with the fill, %lld without; %lld crossings filled (left %lld, "
              "right-half rows %lld of %lld), worst error of the filled %.2e; exact %.2f %% against %.2f %%\n",
              (long long)r.stats.byReason[border], (long long)e.stats.byReason[border],
              (long long)r.stats.crossingsFilled, (long long)filledLeft, (long long)filledRight,
              (long long)candidatesRight, worst, 100 * r.stats.exactFraction(), 100 * e.stats.exactFraction());
  ASSERT_GT(candidatesRight, 100) << "the shadow bands' rows must reach the finest level";
  // Where the shading is linear many crossings are filled (measured: 1549
  // still interpolated, and 2.0 points fewer exact pixels). The stats count
  // every fill; a fill on a line of the 8-pixel level is evaluated after all
  // where a finer level's side needs that pixel (an end, or beside a surface
  // change on a side that is not interleaved there).
  EXPECT_LE(filledLeft + filledRight, r.stats.crossingsFilled);
  EXPECT_GT(filledLeft, 500);
  EXPECT_LT(r.stats.exactPixels, e.stats.exactPixels);
  // One neighbouring row lit, the other in shadow (contrast (1 - 0.4) /
  // (1 + 0.4) = 0.43, against the threshold 0.08): never filled.
  EXPECT_EQ(filledRight, 0);
  // The mean of two samples of a linear ramp 4 pixels across on either side
  // and at most 2 along: off by at most 2 pixels of the slope on each
  // (0.004 for the background's slope along both axes; 0.008 bounds both).
  EXPECT_LE(worst, 4 * kGradient + 1e-5);
  // The supersampled rules are on here; at final resolution, or with noisy
  // samples (the noise regime's settings hold at every supersampling), they
  // and the fill are off.
  EXPECT_TRUE(r.stats.usedSupersampledRules);
  ReconstructionOptions final1 = fill;
  final1.downsample = 1;
  const Reconstruction f1 = ReconstructOrFail(provider, final1);
  EXPECT_FALSE(f1.stats.usedSupersampledRules);
  EXPECT_EQ(f1.stats.crossingsFilled, 0);
  NoisyProvider noisy(provider, NoiseModel{0.02f, 0.002f, 3});
  const Reconstruction n = ReconstructOrFail(noisy, fill);
  EXPECT_FALSE(n.stats.usedSupersampledRules);
  EXPECT_EQ(n.stats.crossingsFilled, 0);
}

}  // namespace
}  // namespace dcm::testing
