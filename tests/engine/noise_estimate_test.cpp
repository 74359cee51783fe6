// Pooling the variance of two halves (dcm/noise_estimate.h): a Monte Carlo
// estimate's variance grows with its value, so it is pooled as a share of it.
// And the variance of one render alone, with detail that is not noise.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "dcm/noise_estimate.h"

namespace dcm::testing {
namespace {

constexpr int kW = 64, kH = 256;
/// The variance of a pixel's mean, as a Poisson-like share of its value.
constexpr double kShare = 1e-3;

/// A dark surface (0.02) meeting a bright highlight (2.0) on the same
/// surface at x = 32 (kW / 2), and the halves of each pixel drawn with the variance
/// kShare * L for their mean (2 kShare L each).
struct Halves {
  std::vector<RGB> truthL, truthVar, mean, raw;
  Halves() {
    std::mt19937 rng(7);
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        const float L = x < kW / 2 ? 0.02f : 2.0f;
        std::normal_distribution<float> noise(0.f, float(std::sqrt(2 * kShare * L)));
        RGB a, b;
        for (int c = 0; c < 3; ++c) a[c] = L + noise(rng), b[c] = L + noise(rng);
        truthL.push_back(RGB::Gray(L));
        truthVar.push_back(RGB::Gray(float(kShare * L)));
        mean.push_back((a + b) * 0.5f);
        raw.push_back(HalvesVariance(a, b, 1, 1));
      }
  }
};

/// The mean over the dark pixels within `reach` px of the highlight of
/// pooled / true variance (green channel).
double DarkRatioNearTheHighlight(const std::vector<RGB>& pooled, const Halves& h, int reach) {
  double sum = 0;
  int n = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = kW / 2 - reach; x < kW / 2; ++x) {
      const size_t i = size_t(y) * kW + size_t(x);
      sum += pooled[i].g / h.truthVar[i].g;
      ++n;
    }
  return sum / n;
}

TEST(NoiseEstimate, VarianceIsPooledAsAShareOfTheValue) {
  const Halves h;
  const std::vector<RGB> relative = SurfaceWindowRelativeMean(h.raw, h.mean, kW, kH, {}, {}, 2);
  const std::vector<RGB> plain = SurfaceWindowMean(h.raw, kW, kH, {}, {}, 2);
  // Beside the highlight a dark pixel's 5x5 window holds 10 bright pixels
  // with 100x its variance: their plain mean is 40x its own (2/5 x 100).
  // As a share of the value it is its own. The bright pixels' raw values
  // decide it: one degree of freedom each (sd sqrt(2) of the mean), 10 per
  // window, about 50 independent windows down the 256 rows, so the mean
  // ratio's own sd is about 0.07; 0.2 is 3 sd (seeds 1-7 pass).
  EXPECT_NEAR(DarkRatioNearTheHighlight(relative, h, 2), 1.0, 0.2);
  EXPECT_GT(DarkRatioNearTheHighlight(plain, h, 2), 20.0);
  // Over the whole image too (16384 pixels).
  double sum = 0;
  for (size_t i = 0; i < relative.size(); ++i) sum += relative[i].g / h.truthVar[i].g;
  EXPECT_NEAR(sum / double(relative.size()), 1.0, 0.1);
}

TEST(NoiseEstimate, ConstantShareIsReturnedExactlyButForTheFloor) {
  // Given the true variances and values, pooling returns each pixel's own:
  // kShare (|L_i| + f) where the whole window has one share, i.e. the truth
  // up to f / L = 3e-4 / 0.02 = 1.5 %.
  const Halves h;
  const std::vector<RGB> pooled = SurfaceWindowRelativeMean(h.truthVar, h.truthL, kW, kH, {}, {}, 2);
  for (size_t i = 0; i < pooled.size(); ++i)
    ASSERT_NEAR(pooled[i].g / h.truthVar[i].g, 1.0, 0.016) << "pixel " << i;
}

