// The tables that share the oriented-element geometry between blocks of one
// shape (BorderPairs for the direction search, OrientedElements for the
// interpolation) give, to the bit, what the per-pixel geometry gives; the
// surface test's bit masks (AdjacentChanges) what each pair gives.
#include <gtest/gtest.h>

#include <cmath>
#include <algorithm>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "../../lib/src/block.h"
#include "../../lib/src/least_discrepancy_direction.h"
#include "../../lib/src/oriented_interpolation.h"
#include "../../lib/src/sample_store.h"

namespace dcm::detail {
namespace {

/// Exact samples from a table, for filling a SampleStore.
class TableProvider : public SampleProvider {
 public:
  TableProvider(int w, int h, std::vector<RGB> L) : w_(w), h_(h), L_(std::move(L)) {}
  ProviderCapabilities Capabilities() const override {
    ProviderCapabilities c;
    c.width = w_;
    c.height = h_;
    return c;
  }
  Status Guides(const Bounds2i&, const GuideRequest&, GuideImage*) override { return Status::Ok(); }
  Status Evaluate(std::span<const Point2i> pixels, const SampleRequest&, std::span<ExactSample> out) override {
    for (size_t i = 0; i < pixels.size(); ++i) out[i].L = L_[size_t(pixels[i].y) * size_t(w_) + size_t(pixels[i].x)];
    return Status::Ok();
  }

 private:
  int w_, h_;
  std::vector<RGB> L_;
};

/// A store whose every pixel is exact, with values from `L`.
SampleStore FilledStore(int w, int h, const std::vector<RGB>& L) {
  SampleStore store(w, h, /*split=*/false);
  TableProvider provider(w, h, L);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) store.Request(x, y, SampleReason::kCorner);
  ReconstructionStats stats;
  EXPECT_TRUE(store.Flush(provider, SampleRequest{}, 4096, false, &stats, nullptr).ok());
  return store;
}

/// The search as the paper states it: for every direction, every border
/// pixel against where its line leaves the block, the mean squared difference.
DirectionChoice ReferenceSearch(const SampleStore& store, const Block& b, int directions) {
  std::vector<Point2i> border;
  BorderLoop(b, &border);
  DirectionChoice best{0, std::numeric_limits<double>::infinity()};
  for (int k = 0; k < directions; ++k) {
    const Direction d = Direction::Of(k, directions);
    double sum = 0;
    int pairs = 0;
    for (Point2i p : border) {
      const int64_t ip = store.Index(p.x, p.y);
      BorderPoint e;
      if (!ExitPoint(b, p.x, p.y, d, &e) && !ExitPoint(b, p.x, p.y, Direction{-d.dx, -d.dy}, &e)) continue;
      const int64_t i0 = store.Index(e.p0.x, e.p0.y), i1 = store.Index(e.p1.x, e.p1.y);
      if (!store.IsFinite(ip) || !store.IsFinite(i0) || !store.IsFinite(i1)) continue;
      Interpolant in;
      in.index = {i0, i1, 0, 0};
      in.weight = {1 - e.w1, e.w1, 0, 0};
      in.count = 2;
      const Value v = store.ValueAt(ip), q = Evaluate(store, in);
      double squared = 0;  // |L(p) - L(p')|^2 over the interpolated channels
      for (int c = 0; c < 3; ++c) {
        const double da = double(v.a[c]) - q.a[c], db = double(v.b[c]) - q.b[c];
        squared += da * da + db * db;
      }
      sum += squared;
      ++pairs;
    }
    if (pairs > 0 && sum / pairs < best.discrepancy) best = {k, sum / pairs};
  }
  if (!std::isfinite(best.discrepancy)) best = {0, 0};
  return best;
}

// Blocks of the lattice sizes and clipped ones, images of random values, of
// a straight edge at several angles (a clear winner), of constants (all
// directions tie: the smallest k), and with non-finite samples.
TEST(GeometryTables, DirectionSearchMatchesThePerPixelSearch) {
  const int W = 40, H = 40;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::vector<std::vector<RGB>> images;
  for (int n = 0; n < 4; ++n) {
    std::vector<RGB> L(size_t(W * H));
    for (auto& v : L) v = RGB(u(rng), u(rng), u(rng));
    images.push_back(L);
  }
  for (double angle : {0.3, 1.1, 2.0}) {
    std::vector<RGB> L(size_t(W * H));
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) L[size_t(y * W + x)] = RGB::Gray((x * std::cos(angle) + y * std::sin(angle)) > 20 ? 1.f : 0.f);
    images.push_back(L);
  }
  images.push_back(std::vector<RGB>(size_t(W * H), RGB::Gray(0.5f)));
  std::vector<RGB> holes = images[0];
  for (size_t i = 0; i < holes.size(); i += 7) holes[i] = RGB::Gray(std::numeric_limits<float>::quiet_NaN());
  images.push_back(holes);

