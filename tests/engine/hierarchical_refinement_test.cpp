// Hierarchical refinement (paper 2.1) with the smooth/edge classification
// (2.2): what happens to smooth blocks above the finest level.
#include <gtest/gtest.h>

#include <cmath>

#include "run_helpers.h"

namespace dcm::testing {
namespace {

// A provider whose guides show every hard shadow gets no centre probes of
// smooth blocks: on a flat 64x64 image, the 16 probes of the level-0 blocks
// (one per 16x16 block) are exactly what it saves. A shadow dot of 3 pixels
// at a block's centre that the guides do not show (a provider that claims
// the capability wrongly) is then missed; with the probe it is found.
TEST(SmoothRefinement, NoCentreProbesWhereTheGuidesShowTheHardShadows) {
  constexpr int N = 64;
  auto dot = [](int x, int y) { return std::abs(x - 40) <= 1 && std::abs(y - 40) <= 1; };
  const SceneFunction scene = [&](int x, int y) {
    PixelTruth t;
    t.Li = RGB::Gray(dot(x, y) ? 0.05f : 0.5f);
    return t;
  };
  AnalyticChannels probed, guided;
  guided.hardShadowsGuided = true;
  AnalyticProvider withProbes(N, N, scene, probed), withoutProbes(N, N, scene, guided);
  const Reconstruction a = ReconstructOrFail(withProbes, {}), b = ReconstructOrFail(withoutProbes, {});
  EXPECT_EQ(ResolveSettings({}, withProbes.Capabilities()).smoothRefinement, SmoothRefinement::kCentreProbe);
  EXPECT_EQ(ResolveSettings({}, withoutProbes.Capabilities()).smoothRefinement, SmoothRefinement::kNever);
  // Noisy samples keep the probes (the denoising fits use them too).
  ProviderCapabilities noisy = withoutProbes.Capabilities();
  noisy.variance = true;
  EXPECT_EQ(ResolveSettings({}, noisy).smoothRefinement, SmoothRefinement::kCentreProbe);
  const auto corner = size_t(SampleReason::kCorner);
  EXPECT_EQ(b.stats.byReason[corner], 25);  // the 5x5 corners of the 16-pixel lattice
  const int64_t blocks = (N / 16) * (N / 16);
  EXPECT_GE(a.stats.byReason[corner], b.stats.byReason[corner] + blocks);
  // The dot: exact with the probes (its centre is the probe of block
  // [32,48]^2), interpolated over without them (error = its full depth).
  const auto full = withProbes.FullRender();
  const auto onDot = [&](int x, int y) { return dot(x, y); };
  EXPECT_LT(MeanLuminanceError(a, full, onDot), 0.05);
  EXPECT_NEAR(MeanLuminanceError(b, full, onDot), 0.45, 1e-3);
}

// A bump between the corners of one elementary block (paper 2.1: "in order
// not to miss any features, the four children of a smooth block undergo the
// same classification"). Every level-0 block is smooth by its corners. The
// paper's refinement splits every one of them; dcm's centre probe splits
// only the block whose centre the bilinear prediction misses; without
// refinement the bump is lost.
TEST(SmoothRefinement, TheCentreProbeSplitsOnlyTheBlockWhoseCentreIsMissed) {
  const int N = 65;  // 8 x 8 elementary blocks of 8, 9 x 9 lattice points
  const int kBumpedX0 = 16, kBumpedY0 = 16;  // the block (16,16)-(24,24)
  auto scene = [](int x, int y) {
    PixelTruth t;
    t.Li = RGB::Gray(std::abs(x - 20) <= 1 && std::abs(y - 20) <= 1 ? 0.6f : 0.3f);
    return t;
  };
  auto run = [&](SmoothRefinement refinement) {
    AnalyticProvider provider(N, N, scene);
    ReconstructionOptions o;
    o.elementaryBlock = 8;  // levels of 8 and 4 (minBlock)
    o.smoothRefinement = refinement;
    return ReconstructOrFail(provider, o);
  };
  auto levelZeroSmooth = [](const Reconstruction& r) {
    int n = 0;
    for (const BlockRecord& b : r.blocks) n += b.level == 0 && b.type == BlockType::kSmooth;
    return n;
  };
  auto at = [&](const Reconstruction& r, int x, int y) { return r.workImage[size_t(y) * N + size_t(x)]; };

  const Reconstruction never = run(SmoothRefinement::kNever);
  EXPECT_EQ(levelZeroSmooth(never), 64);
  EXPECT_EQ(never.stats.exactPixels, 9 * 9);  // the lattice alone
  EXPECT_EQ(at(never, 20, 20), RGB::Gray(0.3f)) << "the bump is interpolated away";

  const Reconstruction probe = run(SmoothRefinement::kCentreProbe);
  EXPECT_EQ(levelZeroSmooth(probe), 63);
  for (const BlockRecord& b : probe.blocks) {
    if (b.level == 0) {
      EXPECT_FALSE(b.x0 == kBumpedX0 && b.y0 == kBumpedY0) << "the bumped block is not split";
    }
  }
  EXPECT_EQ(at(probe, 20, 20), RGB::Gray(0.6f));  // its centre is exact now

  const Reconstruction always = run(SmoothRefinement::kAlways);
  EXPECT_EQ(levelZeroSmooth(always), 0);
  // Every block split once, to the finest level: 16 x 16 blocks of 4, whose
  // 17 x 17 lattice points are all evaluated, the bump's centre among them.
  EXPECT_GE(always.stats.exactPixels, 17 * 17);
  EXPECT_EQ(at(always, 20, 20), RGB::Gray(0.6f));
}

}  // namespace
}  // namespace dcm::testing
