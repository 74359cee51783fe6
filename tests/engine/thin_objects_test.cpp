// The thin-object test (paper 3.1): an interior pixel whose interpolants lie
// on another surface is evaluated exactly, or (dcm) served along a
// neighbouring direction whose ends agree.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "run_helpers.h"

namespace dcm::testing {
namespace {

// 3.1: the thin line survives with the thin-object test and is washed out
// without it.
TEST(ThinObjects, ThinLineSurvivesOnlyWithTheTest) {
  const int N = 256;
  FurnishedOptions only;
  only.softShadow = only.disc = only.texture = only.hdr = false;
  // A shaded background under the line so that the line is not the only
  // detail of its blocks (paper: "in the presence of other shading details").
  only.softShadow = true;
  AnalyticProvider provider(N, N, FurnishedScene(N, N, only));
  const auto full = provider.FullRender();
  auto line = [&](int x, int y) { return OnThinLine(N, N, x, y); };
  // The paper's reading (exact where no border sample used matches) against
  // Guo's interpolation, everything else equal.
  ReconstructionOptions paper = ReconstructionOptions::Paper();
  ReconstructionOptions guo = paper;
  guo.thinObjects = ThinObjectTest::kOff;
  // dcm's reading: exact where a border point used has no sample on the
  // pixel's surface.
  ReconstructionOptions dcm;
  const Reconstruction a = ReconstructOrFail(provider, paper);
  const Reconstruction b = ReconstructOrFail(provider, guo);
  const Reconstruction c = ReconstructOrFail(provider, dcm);
  const double errPaper = MeanLuminanceError(a, full, line), errOff = MeanLuminanceError(b, full, line);
  const double errDcm = MeanLuminanceError(c, full, line);
  std::printf("thin line error: %.4f paper, %.4f dcm, %.4f without the test\n", errPaper, errDcm, errOff);
  // The line is yellow (luminance 0.87) on a background of luminance 0.1-0.5:
  // washed out means an error of a good part of that difference on the line.
  EXPECT_GT(errOff, 0.1);
  EXPECT_LT(errPaper, errOff / 3);
  EXPECT_LT(errDcm, 0.01);
  // And it costs little: the paper measured about 1 % more samples.
  EXPECT_LT(a.stats.exactFraction() - b.stats.exactFraction(), 0.03);
}

// A straight edge between two smoothly shaded surfaces is no thin object:
// where an interior pixel's border point falls between a sample on its
// surface and one across the edge, the end-differs test snaps the point to
// the sample on its surface, while any-differs evaluates the pixel; where a
// point lies wholly across, a neighbouring direction may not. Edges at six
// angles between 6 and 68 degrees, mostly between the 8 directions.
TEST(ThinObjects, AStraightEdgeIsNoThinObject) {
  const int N = 256;
  constexpr double kGradient = 0.002;  ///< the shading's slope, per pixel
  ReconstructionOptions any;
  any.thinObjects = ThinObjectTest::kAnyDiffers;
  any.neighbourDirections = 0;
  ReconstructionOptions end = any;
  end.thinObjects = ThinObjectTest::kEndDiffers;
  const ReconstructionOptions turn;  // the default: end-differs, then the neighbouring directions
  ASSERT_EQ(ResolveSettings(turn, ProviderCapabilities{}).thinObjects, ThinObjectTest::kEndDiffers);
  ASSERT_GT(turn.neighbourDirections, 0);
  const auto thin = [](const Reconstruction& r) { return r.stats.byReason[size_t(SampleReason::kThinObject)]; };
  int64_t thinAny = 0, thinEnd = 0, thinTurn = 0;
  for (const double slope : {0.1, 0.2, 0.3, 0.6, 1.3, 2.5}) {
    auto above = [&](int x, int y) { return double(y) < 40 + slope * x; };
    AnalyticProvider provider(N, N, [&](int x, int y) {
      PixelTruth t;
      const bool a = above(x, y);
      t.objectId = t.shaderId = a ? 1 : 2;
      const double l = a ? 0.2 + kGradient * x + 0.5 * kGradient * y : 0.6 - 0.5 * kGradient * x + kGradient * y;
      t.Li = RGB::Gray(float(l));
      return t;
    });
    const auto full = provider.FullRender();
    const Reconstruction a = ReconstructOrFail(provider, any), e = ReconstructOrFail(provider, end);
    const Reconstruction t = ReconstructOrFail(provider, turn);
    auto nearEdge = [&](int x, int y) { return std::fabs(double(y) - (40 + slope * x)) < 3; };
    const double errAny = MeanLuminanceError(a, full, nearEdge), errEnd = MeanLuminanceError(e, full, nearEdge);
    const double errTurn = MeanLuminanceError(t, full, nearEdge);
    std::printf("edge of slope %.1f: thin-object samples (error) %lld (%.5f) any-differs, %lld (%.5f) end-differs, "
                "%lld (%.5f) and the neighbouring directions\n",
                slope, (long long)thin(a), errAny, (long long)thin(e), errEnd, (long long)thin(t), errTurn);
    // Each surface is linear, so interpolating between samples on it is
    // exact up to where a snapped point lies: less than a pixel from the
    // exit point, so at most one pixel's step of the shading, on average
    // far less; a neighbouring direction's points lie on the same surface.
    EXPECT_LT(errEnd, kGradient) << "slope " << slope;
    EXPECT_LT(errTurn, kGradient) << "slope " << slope;
    thinAny += thin(a), thinEnd += thin(e), thinTurn += thin(t);
  }
  // Each edge is 220-280 pixels long; any-differs evaluates a pixel or two
  // beside it on most of its rows (about 1600 in all). Each step saves a
  // quarter at least (measured: 32 %, then 37 % of the rest).
  EXPECT_GT(thinAny, 1000);
  EXPECT_LT(thinEnd, thinAny * 3 / 4);
  EXPECT_LT(thinTurn, thinEnd * 3 / 4);
}

// Spindles in front of a wall with a hard shadow edge across it: where the
// block's direction fails a wall pixel beside a spindle, the neighbouring
// directions serve it, every one of them by default, but only a line whose
// two ends agree. A line from the lit side to the shadowed one (the shadow
// edge is no surface change: one ID, one normal) would blend light and
// shadow on the pixel's surface.
TEST(ThinObjects, ANeighbouringDirectionNeverBlendsAcrossAShadowEdge) {
  const int N = 192;
  constexpr double kLit = 0.7, kShadow = 0.12, kSpindle = 0.45;
  auto lit = [](int x, int y) { return double(x) > 70 + 0.45 * y; };
  auto spindle = [](int x, int y) {
    // Two pixels wide, 16 pixels apart, at a slope of 0.2 (across the shadow).
    const double d = std::fmod(y - 0.2 * x + 400.0, 16.0);
    return d < 2.0;
  };
  AnalyticProvider provider(N, N, [&](int x, int y) {
    PixelTruth t;
    const bool s = spindle(x, y);
    t.objectId = t.shaderId = s ? 2 : 1;
    t.Li = RGB::Gray(float(s ? kSpindle : (lit(x, y) ? kLit : kShadow)));
    return t;
  });
  const auto full = provider.FullRender();
  ReconstructionOptions none, all;
  none.neighbourDirections = 0;
  ASSERT_GE(all.neighbourDirections * 2, ResolveSettings(all, ProviderCapabilities{}).directions);  // the default: every direction
  const Reconstruction rNone = ReconstructOrFail(provider, none), rAll = ReconstructOrFail(provider, all);
  const auto thin = [](const Reconstruction& r) { return r.stats.byReason[size_t(SampleReason::kThinObject)]; };
  // The wall's pixels: wrong by kLit - kShadow where light and shadow blend.
  double worst = 0;  // of the default's
  int64_t wrong = 0, wrongNone = 0;
  for (int y = 0; y < N; ++y)
    for (int x = 0; x < N; ++x) {
      if (spindle(x, y)) continue;
      const size_t i = size_t(y) * N + size_t(x);
      const double e = std::fabs(Luminance(rAll.workImage[i]) - Luminance(full[i]));
      worst = std::max(worst, e);
      wrong += e > 0.05;
      wrongNone += std::fabs(Luminance(rNone.workImage[i]) - Luminance(full[i])) > 0.05;
    }
  std::printf("thin-object samples: %lld with the block's direction only, %lld with every direction; wall pixels "
              "off by more than 0.05: %lld and %lld (worst %.3f)\n",
              (long long)thin(rNone), (long long)thin(rAll), (long long)wrongNone, (long long)wrong, worst);
  // The other directions serve a good part of the thin-object pixels...
  EXPECT_LT(thin(rAll), thin(rNone) * 3 / 4);
  // ...and blend no light with shadow: they add no wall pixel off by more
  // than 0.05 (a tenth of the step; flat shading is otherwise interpolated
  // exactly) to those the oriented interpolation leaves along the shadow
  // edge itself. Without the agreement of the ends: 80 against 38.
  EXPECT_LE(wrong, wrongNone);
}

// Under the supersampled rules (none-matches) a pixel whose block direction
// has one end on another surface used to take that one end's value, however
// far. A room's wall meets its ceiling along a slightly tilted crease and
// darkens towards it (0.27 at the crease, 0.40 far below: ambient
// occlusion), and the ceiling is 0.40: the block [96, 112] x [80, 96] finds
// the vertical direction the least discrepant and is settled lazily. Straight
// down from a wall pixel under the crease the line meets the ceiling at one
// end and the bright wall 13 pixels below at the other, whose value it
// copied. Across, both ends lie on the wall and differ least.
TEST(OneEndedPixels, TakeTheDirectionWhoseTwoEndsOnTheirSurfaceDifferLeast) {
  constexpr int N = 128;
  auto crease = [](int x) { return 75.5 + x / 16.0; };  // ceiling above
  const SceneFunction scene = [&](int x, int y) {
    PixelTruth t;
    const bool ceiling = y < crease(x);
    t.normal = ceiling ? Vec3f{0.f, 0.f, -1.f} : Vec3f{0.f, -1.f, 0.f};
    t.Li = RGB::Gray(ceiling ? 0.4f : float(0.4 - 0.13 * std::exp(-(y - crease(x)) / 3)));
    return t;
  };
  AnalyticChannels ch;
  ch.normals = true;
  AnalyticProvider provider(N, N, scene, ch);
  ReconstructionOptions o;
  o.downsample = 2;
  const Reconstruction r = ReconstructOrFail(provider, o);
  ASSERT_TRUE(r.stats.usedSupersampledRules);
  const auto full = provider.FullRender();
  double err = 0;
  int n = 0;
  for (int x = 97; x < 112; ++x)  // the block [96, 112] x [80, 96]
    for (int y = int(std::ceil(crease(x))); y < crease(x) + 2; ++y, ++n)
      err += std::fabs(Luminance(r.workImage[size_t(y * N + x)]) - Luminance(full[size_t(y * N + x)]));
  // Measured: 0.029; the nearest neighbouring direction whose ends agree,
  // keeping the one end where there is none, 0.035; copying the far end
  // always, 0.092.
  EXPECT_LT(err / n, 0.05) << "mean error in the two rows under the crease";
}

}  // namespace
}  // namespace dcm::testing