  const std::vector<Block> blocks = {{0, 0, 16, 16}, {3, 5, 11, 13}, {20, 20, 24, 24}, {1, 1, 17, 6},
                                     {30, 2, 39, 18}, {5, 30, 7, 32}, {10, 10, 10, 20}};
  int clearWinners = 0;
  for (size_t n = 0; n < images.size(); ++n) {
    const SampleStore store = FilledStore(W, H, images[n]);
    for (const Block& b : blocks)
      for (int K : {4, 8, 16}) {
        std::vector<Point2i> border;
        BorderLoop(b, &border);
        const BorderPairs table(b.width(), b.height(), K);
        const DirectionChoice got = LeastDiscrepancyDirection(store, border, table);
        const DirectionChoice want = ReferenceSearch(store, b, K);
        EXPECT_EQ(got.index, want.index) << "image " << n << " block " << b.x0 << "," << b.y0 << " K " << K;
        EXPECT_EQ(std::memcmp(&got.discrepancy, &want.discrepancy, sizeof(double)), 0)
            << got.discrepancy << " vs " << want.discrepancy;
        clearWinners += (n >= 4 && n < 7 && want.discrepancy == 0.0 && b.HasInterior());
      }
  }
  // The edge images do have directions that predict the border exactly, so
  // the early exit of the search is exercised against a real winner.
  EXPECT_GT(clearWinners, 0);
}

TEST(GeometryTables, OrientedElementsMatchThePerPixelInterpolant) {
  const int W = 48, H = 48;
  const SampleStore store = FilledStore(W, H, std::vector<RGB>(size_t(W * H), RGB::Gray(1.f)));
  for (const Block& b : std::vector<Block>{{0, 0, 16, 16}, {16, 8, 24, 16}, {30, 30, 34, 34}, {2, 20, 20, 27}})
    for (int K : {8, 12})
      for (int k = 0; k < K; ++k) {
        const Direction d = Direction::Of(k, K);
        const OrientedElements table(b.width(), b.height(), d);
        // Every pixel of the closed block and a ring around it: interior
        // pixels come from the table, the others from the fallback.
        for (int y = b.y0 - 1; y <= b.y1 + 1; ++y)
          for (int x = b.x0 - 1; x <= b.x1 + 1; ++x) {
            Interpolant a, e;
            const bool okA = table.At(store, b, {x, y}, &a);
            const bool okE = OrientedInterpolant(store, b, {x, y}, d, &e);
            ASSERT_EQ(okA, okE) << x << "," << y << " k " << k;
            if (!okA) continue;
            ASSERT_EQ(a.count, e.count);
            for (int i = 0; i < a.count; ++i) {
              EXPECT_EQ(a.index[size_t(i)], e.index[size_t(i)]);
              EXPECT_EQ(std::memcmp(&a.weight[size_t(i)], &e.weight[size_t(i)], sizeof(double)), 0);
            }
          }
      }
}

// Guides with every kind of surface change: objects, shaders, tau = 0 pixels
// and creases (whose cell regions then join pixels); the masks answer as each
// pair's SameAdjacent does, for every test and random rectangles, cells
// crossed or not.
TEST(GeometryTables, SurfaceChangeMasksMatchThePairwiseTest) {
  const int W = 83, H = 61;  // rows of more than one word, not a multiple of 64
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> coin(0, 9);
  for (ObjectTest test : {ObjectTest::kObjectId, ObjectTest::kObjectOrShader, ObjectTest::kObjectAndShader}) {
    for (bool normals : {false, true}) {
      GuideImage g;
      const size_t n = size_t(W) * size_t(H);
      g.objectId.resize(n);
      g.shaderId.resize(n);
      g.texture.resize(n);
      g.normal.resize(n);
      for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
          const size_t i = size_t(y) * size_t(W) + size_t(x);
          // Blobs rather than noise, so that many blocks have no change.
          g.objectId[i] = uint32_t((x / 13 + y / 17) % 3) + (coin(rng) == 0 ? 5u : 0u);
          g.shaderId[i] = uint32_t((x / 7) % 2);
          g.texture[i] = (x > 40 && y > 30 && x < 50) ? RGB{} : RGB::Gray(0.5f);
          g.normal[i] = (x + 2 * y) / 37 % 2 ? Vec3f{0.f, 0.f, 1.f} : Vec3f{1.f, 0.f, 0.f};
        }
      if (!normals) g.normal.clear();
      SampleStore store(W, H, /*split=*/true);
      store.SetGuides(g, test, normals ? 30.f : 0.f, 8);
      const SurfaceTest& s = store.surfaces();
      auto pairwise = [&](int x0, int y0, int x1, int y1) {
        for (int y = y0; y <= y1; ++y)
          for (int x = x0; x <= x1; ++x) {
            const int64_t i = store.Index(x, y);
            if (x < x1 && !s.SameAdjacent(i, i + 1)) return true;
            if (y < y1 && !s.SameAdjacent(i, i + W)) return true;
          }
        return false;
      };
      std::uniform_int_distribution<int> px(0, W - 1), py(0, H - 1), len(0, 12);
      int changes = 0, none = 0;
      for (int r = 0; r < 4000; ++r) {
        const int x0 = px(rng), y0 = py(rng);
        const int x1 = std::min(W - 1, x0 + len(rng)), y1 = std::min(H - 1, y0 + len(rng));
        const bool want = pairwise(x0, y0, x1, y1);
        ASSERT_EQ(s.ChangeIn(x0, y0, x1, y1), want) << x0 << "," << y0 << "-" << x1 << "," << y1;
        (want ? changes : none) += 1;
      }
      EXPECT_GT(changes, 100);  // both answers are exercised
      EXPECT_GT(none, 100);
    }
  }
}

}  // namespace
}  // namespace dcm::detail
