// The texture split (paper 3.3): (L_i, L_c) interpolated, tau re-applied
// per pixel, so texture detail is no lighting detail.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>

#include "../../lib/src/contrast_test.h"

#include "run_helpers.h"

namespace dcm::testing {
namespace {

// 3.3: with the texture split a textured floor needs several times fewer
// exact pixels at equal error (the paper: 17.8 % -> 3.6 %).
TEST(TextureSplit, TexturedFloorNeedsSeveralTimesFewerSamples) {
  const int N = 256;
  FurnishedOptions floorOnly;
  floorOnly.disc = floorOnly.thinLine = floorOnly.hdr = false;
  auto floorPixel = [&](int, int y) { return (float(y) + 0.5f) / float(N) > 0.62f; };
  auto fractionOnFloor = [&](const Reconstruction& r) {
    int64_t exact = 0, total = 0;
    for (int y = 0; y < N; ++y)
      for (int x = 0; x < N; ++x)
        if (floorPixel(x, y)) {
          ++total;
          exact += r.sampleMap[size_t(y) * N + size_t(x)] != SampleReason::kInterpolated;
        }
    return double(exact) / double(total);
  };
  AnalyticProvider provider(N, N, FurnishedScene(N, N, floorOnly));
  const auto full = provider.FullRender();
  ReconstructionOptions noSplit;
  noSplit.textureSplit = false;
  const Reconstruction guo = ReconstructOrFail(provider, noSplit);
  const double targetPsnr = DisplayPsnr(guo.workImage, full);
  EXPECT_FALSE(guo.stats.usedSplit);
  // Equal error: the coarsest threshold at which the split is at least as
  // accurate as the unsplit reconstruction.
  double best = 1.0;
  for (float threshold : {0.06f, 0.1f, 0.15f, 0.25f, 0.4f}) {
    ReconstructionOptions split;
    split.contrastThreshold = threshold;
    const Reconstruction r = ReconstructOrFail(provider, split);
    EXPECT_TRUE(r.stats.usedSplit);
    if (DisplayPsnr(r.workImage, full) >= targetPsnr) best = std::min(best, fractionOnFloor(r));
  }
  std::printf("floor exact fraction at %.1f dB: %.4f without the split, %.4f with\n", targetPsnr,
              fractionOnFloor(guo), best);
  // Several times fewer exact pixels on the floor (the paper: 4.9x).
  EXPECT_GT(fractionOnFloor(guo), 3.0 * best);
}

// With the split, a change of L_c counts against L = L_i tau + L_c, the
// radiance seen: on a dark glossy surface (tau 0.05) under bright light
// (L_i 2), a highlight that raises L_c from 0.03 to 0.5 raises L from 0.13 to
// 0.6. Against L_i + L_c it would be a change of 10 %, below the threshold.
TEST(TextureSplit, AHighlightOnADarkSurfaceIsAnEdge) {
  const detail::ContrastTest contrast(ContrastMetric::kMitchell, 0.12f, /*split=*/true);
  detail::Value dull{RGB::Gray(2.f), RGB::Gray(0.03f)}, lit{RGB::Gray(2.f), RGB::Gray(0.5f)};
  dull.tau = lit.tau = 0.05f;
  EXPECT_NEAR(contrast.Contrast(std::array{dull, lit}), 0.47 / (0.13 + 0.6), 1e-5);
  EXPECT_TRUE(contrast.Differ(dull, lit));
  // On a white surface the same change of L_c is 2.03 -> 2.5: no edge.
  dull.tau = lit.tau = 1.f;
  EXPECT_FALSE(contrast.Differ(dull, lit));
}

// The same highlight in a render: a 3-pixel blob of L_c on a dark surface,
// where the centre probe of the smooth 16x16 block lands on it. It must be
// found and evaluated, not interpolated away from the block's corners.
TEST(TextureSplit, AHighlightOnADarkSurfaceSurvives) {
  const int N = 64;
  constexpr double cx = 40, cy = 40;  ///< the centre of the block [32, 48]^2
  auto blob = [&](int x, int y) { return std::exp(-((x - cx) * (x - cx) + (y - cy) * (y - cy)) / 2.0); };
  AnalyticProvider provider(N, N, [&](int x, int y) {
    PixelTruth t;
    t.tau = RGB::Gray(0.05f);
    t.Li = RGB::Gray(2.f);
    t.Lc = RGB::Gray(float(0.03 + 0.47 * blob(x, y)));
    return t;
  });
  const auto full = provider.FullRender();
  const Reconstruction r = ReconstructOrFail(provider, ReconstructionOptions{});
  auto onBlob = [&](int x, int y) { return blob(x, y) > 0.3; };
  const double err = MeanLuminanceError(r, full, onBlob);
  double rise = 0;  // what the blob adds to L on its pixels, on average
  int n = 0;
  for (int y = 0; y < N; ++y)
    for (int x = 0; x < N; ++x)
      if (onBlob(x, y)) rise += 0.47 * blob(x, y), ++n;
  rise /= n;
  std::printf("highlight: error %.4f on the blob (its rise %.4f), %.2f %% exact\n", err, rise,
              100 * r.stats.exactFraction());
  // Interpolated away from the corners, the error would be the whole rise.
  // Found, the blob's pixels are exact or interpolated along the finest
  // blocks' borders through it, which round its peak off: a quarter at most.
  EXPECT_LT(err, 0.25 * rise);
}

TEST(TextureSplit, NoSplitWhenTheSceneHasNoTexture) {
  AnalyticProvider p(32, 32, FurnishedScene(32, 32), AnalyticChannels{true, true, false});
  const Reconstruction r = ReconstructOrFail(p, ReconstructionOptions{});
  EXPECT_FALSE(r.stats.usedSplit);
}

}  // namespace
}  // namespace dcm::testing
