// Preview correction: the interpolation moves toward a noisy, unbiased preview
// only by the share of their difference the preview's noise does not explain.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "dcm/preview_correction.h"
#include "dcm/round_schedule.h"
#include "run_helpers.h"

namespace dcm::testing {
namespace {

constexpr int N = 64;
constexpr float kSd = 0.05f;  // the preview's noise

/// A smooth truth: a ramp in x.
RGB Truth(int x, int) { return RGB::Gray(0.2f + 0.5f * float(x) / float(N)); }

/// A reconstruction of N x N interpolated pixels with the values `value(x, y)`.
Reconstruction Interpolated(RGB (*value)(int, int)) {
  Reconstruction r;
  r.width = r.workWidth = N;
  r.height = r.workHeight = N;
  for (int y = 0; y < N; ++y)
    for (int x = 0; x < N; ++x) r.workImage.push_back(value(x, y));
  r.image = r.workImage;
  r.sampleMap.assign(size_t(N) * N, SampleReason::kInterpolated);
  return r;
}

/// The truth plus Gaussian noise of sd kSd, with that variance.
ImagePreviewProvider NoisyPreview(unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.f, kSd);
  std::vector<RGB> L, var(size_t(N) * N, RGB::Gray(kSd * kSd));
  for (int y = 0; y < N; ++y)
    for (int x = 0; x < N; ++x) {
      const RGB t = Truth(x, y);
      L.push_back({t.r + noise(rng), t.g + noise(rng), t.b + noise(rng)});
    }
  return ImagePreviewProvider(N, N, N, N, std::move(L), {}, {}, std::move(var));
}

double MseAgainstTruth(const Reconstruction& r, bool onlyStripe = false) {
  double sum = 0;
  int n = 0;
  for (int y = 0; y < N; ++y)
    for (int x = 0; x < N; ++x) {
      if (onlyStripe && (x < 24 || x >= 40)) continue;
      const RGB d = r.workImage[size_t(y) * N + x] - Truth(x, y);
      sum += double(d.r) * d.r + double(d.g) * d.g + double(d.b) * d.b;
      n += 3;
    }
  return sum / n;
}

TEST(PreviewCorrection, WhereTheInterpolationIsRightThePreviewsNoiseStaysOut) {
  Reconstruction r = Interpolated(Truth);
  ImagePreviewProvider preview = NoisyPreview(1);
  PreviewCorrectionStats stats;
  ASSERT_TRUE(CorrectTowardPreview(preview, 5, 1, &r, &stats).ok());
  // Unbiased: the window's mean d^2 exceeds its mean variance only by chance
  // (121 pixels: a relative sd of sqrt(2/121) = 0.13), so weights stay near
  // 0.13 / 1.13 at most and the noise let in is a few hundredths of kSd^2.
  EXPECT_LT(stats.meanWeight, 0.1);
  EXPECT_LT(MseAgainstTruth(r), 0.05 * kSd * kSd);
}

TEST(PreviewCorrection, AnExactPixelsOwnNoiseIsNoBiasOfItsWindow) {
  // Half the pixels exact (a checkerboard), each with noise of the preview's
  // variance (an exact share of 1) and seeds of its own; the interpolated
  // ones right. At an exact pixel the difference to the preview carries both
  // noises, 2 v: counted as v, each window would show a bias of v / 2, four
  // times its sd over 121 pixels, and pull every interpolated pixel a third
  // of the way to the preview's noise.
  std::mt19937 rng(11);
  std::normal_distribution<float> noise(0.f, kSd);
  Reconstruction r = Interpolated(Truth);
  for (int y = 0; y < N; ++y)
    for (int x = (y & 1); x < N; x += 2) {
      const size_t i = size_t(y) * N + size_t(x);
      r.sampleMap[i] = SampleReason::kBorder;
      r.workImage[i] = r.workImage[i] + RGB{noise(rng), noise(rng), noise(rng)};
    }
  ImagePreviewProvider preview = NoisyPreview(3);
  PreviewCorrectionStats stats;
  ASSERT_TRUE(CorrectTowardPreview(preview, 5, 1, &r, &stats, {}, 1.0).ok());
  // As with no exact pixel (WhereTheInterpolationIsRight...): chance excesses only.
  EXPECT_LT(stats.meanWeight, 0.1);
}

TEST(PreviewCorrection, WhatTheInterpolationMissedComesBackAtThePreviewsNoise) {
  // The interpolation lost a bright stripe (x in [24, 40)) of height 0.3 = 6 sd.
  Reconstruction r = Interpolated(+[](int x, int y) {
    return x >= 24 && x < 40 ? Truth(x, y) - RGB::Gray(0.3f) : Truth(x, y);
  });
  const double before = MseAgainstTruth(r, true);
  ImagePreviewProvider preview = NoisyPreview(2);
  ASSERT_TRUE(CorrectTowardPreview(preview, 5, 1, &r).ok());
  const double after = MseAgainstTruth(r, true);
  EXPECT_NEAR(before, 0.09, 1e-6);
  // Inside the stripe the weight is b^2 / (b^2 + v) = 0.97; near its edges the
  // window straddles it and the weight is lower: a few times the noise at most.
  EXPECT_LT(after, 3.0 * kSd * kSd) << "before " << before;
}

TEST(PreviewCorrection, ExactPixelsKeepTheirValuesAndANaNStaysInItsPixel) {
  Reconstruction r = Interpolated(+[](int x, int y) { return Truth(x, y) - RGB::Gray(0.3f); });
  for (int x = 0; x < N; ++x) r.sampleMap[size_t(10) * N + x] = SampleReason::kBorder;
  const std::vector<RGB> before = r.workImage;
  std::vector<RGB> L(size_t(N) * N), var(size_t(N) * N, RGB::Gray(kSd * kSd));
  for (int y = 0; y < N; ++y)
    for (int x = 0; x < N; ++x) L[size_t(y) * N + x] = Truth(x, y);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  L[size_t(30) * N + 30] = RGB::Gray(nan);
  var[size_t(40) * N + 40] = RGB::Gray(std::numeric_limits<float>::infinity());
  ImagePreviewProvider preview(N, N, N, N, std::move(L), {}, {}, std::move(var));
  ASSERT_TRUE(CorrectTowardPreview(preview, 5, 1, &r).ok());
  for (int x = 0; x < N; ++x) EXPECT_EQ(r.workImage[size_t(10) * N + x].r, before[size_t(10) * N + x].r);
  EXPECT_EQ(r.workImage[size_t(30) * N + 30].r, before[size_t(30) * N + 30].r) << "no preview: no move";
  EXPECT_EQ(r.workImage[size_t(40) * N + 40].r, before[size_t(40) * N + 40].r) << "no variance: no move";
  for (size_t i = 0; i < r.workImage.size(); ++i) ASSERT_TRUE(std::isfinite(r.workImage[i].r)) << i;
  EXPECT_NEAR(r.workImage[size_t(31) * N + 31].r, Truth(31, 31).r, 0.02) << "the neighbours still move";
  EXPECT_EQ(r.image.size(), r.workImage.size());
}

std::vector<RGB> TruthImage() {
  std::vector<RGB> t;
  for (int y = 0; y < N; ++y)
    for (int x = 0; x < N; ++x) t.push_back(Truth(x, y));
  return t;
}

TEST(PreviewCorrection, ItEstimatesTheCorrectedImagesPsnrFromThePreview) {
  // Interpolations that missed a stripe (0.3 = 6 sd, or 0.03: a bias of the
  // size of the noise's sd/2 that the correction leaves) and a quarter of
  // the pixels exact, corrected toward previews of 8 seeds (sd 0.05: the
  // preview's own PSNR about 27 dB, above the 25 dB the estimate needs). The
  // estimate from the preview alone is unbiased where the interpolation does
  // not depend on the preview: its 90 % interval covers the true display
  // PSNR at least 6 times in 8, and its mean error over the seeds is within
  // 1 dB (the small miss, an error 25 times below the preview's noise, gives
  // single estimates within about +-1.7 dB: 2.5 standard errors of the mean).
  for (float miss : {0.3f, 0.03f}) {
    double sumError = 0;
    int covered = 0;
    for (unsigned seed = 10; seed < 18; ++seed) {
      Reconstruction r = Interpolated(+[](int x, int y) { return Truth(x, y); });
      for (int y = 0; y < N; ++y)
        for (int x = 0; x < N; ++x) {
          RGB& v = r.workImage[size_t(y) * N + x];
          if (x % 2 == 0 && y % 2 == 0) r.sampleMap[size_t(y) * N + x] = SampleReason::kCorner;
          else if (x >= 24 && x < 40) v = v - RGB::Gray(miss);
        }
      ImagePreviewProvider preview = NoisyPreview(seed);
      PreviewCorrectionStats stats;
      ASSERT_TRUE(CorrectTowardPreview(preview, 5, 1, &r, &stats).ok());
      const double truth = DisplayPsnr(r.workImage, TruthImage());
      ASSERT_TRUE(std::isfinite(stats.estimate.psnr)) << "preview " << stats.previewPsnr << " dB";
      sumError += stats.estimate.psnr - truth;
      covered += truth >= stats.estimate.low && truth <= stats.estimate.high;
    }
    EXPECT_LT(std::fabs(sumError / 8), 1.0) << "missed by " << miss;
    EXPECT_GE(covered, 6) << "missed by " << miss;
  }
}

TEST(PreviewCorrection, AnExactPixelsNoiseIsItsShareOfThePreviewsVarianceThroughTheDisplayAtItsValue) {
  // Every pixel exact, at 1/16 of the preview's variance (a render of 16
  // times its samples), on a dark ramp (0.002 to 0.1) where the preview's
  // sd, 0.01, reaches below 0 and up the sRGB curve's bend: the preview's
  // own display variance, scaled by 1/16, understates the exact pixels' by
  // 1.3 dB here. Taken through the display at each pixel's value, the
  // estimate lies within 0.3 dB of the truth (one draw over 64^2 pixels
  // varies the truth by about 0.1 dB), and so does the render's own.
  constexpr float kShare = 1.f / 16;
  auto dark = [](int x) { return RGB::Gray(0.002f + 0.098f * float(x) / float(N)); };
  std::mt19937 rng(5);
  constexpr float sd = 0.01f;
  std::normal_distribution<float> previewNoise(0.f, sd), exactNoise(0.f, sd * std::sqrt(kShare));
  std::vector<RGB> truth, L, var(size_t(N) * N, RGB::Gray(sd * sd));
  Reconstruction r = Interpolated(Truth);
  for (int y = 0; y < N; ++y)
    for (int x = 0; x < N; ++x) {
      const RGB t = dark(x);
      truth.push_back(t);
      L.push_back({t.r + previewNoise(rng), t.g + previewNoise(rng), t.b + previewNoise(rng)});
      r.workImage[size_t(y) * N + x] = {t.r + exactNoise(rng), t.g + exactNoise(rng), t.b + exactNoise(rng)};
      r.sampleMap[size_t(y) * N + x] = SampleReason::kCorner;
    }
  r.image = r.workImage;
  ImagePreviewProvider preview(N, N, N, N, std::move(L), {}, {}, std::move(var));
  PreviewCorrectionStats stats;
  ASSERT_TRUE(CorrectTowardPreview(preview, 5, 1, &r, &stats, {}, kShare).ok());
  const double psnr = DisplayPsnr(r.workImage, truth);
  ASSERT_TRUE(std::isfinite(stats.estimate.psnr)) << "preview " << stats.previewPsnr << " dB";
  EXPECT_NEAR(stats.estimate.psnr, psnr, 0.3) << "the preview's own " << stats.previewPsnr << " dB";
  EXPECT_NEAR(stats.renderPsnr, psnr, 0.3);
  EXPECT_GT(stats.previewPsnr - 10 * std::log10(kShare), psnr + 1) << "the scaled display noise errs high here";
}

TEST(PreviewCorrection, ATextureGuideThatSharesThePreviewsSamplesIsTakenOut) {
  // A checker of albedos 0.2 and 0.8 whose edges cross two pixels in three
  // (coverage 0, 1/2, 1 by pixel), lit by L_i = 0.6 plus L_c = 0.05. The
  // preview's two halves of 4 samples each draw which albedo each sample sees,
  // and the texture guide is their mean, as Blender's DiffCol of the same
  // renders: the interpolation L_i tau + L_c is then off by L_i (tau - its
  // mean) where the preview is off by the same. Without the covariance of the
  // two the estimate misses that error, which the preview shares and
  // (X - A)(X - B) cancels: it errs far high (here it sees no error at all,
  // +inf); with it the estimate is unbiased: over 8 seeds its mean error is
  // within 0.5 dB (single estimates within about 0.3 dB of the truth).
  constexpr float kLi = 0.6f, kLc = 0.05f, kLightSd = 0.02f, kMiss = 0.05f;
  constexpr int kHalf = 4;
  double sumWith = 0, sumWithout = 0;
  for (unsigned seed = 30; seed < 38; ++seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    std::normal_distribution<float> light(0.f, kLightSd);
    const size_t n = size_t(N) * N;
    std::vector<RGB> truth(n), L(n), Li(n, RGB::Gray(kLi)), Lc(n, RGB::Gray(kLc)), var(n), cov(n);
    Reconstruction r = Interpolated(Truth);
    for (int y = 0; y < N; ++y)
      for (int x = 0; x < N; ++x) {
        const size_t i = size_t(y) * N + x;
        const float coverage = float((x + y) % 3) / 2.f;  // of albedo 0.8
        const float tauTrue = 0.2f + 0.6f * coverage;
        truth[i] = RGB::Gray(kLi * tauTrue + kLc);
        float tau[2], l[2];
        for (int h = 0; h < 2; ++h) {
          float st = 0, sl = 0;
          for (int k = 0; k < kHalf; ++k) {
            const float t = u(rng) < coverage ? 0.8f : 0.2f;
            st += t;
            sl += kLi * t + kLc + light(rng);
          }
          tau[h] = st / kHalf, l[h] = sl / kHalf;
        }
        const float tauMean = (tau[0] + tau[1]) / 2;
        L[i] = RGB::Gray((l[0] + l[1]) / 2);
        var[i] = RGB::Gray((l[0] - l[1]) * (l[0] - l[1]) / 4);
        cov[i] = RGB::Gray((tau[0] - tau[1]) * (l[0] - l[1]) / 4);
        // Exact on a 4-pixel lattice; elsewhere the interpolation's tau is the
        // guide's, its lighting right but in a stripe, where it missed by kMiss.
        if (x % 4 == 0 && y % 4 == 0) {
          r.sampleMap[i] = SampleReason::kCorner;
          r.workImage[i] = truth[i];
        } else {
          r.workImage[i] = RGB::Gray((x >= 24 && x < 40 ? kLi + kMiss : kLi) * tauMean + kLc);
        }
      }
    for (bool withCov : {true, false}) {
      Reconstruction rr = r;
      ImagePreviewProvider preview(N, N, N, N, L, Li, Lc, var);
      PreviewCorrectionStats stats;
      ASSERT_TRUE(CorrectTowardPreview(preview, 5, 1, &rr, &stats, {}, 0,
                                       withCov ? std::span<const RGB>(cov) : std::span<const RGB>())
                      .ok());
      const double error = stats.estimate.psnr - DisplayPsnr(rr.workImage, truth);  // +inf: no error seen
      if (withCov) {
        ASSERT_TRUE(std::isfinite(error)) << "preview " << stats.previewPsnr << " dB";
      }
      (withCov ? sumWith : sumWithout) += error;
    }
  }
  EXPECT_LT(std::fabs(sumWith / 8), 0.5);
  EXPECT_GT(sumWithout / 8, 1.5);
  // A covariance per pixel or none.
  Reconstruction r = Interpolated(Truth);
  ImagePreviewProvider preview = NoisyPreview(3);
  EXPECT_FALSE(CorrectTowardPreview(preview, 5, 1, &r, nullptr, {}, 0, std::vector<RGB>(7)).ok());
}

TEST(PreviewCorrection, ANoisyPreviewMakesNoEstimate) {
  // sd 0.2 on values of 0.2-0.7: the preview's own PSNR about 15 dB, below 25.
  std::mt19937 rng(5);
  std::normal_distribution<float> noise(0.f, 0.2f);
  std::vector<RGB> L, var(size_t(N) * N, RGB::Gray(0.04f));
  for (int y = 0; y < N; ++y)
    for (int x = 0; x < N; ++x) L.push_back(Truth(x, y) + RGB::Gray(noise(rng)));
  ImagePreviewProvider preview(N, N, N, N, std::move(L), {}, {}, std::move(var));
  Reconstruction r = Interpolated(Truth);
  PreviewCorrectionStats stats;
  ASSERT_TRUE(CorrectTowardPreview(preview, 5, 1, &r, &stats).ok());
  EXPECT_LT(stats.previewPsnr, 25);
  EXPECT_TRUE(std::isnan(stats.estimate.psnr));
}

TEST(PreviewCorrection, AFireflyChangesOnlyTheWindowsItIsIn) {
  // A lost stripe, as above, and one preview pixel of radiance 1e6 far from it
  // (a firefly): its d^4 of 1e24 must not swamp the sums of other windows.
  Reconstruction r = Interpolated(+[](int x, int y) {
    return x >= 24 && x < 40 ? Truth(x, y) - RGB::Gray(0.3f) : Truth(x, y);
  });
  // Around the firefly the preview is off by 0.01, a fifth of its sd: noise, no bias.
  std::vector<RGB> L(size_t(N) * N), var(size_t(N) * N, RGB::Gray(kSd * kSd));
  for (int y = 0; y < N; ++y)
    for (int x = 0; x < N; ++x) L[size_t(y) * N + x] = Truth(x, y) + RGB::Gray(y < 12 ? 0.01f : 0.f);
  L[size_t(2) * N + 2] = RGB::Gray(1e6f);
  ImagePreviewProvider preview(N, N, N, N, std::move(L), {}, {}, std::move(var));
  ASSERT_TRUE(CorrectTowardPreview(preview, 5, 1, &r).ok());
  // Far from the firefly (rows from 20), where the window lies inside the
  // stripe: b = 0.09 - 0.0025 against v = 0.0025, weight 0.97, so 3 % of the
  // loss remains (tolerance 5 %).
  for (int y = 20; y < N; ++y)
    for (int x = 29; x <= 34; ++x) ASSERT_NEAR(r.workImage[size_t(y) * N + x].r, Truth(x, y).r, 0.3 * 0.05) << x << "," << y;
  // The firefly's window (one sample in 121 whose e is 1e12): its standard
  // error is as large as its mean, the test fails, and its pixels stay.
  EXPECT_EQ(r.workImage[size_t(3) * N + 3].r, Truth(3, 3).r);
}

TEST(PreviewCorrection, RadiusZeroChangesNothingAndAPreviewWithoutVarianceIsRefused) {
  Reconstruction r = Interpolated(Truth);
  const std::vector<RGB> before = r.workImage;
  ImagePreviewProvider preview = NoisyPreview(3);
  ASSERT_TRUE(CorrectTowardPreview(preview, 0, 1, &r).ok());
  for (size_t i = 0; i < before.size(); ++i) ASSERT_EQ(r.workImage[i].g, before[i].g);
  ImagePreviewProvider noVariance(N, N, N, N, std::vector<RGB>(size_t(N) * N));
  EXPECT_FALSE(CorrectTowardPreview(noVariance, 5, 1, &r).ok());
  EXPECT_FALSE(CorrectTowardPreview(preview, -1, 1, &r).ok());
  EXPECT_FALSE(CorrectTowardPreview(preview, 5, 0, &r).ok());
}

TEST(PreviewCorrection, TheOutputIsTheCorrectedWorkingImageDownsampled) {
  // Working 2N x 2N for an N x N output (downsample 2).
  Reconstruction r;
  r.workWidth = r.workHeight = 2 * N;
  r.width = r.height = N;
  r.workImage.assign(size_t(4) * N * N, RGB::Gray(0.1f));
  r.image.assign(size_t(N) * N, RGB::Gray(0.1f));
  r.sampleMap.assign(r.workImage.size(), SampleReason::kInterpolated);
  ImagePreviewProvider preview(2 * N, 2 * N, 2 * N, 2 * N, std::vector<RGB>(r.workImage.size(), RGB::Gray(0.5f)),
                               {}, {}, std::vector<RGB>(r.workImage.size(), RGB::Gray(1e-4f)));
  ASSERT_TRUE(CorrectTowardPreview(preview, 3, 2, &r).ok());
  ASSERT_EQ(r.width, N);
  ASSERT_EQ(r.image.size(), size_t(N) * N);
  // b^2 = 0.16 against v = 1e-4: the weight is 0.9994.
  EXPECT_NEAR(r.image[0].r, 0.5f, 1e-3f);
}

TEST(PreviewCorrection, APreviewPlannedRunWithANoisyPreviewGetsCloserToTheTruth) {
  // The analytic furnished scene, its preview the truth plus noise of known
  // variance: the correction must not make the result worse than without it.
  constexpr int M = 128;
  AnalyticProvider truth(M, M, FurnishedScene(M, M));
  const std::vector<RGB> ref = truth.FullRender();
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0.f, 0.02f);
  std::vector<RGB> L = ref, var(ref.size(), RGB::Gray(0.02f * 0.02f));
  for (RGB& v : L) v = {v.r + noise(rng), v.g + noise(rng), v.b + noise(rng)};
  ImagePreviewProvider preview(M, M, M, M, std::move(L), {}, {}, std::move(var));
  ReconstructionOptions o;
  o.textureSplit = false;
  double mse[2];
  for (int radius : {0, 5}) {
    PreviewScheduleOptions schedule;
    schedule.correctionRadius = radius;
    Reconstruction r;
    PreviewScheduleStats stats;
    ASSERT_TRUE(ReconstructWithPreview(truth, preview, o, schedule, &r, &stats).ok());
    EXPECT_EQ(stats.correction.pixels > 0, radius > 0);
    // Pixels a round rendered that the final run did not ask for hold their
    // exact values, corrected or not, and the correction did not count them.
    int64_t rendered = 0, interpolated = 0;
    for (size_t i = 0; i < ref.size(); ++i) {
      interpolated += r.sampleMap[i] == SampleReason::kInterpolated;
      if (r.sampleMap[i] != SampleReason::kRendered) continue;
      ++rendered;
      EXPECT_EQ(r.workImage[i], ref[i]) << "pixel " << i;
    }
    EXPECT_GT(rendered, 0) << "the noisy preview's plan asks for pixels the exact samples do not";
    EXPECT_LE(stats.correction.pixels, interpolated);
    double s = 0;
    for (size_t i = 0; i < ref.size(); ++i) {
      const RGB d = r.image[i] - ref[i];
      s += double(d.r) * d.r + double(d.g) * d.g + double(d.b) * d.b;
    }
    mse[radius > 0] = s / double(3 * ref.size());
  }
  // Where the interpolation is exact the weights stay near 0 (the first test);
  // where it errs by more than the noise, the error shrinks.
  EXPECT_LE(mse[1], mse[0]) << "without " << mse[0] << ", with " << mse[1];
}

