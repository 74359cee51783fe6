// Preview filter: a leave-one-out mean of the preview over the neighbours the
// guides and the pilot call alike, and the correction that ends halfway to it.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "dcm/preview_correction.h"
#include "dcm/preview_filter.h"
#include "dcm/round_schedule.h"
#include "run_helpers.h"

namespace dcm::testing {
namespace {

constexpr int N = 48;
constexpr size_t kPixels = size_t(N) * N;
constexpr float kSd = 0.05f;

std::vector<ExactSample> Samples(const std::vector<RGB>& L) {
  std::vector<ExactSample> s(L.size());
  for (size_t i = 0; i < L.size(); ++i) s[i].L = L[i];
  return s;
}

std::vector<RGB> Constant(float v) { return std::vector<RGB>(kPixels, RGB::Gray(v)); }

/// `truth` plus noise of sd kSd, independent per channel or (`gray`) the
/// same in all three, as a path tracer's noise of the path's throughput.
std::vector<RGB> Noisy(const std::vector<RGB>& truth, unsigned seed, bool gray = false) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.f, kSd);
  std::vector<RGB> L = truth;
  for (RGB& v : L) v = v + (gray ? RGB::Gray(noise(rng)) : RGB(noise(rng), noise(rng), noise(rng)));
  return L;
}

const std::vector<SampleReason> kAllInterpolated(kPixels, SampleReason::kInterpolated);

TEST(PreviewFilter, OnAFlatSurfaceItIsTheMeanOfTheOtherPixelsOfTheWindow) {
  // A constant pilot, no guides: every neighbour weighs 1, so each value is
  // the plain mean of the 48 others of its 7 x 7 window (fewer at the border):
  // its noise variance kSd^2 / 48 inside, up to kSd^2 / 15 in the corners. Over
  // the image the mean squared error lies between kSd^2 / 48 and kSd^2 / 30
  // (the border's share; the 6912 values' sampling error is a few per cent).
  const std::vector<RGB> L = Noisy(Constant(0.4f), 1);
  FilteredPreview f;
  ASSERT_TRUE(FilterPreview(Samples(L), false, {}, Constant(0.4f), {}, kAllInterpolated, N, N, 3, &f).ok());
  double mse = 0;
  for (const RGB& v : f.value)
    for (int c = 0; c < 3; ++c) mse += (v[c] - 0.4) * (v[c] - 0.4) / (3.0 * kPixels);
  EXPECT_GT(mse, kSd * kSd / 48 * 0.9);
  EXPECT_LT(mse, kSd * kSd / 30);
  // The pixel's own preview is left out: changing it changes no value there.
  std::vector<RGB> moved = L;
  moved[size_t(20) * N + 20] = RGB::Gray(5.f);
  FilteredPreview g;
  ASSERT_TRUE(FilterPreview(Samples(moved), false, {}, Constant(0.4f), {}, kAllInterpolated, N, N, 3, &g).ok());
  EXPECT_EQ(g.value[size_t(20) * N + 20].r, f.value[size_t(20) * N + 20].r);
  EXPECT_NE(g.value[size_t(20) * N + 21].r, f.value[size_t(20) * N + 21].r);
  EXPECT_TRUE(f.plus.empty() && f.minus.empty());
}

TEST(PreviewFilter, NothingCrossesAnObjectsEdgeOrAStepOfThePilot) {
  // Left half object 1 at 0.2, right half object 2 at 0.8, the preview
  // noise-free: each side's values are its own, exactly (a weight across
  // would pull them by 0.6 times its share).
  std::vector<RGB> truth(kPixels);
  GuideImage guides;
  guides.region = {{0, 0}, {N, N}};
  guides.objectId.resize(kPixels);
  for (int y = 0; y < N; ++y)
    for (int x = 0; x < N; ++x) {
      truth[size_t(y) * N + x] = RGB::Gray(x < N / 2 ? 0.2f : 0.8f);
      guides.objectId[size_t(y) * N + x] = x < N / 2 ? 1 : 2;
    }
  FilteredPreview f;
  ASSERT_TRUE(FilterPreview(Samples(truth), false, guides, Constant(0.5f), {}, kAllInterpolated, N, N, 3, &f).ok());
  for (size_t i = 0; i < kPixels; ++i) ASSERT_FLOAT_EQ(f.value[i].g, truth[i].g) << i;
  // The same step in the pilot alone (no guides): 0.6 in the display is 12
  // widths of 0.05 per channel, a weight of exp(-3 * 72) = 0.
  ASSERT_TRUE(FilterPreview(Samples(truth), false, {}, truth, {}, kAllInterpolated, N, N, 3, &f).ok());
  for (size_t i = 0; i < kPixels; ++i) ASSERT_FLOAT_EQ(f.value[i].g, truth[i].g) << i;
}

