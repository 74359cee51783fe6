// Hard cases stay numerically stable: black, negative, NaN/Inf, huge dynamic
// range, denormal texture values, ramps, tiny and odd-sized images.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "run_helpers.h"

namespace dcm::testing {
namespace {

TEST(HardCases, BlackImageIsExactAndFinite) {
  AnalyticProvider p(40, 40, Constant(RGB::Gray(0)));
  const Reconstruction r = ReconstructOrFail(p, ReconstructionOptions{});
  for (const RGB& c : r.image) ASSERT_EQ(c, RGB::Gray(0));
  // 0/0 contrast counts as smooth: lattice points and centre probes only.
  EXPECT_LT(r.stats.exactFraction(), 0.05);
}

TEST(HardCases, NegativeValuesAreInterpolatedNotClamped) {
  AnalyticProvider p(64, 64, LinearRamp(RGB(-1, -0.5f, 0), RGB(0.01f, 0, 0), RGB(0, 0.01f, 0)));
  const Reconstruction r = ReconstructOrFail(p, ReconstructionOptions{});
  const auto full = p.FullRender();
  for (size_t i = 0; i < full.size(); ++i)
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(r.workImage[i][c], full[i][c], 1e-5f) << i;
}

// NaN and infinite samples stay in their own pixel and are counted.
TEST(HardCases, NonFiniteSamplesNeverSpread) {
  const int N = 96;
  auto base = FurnishedScene(N, N);
  auto poisoned = [&](int x, int y) {
    PixelTruth t = base(x, y);
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    // Lattice points of the default 16-pixel blocks (always evaluated) and
    // an arbitrary pixel.
    if ((x == 16 && y == 32) || (x == 48 && y == 48)) t.Li = RGB(nan, nan, nan);
    if ((x == 64 && y == 16) || (x == 13 && y == 77)) t.Li = RGB(inf, 0, 0);
    return t;
  };
  for (const ReconstructionOptions& opt : {ReconstructionOptions{}, ReconstructionOptions::Guo()}) {
    AnalyticProvider p(N, N, poisoned);
    const Reconstruction r = ReconstructOrFail(p, opt);
    int nonFinite = 0;
    for (int y = 0; y < N; ++y)
      for (int x = 0; x < N; ++x) {
        const RGB c = r.workImage[size_t(y) * N + size_t(x)];
        if (!IsFinite(c)) {
          ++nonFinite;
          ASSERT_NE(r.sampleMap[size_t(y) * N + size_t(x)], SampleReason::kInterpolated)
              << "interpolated pixel " << x << "," << y << " is not finite";
        }
      }
    EXPECT_EQ(nonFinite, r.stats.nonFiniteSamples);
    EXPECT_GE(r.stats.nonFiniteSamples, 3);  // the three lattice points at least
  }
}

// Huge finite samples (a provider's -3e38, finite in float) are clamped to
// kMaxSampleMagnitude as they arrive and counted: no sum or square of the
// engine overflows to infinity, so every pixel stays finite.
TEST(HardCases, HugeFiniteSamplesGiveFinitePixels) {
  const int N = 96;
  auto base = FurnishedScene(N, N);
  auto huge = [&](int x, int y) {
    PixelTruth t = base(x, y);
    // Lattice points of the default 16-pixel blocks (always evaluated), of
    // both signs, and an arbitrary pixel.
    if ((x == 16 && y == 32) || (x == 48 && y == 48)) t.Li = RGB(-3e38f, -3e38f, -3e38f);
    if ((x == 64 && y == 16) || (x == 13 && y == 77)) t.Li = RGB(3e38f, 0, 0);
    return t;
  };
  for (const ReconstructionOptions& opt : {ReconstructionOptions{}, ReconstructionOptions::Guo()}) {
    AnalyticProvider p(N, N, huge);
    const Reconstruction r = ReconstructOrFail(p, opt);
    for (size_t i = 0; i < r.workImage.size(); ++i)
      ASSERT_TRUE(IsFinite(r.workImage[i])) << "pixel " << i % N << "," << i / N;
    EXPECT_EQ(r.stats.nonFiniteSamples, 0);
    EXPECT_GE(r.stats.clampedSamples, 3);  // the three lattice points at least
    EXPECT_LE(r.stats.clampedSamples, 4);
  }
}

TEST(HardCases, DynamicRangeOfTwelveDecadesInOneBlock) {
  const int N = 33;
  auto scene = [](int x, int y) {
    PixelTruth t;
    t.Li = RGB::Gray(x < 16 ? 1e-6f : 1e6f);
    t.objectId = 1 + (x >= 16);
    (void)y;
    return t;
  };
  AnalyticProvider p(N, N, scene);
  const Reconstruction r = ReconstructOrFail(p, ReconstructionOptions{});
  const auto full = p.FullRender();
  for (size_t i = 0; i < full.size(); ++i) {
    ASSERT_TRUE(IsFinite(r.workImage[i]));
    // Each pixel takes the value of its own surface: relative error 1e-6.
    ASSERT_NEAR(r.workImage[i].r / full[i].r, 1.0, 1e-6) << i;
  }
}

TEST(HardCases, ZeroAndDenormalTextureValues) {
  const int N = 64;
  auto scene = [](int x, int y) {
    PixelTruth t;
    t.Li = RGB(0.5f, 0.5f, 0.5f);
    const float tiny = std::numeric_limits<float>::denorm_min();
    t.tau = ((x / 4 + y / 4) % 3 == 0) ? RGB::Gray(0) : ((x / 4 + y / 4) % 3 == 1) ? RGB::Gray(tiny) : RGB::Gray(0.8f);
    t.Lc = RGB::Gray(0.1f);
    return t;
  };
  AnalyticProvider p(N, N, scene);
  const Reconstruction r = ReconstructOrFail(p, ReconstructionOptions{});
  const auto full = p.FullRender();
  for (size_t i = 0; i < full.size(); ++i) {
    ASSERT_TRUE(IsFinite(r.workImage[i]));
    // L_i and L_c are constant: the split reconstructs the texture exactly.
    ASSERT_NEAR(r.workImage[i].r, full[i].r, 1e-6f);
  }
  // Samples where tau is zero or denormal never serve as interpolants (L_i =
  // L_t/tau is not recoverable there), so two thirds of this checker's cells
  // are evaluated rather than interpolated: measured 79 %.
  EXPECT_LT(r.stats.exactFraction(), 0.85);
}

// A whole surface without diffuse texture (tau = 0: the sky, chrome, an
// emitter) next to a textured one: its samples interpolate its L_c among
// themselves, so it costs the lattice, not an exact evaluation of every pixel
// (a Cycles render's sky through a window once did: DiffCol is 0 there).
TEST(HardCases, SurfacesWithoutTextureInterpolateTheirLc) {
  const int N = 128;
  auto scene = [](int x, int y) {
    PixelTruth t;
    const bool sky = x >= 64;
    t.objectId = t.shaderId = sky ? 0 : 1;
    t.tau = sky ? RGB::Gray(0.f) : (((x / 4 + y / 4) % 2) ? RGB::Gray(0.8f) : RGB::Gray(0.3f));
    t.Li = sky ? RGB::Gray(0.f) : RGB::Gray(0.5f + 0.002f * float(y));
    t.Lc = sky ? RGB(0.3f + 0.001f * float(x), 0.5f, 0.9f - 0.002f * float(y)) : RGB{};
    return t;
  };
  AnalyticProvider p(N, N, scene);
  const Reconstruction r = ReconstructOrFail(p, ReconstructionOptions{});
  const auto full = p.FullRender();
  for (size_t i = 0; i < full.size(); ++i)
    for (int c = 0; c < 3; ++c)
      // Linear L_i and L_c, constant tau per cell: exact to float rounding.
      ASSERT_NEAR(r.workImage[i][c], full[i][c], 1e-5f) << "pixel " << i;
  // The sky half: its lattice corners and the samples along the boundary.
  // Measured 2.3 % of the whole image; a sky evaluated in full would be > 50 %.
  EXPECT_LT(r.stats.exactFraction(), 0.10);
}

// Double-precision weights: a linear ramp is exact to float rounding at any
// block size.
TEST(HardCases, LinearRampIsExactAtAnyBlockSize) {
  const int N = 100;
  for (int block : {2, 4, 8, 16, 32, 64}) {
    AnalyticProvider p(N, N, LinearRamp(RGB(0.1f, 0.2f, 0.3f), RGB(0.004f, 0.001f, 0), RGB(0.002f, 0, 0.003f)));
    ReconstructionOptions o;
    o.elementaryBlock = block;
    o.minBlock = std::min(block, 4);
    const Reconstruction r = ReconstructOrFail(p, o);
    const auto full = p.FullRender();
    for (size_t i = 0; i < full.size(); ++i)
      for (int c = 0; c < 3; ++c)
        // A few float roundings of values below 1: 4 ulp at 1.0.
        ASSERT_NEAR(r.workImage[i][c], full[i][c], 4 * std::numeric_limits<float>::epsilon())
            << "block " << block << " pixel " << i;
  }
}

TEST(HardCases, DirectionsExactlyOnTheDiagonal) {
  const int N = 65;
  auto scene = [](int x, int y) {
    PixelTruth t;
    t.Li = RGB::Gray(x > y ? 1.f : 0.1f);
    t.objectId = 1 + (x > y);
    return t;
  };
  AnalyticProvider p(N, N, scene);
  const Reconstruction r = ReconstructOrFail(p, ReconstructionOptions{});
  EXPECT_EQ(r.workImage, p.FullRender());
  bool diagonal = false;
  for (const BlockRecord& b : r.blocks) diagonal |= b.direction == 2;  // 45 degrees of 8
  EXPECT_TRUE(diagonal);
}

TEST(HardCases, TinyAndOddImages) {
  for (auto [w, h] : {std::pair{1, 1}, {1, 7}, {7, 1}, {2, 2}, {3, 2}, {7, 13}, {9, 9}, {13, 7}}) {
    AnalyticProvider p(w, h, FurnishedScene(w, h));
    for (const ReconstructionOptions& opt : {ReconstructionOptions{}, ReconstructionOptions::Guo()}) {
      const Reconstruction r = ReconstructOrFail(p, opt);
      ASSERT_EQ(r.width, w);
      ASSERT_EQ(r.height, h);
      for (const RGB& c : r.image) ASSERT_TRUE(IsFinite(c));
      if (w * h <= 4) {
        EXPECT_EQ(r.stats.exactPixels, w * h) << w << "x" << h;
      }
    }
  }
}

}  // namespace
}  // namespace dcm::testing
