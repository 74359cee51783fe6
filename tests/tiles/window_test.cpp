// Regions reconstructed through a WindowProvider are bit-identical to the same
// pixels of a whole-frame reconstruction (the engine-level half of tiles; the
// `dcm render|reconstruct --tile` + `dcm merge` half is in cli_tiles_test.cpp).
#include <gtest/gtest.h>

#include <cstring>
#include <string>
#include <vector>

#include "analytic_provider.h"
#include "noisy_provider.h"
#include "dcm/reconstructor.h"
#include "dcm/window_provider.h"

namespace dcm::testing {
namespace {

bool SameBits(const RGB& a, const RGB& b) { return std::memcmp(&a, &b, sizeof(RGB)) == 0; }

struct Case {
  std::string name;
  int width, height, downsample;
  ReconstructionOptions options;
  bool noisy = false;  ///< Monte Carlo noise with its variance: significance tests and sample denoising
  bool creases = false;  ///< normal guides whose creases cut the objects into regions
};

/// The furnished scene with a comb of creases: slots 3 pixels wide, every 20
/// pixels, from the top to three quarters down, whose normal is turned by
/// 90 degrees (regions: Crease.RegionsAreDecidedInsideOneCellOfTheLattice).
SceneFunction Creased(int width, int height) {
  const SceneFunction base = FurnishedScene(width, height);
  return [base, height](int x, int y) {
    PixelTruth t = base(x, y);
    const bool slot = x % 20 >= 9 && x % 20 < 12 && y < height * 3 / 4;
    t.normal = slot ? Vec3f{0.f, 1.f, 0.f} : Vec3f{0.f, 0.f, 1.f};
    return t;
  };
}

/// The case's provider: the furnished scene, with noise for noisy cases.
struct CaseProvider {
  explicit CaseProvider(const Case& c)
      : exact(c.width, c.height, c.creases ? Creased(c.width, c.height) : FurnishedScene(c.width, c.height),
              AnalyticChannels{.normals = c.creases}),
        noisy(exact, NoiseModel{0.1f, 0.01f, 7}) {}
  SampleProvider& Get(const Case& c) { return c.noisy ? static_cast<SampleProvider&>(noisy) : exact; }
  AnalyticProvider exact;
  NoisyProvider noisy;
};

std::vector<Case> Cases() {
  std::vector<Case> cases;
  ReconstructionOptions dcm;
  dcm.threads = 2;
  cases.push_back({"dcm 160x128", 160, 128, 1, dcm});
  cases.push_back({"dcm odd 157x101", 157, 101, 1, dcm});
  ReconstructionOptions ss = dcm;
  ss.downsample = 2;
  cases.push_back({"dcm supersampled 2, odd 198x134", 198, 134, 2, ss});
  ReconstructionOptions ss3 = dcm;
  ss3.downsample = 3;
  cases.push_back({"dcm supersampled 3, 201x150", 201, 150, 3, ss3});
  ReconstructionOptions paper = ReconstructionOptions::Paper();
  paper.threads = 2;
  cases.push_back({"paper 131x97", 131, 97, 1, paper});
  ReconstructionOptions guo = ReconstructionOptions::Guo();
  guo.threads = 2;
  cases.push_back({"guo 120x88", 120, 88, 1, guo});
  ReconstructionOptions always = dcm;
  always.smoothRefinement = SmoothRefinement::kAlways;
  always.minBlock = 2;
  always.elementaryBlock = 32;
  cases.push_back({"32/2 blocks, always split 170x140", 170, 140, 1, always});
  ReconstructionOptions full = dcm;
  full.adaptiveBorders = false;
  full.lazyEvaluation = false;
  cases.push_back({"full borders, no lazy 150x150", 150, 150, 1, full});
  cases.push_back({"noisy samples, denoised, 157x101", 157, 101, 1, dcm, true});
  cases.push_back({"noisy samples, denoised, supersampled 2, 198x134", 198, 134, 2, ss, true});
  ReconstructionOptions plain = dcm;
  plain.denoiseSamples = false;
  cases.push_back({"noisy samples, not denoised, 150x118", 150, 118, 1, plain, true});
  cases.push_back({"normal guides with creases, 160x128", 160, 128, 1, dcm, false, true});
  cases.push_back({"normal guides with creases, noisy, supersampled 2, 198x134", 198, 134, 2, ss, true, true});
  return cases;
}

/// Compares every tile of an N-way split against the whole frame; returns the
/// number of pixels that differ (image or sample map) and checks the counts.
int64_t CompareTiles(const Case& c, int count, int halo, bool expectOk) {
  CaseProvider cp(c);
  SampleProvider& p = cp.Get(c);
  Reconstruction whole;
  Status st = Reconstruct(p, c.options, &whole);
  EXPECT_TRUE(st.ok()) << st.message();
  if (!st.ok()) return -1;
  // Every rule that reads beyond its own pixel is exercised: the
  // supersampled cases without noise fill crossings from the neighbouring
  // lattice lines.
  EXPECT_EQ(whole.stats.usedSupersampledRules, c.downsample >= 2 && !c.noisy) << c.name;
  if (whole.stats.usedSupersampledRules && c.options.adaptiveBorders && c.options.crossingFillReach > 0) {
    EXPECT_GT(whole.stats.crossingsFilled, 0) << c.name;
  }
  int64_t differ = 0, exact = 0;
  std::vector<int> covered(size_t(whole.width) * size_t(whole.height), 0);
  const int align = std::max(1, LargestElementaryBlock(c.options) / std::max(1, c.options.downsample));
  for (int i = 0; i < count; ++i) {
    Bounds2i region;
    st = TileRegion(whole.width, whole.height, i, count, align, &region);
    EXPECT_TRUE(st.ok()) << st.message();
    if (!st.ok()) return -1;
    Reconstruction part;
    RegionInfo info;
    st = ReconstructRegion(p, c.options, region, &part, &info, nullptr,
                           halo < 0 ? RegionHaloBlocks(c.options, p.Capabilities()) : halo);
    EXPECT_TRUE(st.ok()) << st.message();
    if (!st.ok()) return -1;
    EXPECT_EQ(part.width, region.width());
    EXPECT_EQ(part.height, region.height());
    for (int y = 0; y < part.height; ++y)
      for (int x = 0; x < part.width; ++x) {
        const size_t g = size_t(y + region.min.y) * size_t(whole.width) + size_t(x + region.min.x);
        ++covered[g];
        differ += !SameBits(part.image[size_t(y) * size_t(part.width) + size_t(x)], whole.image[g]);
      }
    for (int y = 0; y < part.workHeight; ++y)
      for (int x = 0; x < part.workWidth; ++x) {
        const size_t g = size_t(y + info.work.min.y) * size_t(whole.workWidth) + size_t(x + info.work.min.x);
        const size_t l = size_t(y) * size_t(part.workWidth) + size_t(x);
        differ += part.sampleMap[l] != whole.sampleMap[g];
      }
    exact += part.stats.exactPixels;
  }
  for (int v : covered) EXPECT_EQ(v, 1) << c.name << ": tiles must cover the frame once";
  if (expectOk && differ == 0) {
    EXPECT_EQ(exact, whole.stats.exactPixels) << c.name;
  }
  return differ;
}

TEST(Tiles, RegionsAreBitIdenticalToTheWholeFrame) {
  for (const Case& c : Cases())
    for (int n : {2, 3, 8}) {
      SCOPED_TRACE(c.name + ", " + std::to_string(n) + " tiles");
      EXPECT_EQ(CompareTiles(c, n, -1, true), 0);
    }
}

TEST(Tiles, ASmallerHaloIsNotEnough) {
  // The halo is necessary: without it, pixels near tile boundaries change
  // (a neighbouring block's refinement makes shared side pixels exact). This
  // keeps the bit-identity test above honest: it can fail.
  int64_t differ = 0;
  for (const Case& c : Cases()) differ += CompareTiles(c, 8, 0, false);
  std::printf("pixels differing without a halo, over all cases: %lld\n", static_cast<long long>(differ));
  EXPECT_GT(differ, 0);
  // Denoised noisy samples are local fits over an elementary block around each
  // exact sample: one block of halo is not enough, two are (RegionHaloBlocks).
  differ = 0;
  for (const Case& c : Cases())
    if (c.noisy && c.options.denoiseSamples) differ += CompareTiles(c, 8, 1, false);
  std::printf("pixels differing with a halo of one block, denoised noisy cases: %lld\n",
              static_cast<long long>(differ));
  EXPECT_GT(differ, 0);
}

TEST(Tiles, ArbitraryRegionsAreBitIdentical) {
  const Case c = Cases()[2];  // supersampled, odd size
  AnalyticProvider p(c.width, c.height, FurnishedScene(c.width, c.height));
  Reconstruction whole;
  ASSERT_TRUE(Reconstruct(p, c.options, &whole).ok());
  for (Bounds2i region : {Bounds2i{{0, 0}, {1, 1}}, Bounds2i{{13, 7}, {14, 60}}, Bounds2i{{50, 31}, {99, 67}},
                          Bounds2i{{98, 0}, {99, 67}}, Bounds2i{{0, 0}, {99, 67}}}) {
    Reconstruction part;
    Status st = ReconstructRegion(p, c.options, region, &part);
    ASSERT_TRUE(st.ok()) << st.message();
    for (int y = 0; y < part.height; ++y)
      for (int x = 0; x < part.width; ++x)
        ASSERT_TRUE(SameBits(part.image[size_t(y) * size_t(part.width) + size_t(x)],
                             whole.image[size_t(y + region.min.y) * size_t(whole.width) + size_t(x + region.min.x)]))
            << "region " << region.min.x << "," << region.min.y << " pixel " << x << "," << y;
  }
}

TEST(Tiles, WindowIsTheRegionOnTheLatticeWithAHalo) {
  // 100x60 output, 2x supersampling: 200x120 working pixels, 16-pixel blocks.
  const Bounds2i w = RegionWindow({{20, 10}, {40, 30}}, 200, 120, 2, 16, 1);
  // Work region [40, 80) x [20, 60): lattice [32, 80] x [16, 64], halo 16.
  EXPECT_EQ(w, (Bounds2i{{16, 0}, {97, 81}}));
  // At the frame's edges the window is clamped.
  EXPECT_EQ(RegionWindow({{0, 0}, {100, 60}}, 200, 120, 2, 16, 1), (Bounds2i{{0, 0}, {200, 120}}));
  EXPECT_EQ(RegionWindow({{0, 0}, {8, 8}}, 200, 120, 2, 16, 0), (Bounds2i{{0, 0}, {17, 17}}));
}

TEST(Tiles, TileGridCoversTheFrameOnTheLattice) {
  for (int n : {1, 2, 3, 5, 7, 8, 12}) {
    std::vector<int> covered(512 * 300, 0);
    for (int i = 0; i < n; ++i) {
      Bounds2i r;
      ASSERT_TRUE(TileRegion(512, 300, i, n, 8, &r).ok());
      for (int v : {r.min.x, r.max.x}) EXPECT_TRUE(v % 8 == 0 || v == 512) << v;
      for (int v : {r.min.y, r.max.y}) EXPECT_TRUE(v % 8 == 0 || v == 300) << v;
      for (int y = r.min.y; y < r.max.y; ++y)
        for (int x = r.min.x; x < r.max.x; ++x) ++covered[size_t(y) * 512 + size_t(x)];
    }
    for (int v : covered) ASSERT_EQ(v, 1) << n << " tiles";
  }
  EXPECT_EQ(TileGridShape(512, 512, 8), (Point2i{4, 2}));  // 4 columns x 2 rows
  Bounds2i r;
  EXPECT_FALSE(TileRegion(512, 512, 8, 8, 8, &r).ok());   // 0-based: 0..7
  EXPECT_FALSE(TileRegion(512, 512, -1, 8, 8, &r).ok());
  EXPECT_FALSE(TileRegion(2, 2, 0, 5, 1, &r).ok());        // 5 tiles of 4 pixels: impossible
  EXPECT_TRUE(TileRegion(3, 2, 4, 6, 8, &r).ok());         // too small for the lattice: even split
  EXPECT_EQ(r.area(), 1);
}

TEST(Tiles, WindowProviderRejectsWindowsOutsideTheImage) {
  AnalyticProvider p(64, 64, Constant(RGB::Gray(1)));
  EXPECT_FALSE(WindowProvider(p, {{0, 0}, {65, 10}}).Validate().ok());
  EXPECT_FALSE(WindowProvider(p, {{10, 10}, {10, 20}}).Validate().ok());
  WindowProvider w(p, {{16, 8}, {33, 41}});
  ASSERT_TRUE(w.Validate().ok());
  EXPECT_EQ(w.Capabilities().width, 17);
  EXPECT_EQ(w.Capabilities().height, 33);
  std::vector<ExactSample> out(1);
  const Point2i outside{17, 0};
  EXPECT_FALSE(w.Evaluate({&outside, 1}, {}, out).ok());
}

}  // namespace
}  // namespace dcm::testing
