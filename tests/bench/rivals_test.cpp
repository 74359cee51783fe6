// The rivals of `dcm bench` (tools/dcm/bench_rivals.h) on the analytic
// provider: the grid matches the budget, each exact sample is evaluated once,
// bilinear upsampling is exact on a linear ramp, and joint bilateral
// upsampling keeps an object edge that bilinear upsampling blurs.
#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "analytic_provider.h"
#include "bench_rivals.h"

namespace dcm::bench {
namespace {

using testing::AnalyticProvider;
using testing::PixelTruth;

TEST(UniformGrid, MatchesTheBudgetAndCoversTheImage) {
  for (auto [w, h, budget] : {std::tuple{256, 256, 5000}, std::tuple{300, 200, 1234}, std::tuple{64, 128, 64},
                              std::tuple{97, 31, 2000}}) {
    const UniformGrid g = MakeGrid(w, h, budget);
    ASSERT_GE(g.xs.size(), 2u);
    ASSERT_GE(g.ys.size(), 2u);
    EXPECT_EQ(g.xs.front(), 0);
    EXPECT_EQ(g.ys.front(), 0);
    EXPECT_EQ(g.xs.back(), w - 1);
    EXPECT_EQ(g.ys.back(), h - 1);
    for (size_t i = 1; i < g.xs.size(); ++i) EXPECT_LT(g.xs[i - 1], g.xs[i]);
    for (size_t i = 1; i < g.ys.size(); ++i) EXPECT_LT(g.ys[i - 1], g.ys[i]);
    // Within 5 % of the budget (the grid is a product of two integers).
    EXPECT_NEAR(double(g.count()), double(budget), 0.05 * double(budget) + 2) << w << "x" << h << " " << budget;
  }
}

TEST(Rivals, EvaluateEachGridPixelOnceAndKeepItsBits) {
  AnalyticProvider p(128, 96, testing::FurnishedScene(128, 96));
  RivalResult r;
  ASSERT_TRUE(RunRival(p, Upsampler::kJointBilateral, 700, 2, &r, {}, 64).ok());
  EXPECT_EQ(r.exactPixels, MakeGrid(128, 96, 700).count());
  EXPECT_EQ(p.TotalEvaluations(), r.exactPixels);
  EXPECT_EQ(p.MaxEvaluationsOfOnePixel(), 1);
  const UniformGrid g = MakeGrid(128, 96, 700);
  for (int y : g.ys)
    for (int x : g.xs) EXPECT_EQ(r.workImage[size_t(y) * 128 + size_t(x)], p.Truth(x, y).L());
}

TEST(Rivals, BilinearIsExactOnALinearRamp) {
  AnalyticProvider p(120, 80, testing::LinearRamp(RGB(0.1f, 0.2f, 0.3f), RGB(0.01f, 0.002f, 0.f),
                                                  RGB(0.f, 0.003f, 0.005f)));
  RivalResult r;
  ASSERT_TRUE(RunRival(p, Upsampler::kBilinear, 300, 1, &r).ok());
  const auto full = p.FullRender();
  double maxErr = 0;
  for (size_t i = 0; i < full.size(); ++i)
    for (int c = 0; c < 3; ++c) maxErr = std::max(maxErr, double(std::fabs(r.workImage[i][c] - full[i][c])));
  EXPECT_LT(maxErr, 1e-5);
}

// Two objects meeting at a vertical edge between grid columns: bilinear
// upsampling blurs it over a grid spacing, the ID-guided upsampler does not.
TEST(Rivals, JointBilateralKeepsAnObjectEdgeThatBilinearBlurs) {
  const int w = 128, h = 64, edge = 61;
  auto scene = [edge](int x, int /*y*/) {
    PixelTruth t;
    t.objectId = x < edge ? 1u : 2u;
    t.shaderId = t.objectId;
    t.Li = x < edge ? RGB::Gray(0.1f) : RGB::Gray(0.8f);
    return t;
  };
  AnalyticProvider p(w, h, scene);
  const auto full = p.FullRender();
  auto meanAbsErr = [&](const RivalResult& r) {
    double e = 0;
    for (size_t i = 0; i < full.size(); ++i) e += std::fabs(double(r.workImage[i].g) - double(full[i].g));
    return e / double(full.size());
  };
  RivalResult bl, jbu;
  ASSERT_TRUE(RunRival(p, Upsampler::kBilinear, 128, 1, &bl).ok());
  ASSERT_TRUE(RunRival(p, Upsampler::kJointBilateral, 128, 1, &jbu).ok());
  const double eb = meanAbsErr(bl), ej = meanAbsErr(jbu);
  EXPECT_GT(eb, 0.01);
  EXPECT_LT(ej, 1e-4);
}

}  // namespace
}  // namespace dcm::bench
