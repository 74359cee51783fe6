// Pooling the variance of two halves (dcm/noise_estimate.h): a Monte Carlo
// estimate's variance grows with its value, so it is pooled as a share of it.
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

}  // namespace
}  // namespace dcm::testing
