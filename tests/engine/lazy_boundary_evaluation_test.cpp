// Lazy boundary evaluation (paper 2.1): "for simple edge blocks only a lazy
// boundary evaluation is done. Here, only the center pixel (of the parent) is
// computed exactly and this value is compared to the result of the finite
// element approximation. If this does not differ significantly the old
// orientation of the finite elements is kept, the interpolation is just
// corrected with the new values."
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "run_helpers.h"

namespace dcm::testing {
namespace {

// A straight edge between two surfaces, each shaded linearly: every block it
// crosses is simple, and the oriented interpolation of its parent predicts
// each centre. The lazy evaluation settles those blocks at their level with
// one sample each, where the full evaluation refines them to the finest level
// with their borders.
TEST(LazyEvaluation, AStraightEdgeIsSettledByTheCentreAlone) {
  const int N = 128;
  constexpr double kSlope = 0.4;       ///< the edge: x = 40 + kSlope * y
  constexpr double kGradient = 0.002;  ///< the shading's slope, per pixel
  AnalyticProvider provider(N, N, [](int x, int y) {
    PixelTruth t;
    const bool right = x + 0.5 > 40 + kSlope * (y + 0.5);
    t.objectId = t.shaderId = right ? 2 : 1;
    t.Li = RGB::Gray(float(right ? 0.7 - kGradient * y : 0.2 + kGradient * x));
    return t;
  });
  const auto full = provider.FullRender();
  ReconstructionOptions lazyOff;
  lazyOff.lazyEvaluation = false;
  const Reconstruction lazy = ReconstructOrFail(provider, ReconstructionOptions{});
  const Reconstruction eager = ReconstructOrFail(provider, lazyOff);
  auto all = [](int, int) { return true; };
  const double errLazy = MeanLuminanceError(lazy, full, all), errEager = MeanLuminanceError(eager, full, all);
  std::printf("straight edge: lazy %lld exact pixels (%lld blocks settled, %lld refined), %.2e mean error; "
              "full boundary evaluation %lld, %.2e\n",
              (long long)lazy.stats.exactPixels, (long long)lazy.stats.lazyAccepted,
              (long long)lazy.stats.lazyRejected, errLazy, (long long)eager.stats.exactPixels, errEager);
  EXPECT_GT(lazy.stats.lazyAccepted, 0);
  EXPECT_EQ(eager.stats.lazyAccepted, 0);
  EXPECT_EQ(eager.stats.byReason[size_t(SampleReason::kLazyCentre)], 0);
  // Each settled block: its centre is exact, for the lazy evaluation, and
  // the block keeps a direction.
  int settled = 0;
  for (const BlockRecord& b : lazy.blocks) {
    if (b.type != BlockType::kLazy) continue;
    ++settled;
    const size_t c = size_t((b.y0 + b.y1) / 2) * N + size_t((b.x0 + b.x1) / 2);
    EXPECT_EQ(lazy.sampleMap[c], SampleReason::kLazyCentre);
    EXPECT_GE(b.direction, 0);
  }
  EXPECT_EQ(settled, lazy.stats.lazyAccepted);
  // One sample per settled block instead of the borders of its children.
  EXPECT_LT(lazy.stats.exactPixels, eager.stats.exactPixels);
  // Linear shading on each side is interpolated exactly from samples on its
  // own surface, lazily or not: the mean error stays below one pixel's step
  // of the shading.
  EXPECT_LT(errLazy, kGradient);
}

}  // namespace
}  // namespace dcm::testing