TEST(PreviewFilter, LightingAndTextureAreAveragedApartSoTheTextureStaysSharp) {
  // A fine checker of albedos 0.5 and 0.53 (within the texture guide's
  // width, so the neighbours of the other albedo weigh exp(-3 * 0.0009 /
  // 0.005) = 0.58) under a noise-free light L_i = 0.6, L_c = 0.1. Averaged
  // apart the value is mean(L_i) tau + mean(L_c): the truth, to rounding.
  // Averaged as one, it is pulled by about half of the checker's step of
  // 0.6 * 0.03 = 0.018 toward the other albedo.
  std::vector<ExactSample> s(kPixels);
  GuideImage guides;
  guides.region = {{0, 0}, {N, N}};
  guides.texture.resize(kPixels);
  for (int y = 0; y < N; ++y)
    for (int x = 0; x < N; ++x) {
      const size_t i = size_t(y) * N + x;
      guides.texture[i] = RGB::Gray((x + y) % 2 ? 0.53f : 0.5f);
      s[i].Li = RGB::Gray(0.6f);
      s[i].Lc = RGB::Gray(0.1f);
      s[i].L = s[i].Li * guides.texture[i] + s[i].Lc;
    }
  std::vector<RGB> truth(kPixels);
  for (size_t i = 0; i < kPixels; ++i) truth[i] = s[i].L;
  FilteredPreview apart, together;
  ASSERT_TRUE(FilterPreview(s, true, guides, truth, {}, kAllInterpolated, N, N, 3, &apart).ok());
  ASSERT_TRUE(FilterPreview(s, false, guides, truth, {}, kAllInterpolated, N, N, 3, &together).ok());
  double worstApart = 0, meanTogether = 0;
  for (size_t i = 0; i < kPixels; ++i) {
    worstApart = std::max(worstApart, double(std::fabs(apart.value[i].r - truth[i].r)));
    meanTogether += std::fabs(together.value[i].r - truth[i].r) / double(kPixels);
  }
  EXPECT_LT(worstApart, 1e-6);
  EXPECT_GT(meanTogether, 0.005);
}

TEST(PreviewFilter, OnlyInterpolatedPixelsGetAValueAndNaNStaysOut) {
  std::vector<RGB> L = Noisy(Constant(0.4f), 2);
  L[size_t(10) * N + 10] = RGB::Gray(std::numeric_limits<float>::quiet_NaN());
  std::vector<SampleReason> map = kAllInterpolated;
  map[size_t(30) * N + 30] = SampleReason::kCorner;
  FilteredPreview f;
  ASSERT_TRUE(FilterPreview(Samples(L), false, {}, Constant(0.4f), {}, map, N, N, 3, &f).ok());
  EXPECT_TRUE(std::isnan(f.value[size_t(30) * N + 30].r)) << "an exact pixel";
  EXPECT_TRUE(std::isnan(f.value[size_t(10) * N + 10].r)) << "no preview";
  for (size_t i = 0; i < kPixels; ++i)
    if (i != size_t(30) * N + 30 && i != size_t(10) * N + 10) {
      ASSERT_TRUE(IsFinite(f.value[i])) << i;
    }
  // A lone pixel: its only neighbours are of another object.
  GuideImage guides;
  guides.region = {{0, 0}, {N, N}};
  guides.objectId.assign(kPixels, 1);
  guides.objectId[size_t(5) * N + 5] = 2;
  ASSERT_TRUE(FilterPreview(Samples(L), false, guides, Constant(0.4f), {}, map, N, N, 3, &f).ok());
  EXPECT_TRUE(std::isnan(f.value[size_t(5) * N + 5].r));
  EXPECT_FALSE(FilterPreview(Samples(L), false, {}, Constant(0.4f), {}, map, N, N - 1, 3, &f).ok());
  guides.objectId.resize(7);
  EXPECT_FALSE(FilterPreview(Samples(L), false, guides, Constant(0.4f), {}, map, N, N, 3, &f).ok());
}