TEST(NoiseEstimate, NonFinitePixelsGiveAndTakeNothing) {
  const Halves h;
  std::vector<RGB> L = h.truthL, v = h.truthVar;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const size_t hole = size_t(10) * kW + 5, neighbour = hole + 1;
  L[hole] = RGB::Gray(nan);                               // no value: no variance
  v[neighbour] = RGB::Gray(std::numeric_limits<float>::infinity());  // left out of its neighbours' windows
  const std::vector<RGB> pooled = SurfaceWindowRelativeMean(v, L, kW, kH, {}, {}, 2);
  EXPECT_EQ(pooled[hole].g, 0.f);
  for (size_t i = 0; i < pooled.size(); ++i) ASSERT_TRUE(std::isfinite(pooled[i].g)) << "pixel " << i;
  EXPECT_NEAR(pooled[neighbour + 1].g / h.truthVar[neighbour + 1].g, 1.0, 0.016);
}

TEST(NoiseEstimate, OnlyTheSameSurfacePools) {
  // The highlight as another object: the dark pixels beside it pool only
  // their own, in either form.
  const Halves h;
  std::vector<uint32_t> id(size_t(kW) * kH);
  for (size_t i = 0; i < id.size(); ++i) id[i] = int(i % kW) < kW / 2 ? 1 : 2;
  const std::vector<RGB> pooled = SurfaceWindowRelativeMean(h.truthVar, h.truthL, kW, kH, id, {}, 2);
  const std::vector<RGB> plain = SurfaceWindowMean(h.truthVar, kW, kH, id, {}, 2);
  for (int y = 0; y < kH; ++y) {
    const size_t i = size_t(y) * kW + kW / 2 - 1;
    EXPECT_NEAR(pooled[i].g / h.truthVar[i].g, 1.0, 0.016);
    EXPECT_FLOAT_EQ(plain[i].g, h.truthVar[i].g);
  }
}

/// One render of `truth` (kOneW x kOneH) with noise of the variance
/// share * (|L| + f) per channel, the channels correlated by `correlation`.
constexpr int kOneW = 192, kOneH = 192;
std::vector<RGB> OneRender(const std::vector<RGB>& truth, const std::vector<double>& share, double correlation,
                           uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0, 1);
  std::vector<RGB> out(truth.size());
  for (size_t i = 0; i < truth.size(); ++i) {
    const double common = normal(rng);
    for (int c = 0; c < 3; ++c) {
      const double z = std::sqrt(correlation) * common + std::sqrt(1 - correlation) * normal(rng);
      const double sd = std::sqrt(share[i] * (std::fabs(truth[i][c]) + kRelativeVarianceFloor));
      out[i][c] = float(truth[i][c] + sd * z);
    }
  }
  return out;
}

/// The mean over the pixels of `at` of estimated / true variance (green).
template <class At>
double OneRenderRatio(const std::vector<RGB>& estimate, const std::vector<RGB>& truth,
                      const std::vector<double>& share, At at) {
  double sum = 0;
  int n = 0;
  for (int y = 4; y < kOneH - 4; ++y)
    for (int x = 4; x < kOneW - 4; ++x) {
      const size_t i = size_t(y) * kOneW + size_t(x);
      if (!at(x, y)) continue;
      sum += estimate[i].g / (share[i] * (truth[i].g + kRelativeVarianceFloor));
      ++n;
    }
  return sum / n;
}

TEST(NoiseEstimate, VarianceFromOneRenderOfWhiteNoise) {
  // A flat grey with white noise: the mean estimate is the truth over
  // kOneRenderMedian's simulation. 35000 pixels, but each window median
  // shares 48 of 49 values with its neighbour's: about 700 independent
  // windows of a skewed median whose sd is about 0.3 of its mean, so the
  // mean ratio's own sd is about 0.012; 0.05 is 4 sd.
  const std::vector<RGB> truth(size_t(kOneW) * kOneH, RGB::Gray(0.5f));
  const std::vector<double> share(truth.size(), 1e-4);
  const auto all = [](int, int) { return true; };
  const std::vector<RGB> v = OneRender(truth, share, 0.9, 3);
  EXPECT_NEAR(OneRenderRatio(VarianceFromOneRender(v, kOneW, kOneH, {}, {}), truth, share, all), 1.0, 0.05);
  // How R, G and B correlate hardly matters: independent channels 1.06,
  // identical ones 1.00 here.
  const std::vector<RGB> independent = OneRender(truth, share, 0.0, 4), identical = OneRender(truth, share, 1.0, 5);
  EXPECT_NEAR(OneRenderRatio(VarianceFromOneRender(independent, kOneW, kOneH, {}, {}), truth, share, all), 1.0, 0.1);
  EXPECT_NEAR(OneRenderRatio(VarianceFromOneRender(identical, kOneW, kOneH, {}, {}), truth, share, all), 1.0, 0.05);
}