TEST(PreviewCorrection, WithEachPixelsOwnVarianceIsolatedMissesComeBackAndTheirSurroundsStayClean) {
  // The interpolation lost isolated dots (1.0 = 20 sd, every 16 pixels) and a
  // thin line (one column, 0.5). In an 11 x 11 window a dot is one pixel of
  // 121: the window's excess is 1 / 121, less than 1.5 standard errors (its
  // sd measured in the window, about 1 / 11, over 11), so the Wiener share
  // alone leaves the dot lost. Over 7 x 7 its d^2 of 1 outweighs what taking
  // the preview costs, 3 v more per pixel (0.37). The line passes that test, and its
  // Wiener share (0.96) lets the noise into every pixel of its window, also
  // 4 and 5 pixels from it, where the interpolation is right. With each
  // pixel's own variance, the share is chosen over 7 x 7 windows among none,
  // the Wiener share and all: the dots take the preview, the pixels 4 and 5
  // columns from the line keep the interpolation.
  auto lost = +[](int x, int y) {
    const bool dot = x % 16 == 8 && y % 16 == 8 && x < 40;
    return dot ? Truth(x, y) - RGB::Gray(1.0f) : x == 52 ? Truth(x, y) - RGB::Gray(0.5f) : Truth(x, y);
  };
  auto dotError = [](const Reconstruction& r) {
    double s = 0;
    for (int y = 8; y < N; y += 16)
      for (int x = 8; x < 40; x += 16) s += std::fabs(r.workImage[size_t(y) * N + x].r - Truth(x, y).r);
    return s / 8;
  };
  auto besideLineMse = [](const Reconstruction& r) {  // columns 4 and 5 from the line, both sides
    double s = 0;
    int n = 0;
    for (int y = 0; y < N; ++y)
      for (int x : {47, 48, 56, 57}) {
        const double d = r.workImage[size_t(y) * N + x].g - Truth(x, y).g;
        s += d * d;
        ++n;
      }
    return s / n;
  };
  Reconstruction wiener = Interpolated(lost), chosen = Interpolated(lost);
  ImagePreviewProvider preview = NoisyPreview(4);
  ASSERT_TRUE(CorrectTowardPreview(preview, 5, 1, &wiener).ok());
  const std::vector<RGB> own(size_t(N) * N, RGB::Gray(kSd * kSd));
  ASSERT_TRUE(CorrectTowardPreview(preview, 5, 1, &chosen, nullptr, own).ok());
  // A dot that took the preview is off by its noise (sd 0.05; the mean
  // |error| of 8 such is about 0.04): a tenth of the loss at most.
  EXPECT_GT(dotError(wiener), 0.9) << "the Wiener share alone keeps the dots lost";
  EXPECT_LT(dotError(chosen), 0.1);
  // Beside the line the Wiener share lets in 0.96^2 of the preview's variance;
  // the chosen share keeps the interpolation, which is exact there.
  EXPECT_GT(besideLineMse(wiener), 0.5 * kSd * kSd);
  EXPECT_LT(besideLineMse(chosen), 0.1 * kSd * kSd);
}

}  // namespace
}  // namespace dcm::testing