// The correction with the filter, on a ramp whose interpolation lost a stripe.
RGB Ramp(int x, int) { return RGB::Gray(0.2f + 0.5f * float(x) / float(N)); }

struct Case {
  std::vector<RGB> truth;
  Reconstruction rec;
};

/// A quarter of the pixels exact (even x and y), the others interpolated,
/// 0.3 short in the stripe 16 <= x < 32.
Case Stripe() {
  Case c;
  Reconstruction& r = c.rec;
  r.width = r.workWidth = N;
  r.height = r.workHeight = N;
  r.sampleMap = kAllInterpolated;
  for (int y = 0; y < N; ++y)
    for (int x = 0; x < N; ++x) {
      c.truth.push_back(Ramp(x, y));
      const bool exact = x % 2 == 0 && y % 2 == 0;
      if (exact) r.sampleMap[size_t(y) * N + x] = SampleReason::kCorner;
      r.workImage.push_back(!exact && x >= 16 && x < 32 ? Ramp(x, y) - RGB::Gray(0.3f) : Ramp(x, y));
    }
  r.image = r.workImage;
  return c;
}

TEST(PreviewFilter, TheCorrectionEndsCloserAndItsEstimateStaysUnbiased) {
  // Previews of 8 seeds (sd 0.05, about 27 dB of their own, the same in R, G
  // and B: the estimate takes the noise as a path tracer's). Without the
  // filter, the stripe's pixels take the preview (its noise, kSd^2); with it
  // they end halfway to the mean of their like neighbours, whose noise is a
  // few times smaller: the squared error falls to about 0.3 of what it was
  // (bound 0.6, over the 8 seeds). The estimate's mean error over the seeds
  // stays within 1 dB, as without the filter (PreviewCorrection's test).
  double errorWith = 0, errorWithout = 0, estimateError = 0;
  for (unsigned seed = 40; seed < 48; ++seed) {
    const Case c = Stripe();
    std::vector<RGB> var(kPixels, RGB::Gray(kSd * kSd));
    for (bool filter : {false, true}) {
      Reconstruction r = c.rec;
      ImagePreviewProvider preview(N, N, N, N, Noisy(c.truth, seed, true), {}, {}, var);
      PreviewCorrectionStats stats;
      ASSERT_TRUE(CorrectTowardPreview(preview, 5, 1, &r, &stats, {}, 0, {}, filter ? 3 : 0).ok());
      double mse = 0;
      for (size_t i = 0; i < kPixels; ++i) {
        const RGB d = r.workImage[i] - c.truth[i];
        mse += (double(d.r) * d.r + double(d.g) * d.g + double(d.b) * d.b) / (3.0 * kPixels);
      }
      (filter ? errorWith : errorWithout) += mse;
      if (filter) {
        EXPECT_GT(stats.filtered, int64_t(kPixels / 2));
        ASSERT_TRUE(std::isfinite(stats.estimate.psnr));
        estimateError += (stats.estimate.psnr - DisplayPsnr(r.workImage, c.truth)) / 8;
      } else {
        EXPECT_EQ(stats.filtered, 0);
      }
    }
  }
  EXPECT_LT(errorWith, 0.6 * errorWithout);
  EXPECT_LT(std::fabs(estimateError), 1.0);
}

}  // namespace
}  // namespace dcm::testing