/// A dark floor (0.05) with a hard edge to a bright wall (0.8) at x = 96, a
/// bright diagonal line one pixel wide on the floor and 2x2 highlights every
/// 16 px on the wall: detail at the pixel scale, all on one surface.
std::vector<RGB> DetailedImage() {
  std::vector<RGB> t(size_t(kOneW) * kOneH);
  for (int y = 0; y < kOneH; ++y)
    for (int x = 0; x < kOneW; ++x) {
      float L = x < kOneW / 2 ? 0.05f : 0.8f;
      if (x == y && x < kOneW / 2 - 8) L = 2.0f;
      if (x > kOneW / 2 + 8 && x % 16 / 2 == 4 && y % 16 / 2 == 4) L = 3.0f;
      t[size_t(y) * kOneW + size_t(x)] = RGB::Gray(L);
    }
  return t;
}

TEST(NoiseEstimate, AnEdgeALineAndSmallHighlightsAreNotNoise) {
  const std::vector<RGB> truth = DetailedImage();
  // Noise-free: along the edge and the line a direction sees no change, and
  // a highlight with the pixels whose residual it enters is less than half
  // of any window: no variance, but at the image's border, where a line
  // ending in a corner leaves no other direction.
  const std::vector<RGB> clean = VarianceFromOneRender(truth, kOneW, kOneH, {}, {});
  for (int y = 4; y < kOneH - 4; ++y)
    for (int x = 4; x < kOneW - 4; ++x) ASSERT_EQ(clean[size_t(y) * kOneW + size_t(x)].g, 0.f) << x << ", " << y;
  // Noisy, the noise is found beside them as elsewhere: within 2 px of the
  // edge or the line (1.11 and 1.08 here; about 900 pixels each, 30 windows
  // independent of each other along them: the ratio's sd about 0.06, 0.25
  // is 4 sd), a little high around the highlights (1.29: the pixels their
  // blur lets choose a direction across them). A window mean of the squared
  // residuals takes the detail itself for noise: 10x or more.
  const std::vector<double> share(truth.size(), 1e-4);
  const std::vector<RGB> v = OneRender(truth, share, 0.9, 6);
  const std::vector<RGB> estimate = VarianceFromOneRender(v, kOneW, kOneH, {}, {});
  const auto nearEdge = [](int x, int) { return std::abs(x - kOneW / 2) <= 2; };
  const auto nearLine = [](int x, int y) { return x < kOneW / 2 - 12 && std::abs(x - y) <= 2; };
  const auto nearHighlight = [](int x, int y) { return x > kOneW / 2 + 12 && x % 16 / 6 == 1 && y % 16 / 6 == 1; };
  EXPECT_NEAR(OneRenderRatio(estimate, truth, share, nearEdge), 1.0, 0.25);
  EXPECT_NEAR(OneRenderRatio(estimate, truth, share, nearLine), 1.0, 0.25);
  EXPECT_LT(OneRenderRatio(estimate, truth, share, nearHighlight), 1.5);
  std::vector<RGB> r2(v.size());
  for (int y = 1; y < kOneH - 1; ++y)
    for (int x = 1; x < kOneW - 1; ++x) {
      const size_t i = size_t(y) * kOneW + size_t(x);
      const RGB r = v[i] - (v[i - 1] + v[i + 1] + v[i - kOneW] + v[i + kOneW]) * 0.25f;
      r2[i] = r * r * (1.f / 1.25f);
    }
  const std::vector<RGB> windowMean = SurfaceWindowMean(r2, kOneW, kOneH, {}, {}, 2);
  EXPECT_GT(OneRenderRatio(windowMean, truth, share, nearEdge), 10.0);
  EXPECT_GT(OneRenderRatio(windowMean, truth, share, nearLine), 10.0);
}

