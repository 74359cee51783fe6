// Properties that hold for every reconstruction: range, determinism, one
// evaluation per sample, the record of reasons.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>

#include "run_helpers.h"

namespace dcm::testing {
namespace {

// Interpolation never leaves the range of the samples it interpolates: every
// interpolated pixel of a leaf block lies within the per-channel range of the
// exact samples on that block's closed region (untextured scene, so that the
// displayed value is the interpolated one).
TEST(Invariants, InterpolationStaysInTheRangeOfItsSamples) {
  const int N = 128;
  FurnishedOptions o;
  o.texture = false;
  AnalyticProvider p(N, N, FurnishedScene(N, N, o));
  for (const ReconstructionOptions& opt : {ReconstructionOptions{}, ReconstructionOptions::Paper(),
                                            ReconstructionOptions::Guo()}) {
    const Reconstruction r = ReconstructOrFail(p, opt);
    int checked = 0;
    for (const BlockRecord& b : r.blocks) {
      const int px0 = b.x0, py0 = b.y0, px1 = b.x1, py1 = b.y1;
      RGB lo = RGB::Gray(1e30f), hi = RGB::Gray(-1e30f);
      for (int y = py0; y <= py1; ++y)
        for (int x = px0; x <= px1; ++x) {
          const size_t i = size_t(y) * N + size_t(x);
          if (r.sampleMap[i] == SampleReason::kInterpolated) continue;
          for (int c = 0; c < 3; ++c) lo[c] = std::min(lo[c], r.workImage[i][c]), hi[c] = std::max(hi[c], r.workImage[i][c]);
        }
      for (int y = b.y0; y <= b.y1; ++y)
        for (int x = b.x0; x <= b.x1; ++x) {
          const size_t i = size_t(y) * N + size_t(x);
          if (r.sampleMap[i] != SampleReason::kInterpolated) continue;
          // Smooth leaves share edges with coarser neighbours; only their
          // interior is theirs alone.
          if (x == b.x0 || y == b.y0 || x == b.x1 || y == b.y1) continue;
          for (int c = 0; c < 3; ++c) {
            // Relative 1e-6: double weights rounded to float once.
            const float tol = 1e-6f * std::max(1.f, std::fabs(hi[c]));
            ASSERT_GE(r.workImage[i][c], lo[c] - tol) << "pixel " << x << "," << y;
            ASSERT_LE(r.workImage[i][c], hi[c] + tol) << "pixel " << x << "," << y;
          }
          ++checked;
        }
    }
    EXPECT_GT(checked, N * N / 2);
  }
}

TEST(Invariants, BitIdenticalForAnyThreadCountAndTileSize) {
  const int N = 200;  // not a multiple of the block size
  AnalyticProvider p(N, N, FurnishedScene(N, N));
  ReconstructionOptions base;
  base.threads = 1;
  base.tileSize = 8;
  const Reconstruction ref = ReconstructOrFail(p, base);
  for (int threads : {1, 2, 8})
    for (int tile : {8, 16, 64, 256}) {
      ReconstructionOptions o = base;
      o.threads = threads;
      o.tileSize = tile;
      o.batchSize = 97 * tile;  // batches of different sizes too
      const Reconstruction r = ReconstructOrFail(p, o);
      EXPECT_EQ(r.workImage, ref.workImage) << threads << " threads, tile " << tile;
      EXPECT_EQ(r.sampleMap, ref.sampleMap) << threads << " threads, tile " << tile;
      EXPECT_EQ(r.stats.exactPixels, ref.stats.exactPixels);
    }
}

TEST(Invariants, EachSampleIsEvaluatedOnce) {
  const int N = 160;
  for (const ReconstructionOptions& opt : {ReconstructionOptions{}, ReconstructionOptions::Paper(),
                                            ReconstructionOptions::Guo()}) {
    AnalyticProvider p(N, N, FurnishedScene(N, N));
    const Reconstruction r = ReconstructOrFail(p, opt);
    EXPECT_EQ(p.MaxEvaluationsOfOnePixel(), 1);
    EXPECT_EQ(p.TotalEvaluations(), r.stats.exactPixels);
  }
}

TEST(Invariants, ReasonsAddUpAndExactPixelsHoldTheirSamples) {
  const int N = 96;
  AnalyticProvider p(N, N, FurnishedScene(N, N));
  const Reconstruction r = ReconstructOrFail(p, ReconstructionOptions{});
  int64_t sum = 0;
  for (int64_t c : r.stats.byReason) sum += c;
  EXPECT_EQ(sum, r.stats.totalPixels);
  const auto full = p.FullRender();
  for (size_t i = 0; i < full.size(); ++i) {
    if (r.sampleMap[i] != SampleReason::kInterpolated) {
      ASSERT_EQ(r.workImage[i], full[i]) << i;
    }
  }
  EXPECT_GT(r.stats.byReason[size_t(SampleReason::kCorner)], 0);
  EXPECT_GT(r.stats.byReason[size_t(SampleReason::kBorder)], 0);
  EXPECT_GT(r.stats.byReason[size_t(SampleReason::kThinObject)], 0);
}

// A provider that renders in another process: the engine stops at the first
// phase and reports what it needs.
class PendingProvider final : public SampleProvider {
 public:
  ProviderCapabilities Capabilities() const override {
    ProviderCapabilities c;
    c.width = 17;
    c.height = 9;
    c.name = "pending";
    return c;
  }
  Status Guides(const Bounds2i&, const GuideRequest&, GuideImage*) override { return Status::Ok(); }
  Status Evaluate(std::span<const Point2i>, const SampleRequest&, std::span<ExactSample>) override {
    return Status::Pending("rendered elsewhere");
  }
};

TEST(Invariants, PendingProviderGetsTheFirstRoundOfRequests) {
  PendingProvider p;
  Reconstruction r;
  std::vector<Point2i> pending;
  ReconstructionOptions o;
  o.elementaryBlock = 8;
  const Status s = Reconstruct(p, o, &r, &pending);
  ASSERT_TRUE(s.pending());
  // The lattice corners of a 17x9 image: x in {0, 8, 16}, y in {0, 8}.
  EXPECT_EQ(pending.size(), 6u);
}

/// Options that `set` makes invalid are rejected with a message naming
/// `field` (and containing `got`, the value, when given).
template <typename Set>
void ExpectRejected(SampleProvider& p, Set set, const std::string& field, const std::string& got = "") {
  ReconstructionOptions o;
  set(o);
  Reconstruction r;
  const Status s = Reconstruct(p, o, &r);
  ASSERT_FALSE(s.ok()) << field;
  EXPECT_NE(s.message().find(field), std::string::npos) << s.message();
  if (!got.empty()) {
    EXPECT_NE(s.message().find(got), std::string::npos) << s.message();
  }
}

TEST(Invariants, InvalidOptionsNameTheField) {
  AnalyticProvider p(8, 8, Constant(RGB::Gray(1)));
  // Unset, the elementary block is at least the noiseless regime's; the finest block may not exceed it.
  ExpectRejected(p, [](ReconstructionOptions& o) { o.minBlock = 2 * LargestElementaryBlock(o); }, "minBlock");
  // A negative count of directions is no count; more than half the
  // directions is every direction (whatever their number), up to 32.
  ExpectRejected(p, [](ReconstructionOptions& o) { o.neighbourDirections = -1; }, "neighbourDirections", "got -1");
  ExpectRejected(p, [](ReconstructionOptions& o) { o.neighbourDirections = 33; }, "neighbourDirections");
  ReconstructionOptions turns;
  turns.neighbourDirections = 32;
  turns.directions = 4;
  Reconstruction r;
  EXPECT_TRUE(Reconstruct(p, turns, &r).ok());
  ExpectRejected(p, [](ReconstructionOptions& o) { o.probeLcShare = -0.5f; }, "probeLcShare");
  // Fewer than the one edge Guo's test accepts.
  ExpectRejected(p, [](ReconstructionOptions& o) { o.simpleSurfaceChanges = 1; }, "simpleSurfaceChanges", "got 1");
  // -1 is "every change counts"; below it means nothing.
  ExpectRejected(p, [](ReconstructionOptions& o) { o.fallbackShadingChanges = -2; }, "fallbackShadingChanges",
                 "got -2");
  ExpectRejected(p, [](ReconstructionOptions& o) { o.crossingFillReach = -1; }, "crossingFillReach", "got -1");
  // TBB crashed on an arena of 10^7 threads; the library refuses it as the CLI does.
  ExpectRejected(p, [](ReconstructionOptions& o) { o.threads = 10000000; }, "threads", "got 10000000");
  // A value set is checked at every supersampling: it serves every regime.
  ExpectRejected(p,
                 [](ReconstructionOptions& o) {
                   o.downsample = 2;
                   o.contrastThreshold = std::numeric_limits<float>::quiet_NaN();
                 },
                 "contrastThreshold");
  ExpectRejected(p, [](ReconstructionOptions& o) { o.directions = 0; }, "directions", "got 0");
  ExpectRejected(p, [](ReconstructionOptions& o) { o.elementaryBlock = 12; }, "elementaryBlock", "got 12");
}

}  // namespace
}  // namespace dcm::testing