TEST(NoiseEstimate, OneRenderKeepsNonFiniteAndHugeValuesInTheirPixel) {
  // A NaN, an Inf and a finite 1e30 in a noisy grey: the NaN and the Inf get
  // no variance and give none; the huge value's own is finite. Beyond 6 px
  // (the blur, a pair, the choice over 3x3, the 7x7 median) nothing changes,
  // bit for bit; within it every pixel's stays finite and their mean within
  // 25 % of the truth (one window median holds 49 values: the few that cross
  // the odd pixel or lose a direction hardly move it).
  const std::vector<RGB> truth(size_t(kOneW) * kOneH, RGB::Gray(0.5f));
  const std::vector<double> share(truth.size(), 1e-4);
  const std::vector<RGB> clean = OneRender(truth, share, 0.9, 9);
  std::vector<RGB> v = clean;
  const std::vector<Point2i> odd{{40, 40}, {100, 40}, {70, 100}};
  v[size_t(40) * kOneW + 40] = RGB::Gray(std::numeric_limits<float>::quiet_NaN());
  v[size_t(40) * kOneW + 100] = RGB::Gray(std::numeric_limits<float>::infinity());
  v[size_t(100) * kOneW + 70] = RGB::Gray(1e30f);
  const std::vector<RGB> estimate = VarianceFromOneRender(v, kOneW, kOneH, {}, {});
  const std::vector<RGB> reference = VarianceFromOneRender(clean, kOneW, kOneH, {}, {});
  EXPECT_EQ(estimate[size_t(40) * kOneW + 40].g, 0.f);
  EXPECT_EQ(estimate[size_t(40) * kOneW + 100].g, 0.f);
  EXPECT_TRUE(IsFinite(estimate[size_t(100) * kOneW + 70]));
  double sum = 0;
  int near = 0;
  for (int y = 0; y < kOneH; ++y)
    for (int x = 0; x < kOneW; ++x) {
      const size_t i = size_t(y) * kOneW + size_t(x);
      int reach = kOneW;
      for (const Point2i& p : odd) reach = std::min(reach, std::max(std::abs(x - p.x), std::abs(y - p.y)));
      if (reach == 0) continue;
      ASSERT_TRUE(IsFinite(estimate[i])) << x << ", " << y;
      if (reach > 6) {
        ASSERT_EQ(estimate[i].g, reference[i].g) << x << ", " << y;
      } else {
        sum += estimate[i].g / (share[i] * (0.5 + kRelativeVarianceFloor));
        ++near;
      }
    }
  EXPECT_NEAR(sum / near, 1.0, 0.25);
}

TEST(NoiseEstimate, OneRenderFollowsTheNoiseAcrossTheImage) {
  // Sixteen times the noise share in the right half (a shadow lit by
  // bounces beside a direct light): each half's estimate is its own, within
  // 10 % away from the border between them (each half about 350 independent
  // windows: sd about 0.02).
  const std::vector<RGB> truth(size_t(kOneW) * kOneH, RGB::Gray(0.5f));
  std::vector<double> share(truth.size());
  for (size_t i = 0; i < share.size(); ++i) share[i] = int(i % kOneW) < kOneW / 2 ? 1e-4 : 16e-4;
  const std::vector<RGB> estimate = VarianceFromOneRender(OneRender(truth, share, 0.9, 8), kOneW, kOneH, {}, {});
  EXPECT_NEAR(OneRenderRatio(estimate, truth, share, [](int x, int) { return x < kOneW / 2 - 4; }), 1.0, 0.1);
  EXPECT_NEAR(OneRenderRatio(estimate, truth, share, [](int x, int) { return x >= kOneW / 2 + 4; }), 1.0, 0.1);
}

}  // namespace
}  // namespace dcm::testing
