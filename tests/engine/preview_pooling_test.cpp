// Preview pooling: an exact pixel and its preview, rendered on random numbers
// of their own, are two estimates of one value; their inverse-variance mean
// carries s / (1 + s) of the preview's variance where the exact one carries s.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "dcm/preview_pooling.h"
#include "dcm/round_schedule.h"
#include "noisy_provider.h"
#include "run_helpers.h"

namespace dcm::testing {
namespace {

constexpr int N = 128;
constexpr float kSd = 0.05f;       // the preview's noise
constexpr double kShare = 1.0 / 8;  // the exact samples' variance over the preview's

RGB Truth(int x, int) { return RGB::Gray(0.2f + 0.5f * float(x) / float(N)); }

/// Every pixel exact with noise of kShare times the preview's variance, and
/// the preview: the truth with independent noise of sd kSd.
struct Pair {
  Reconstruction rec;
  std::vector<RGB> truth;
  std::unique_ptr<ImagePreviewProvider> preview;
};

Pair ExactAndPreview(unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> previewNoise(0.f, kSd), exactNoise(0.f, kSd * float(std::sqrt(kShare)));
  Pair p;
  Reconstruction& r = p.rec;
  r.width = r.workWidth = N;
  r.height = r.workHeight = N;
  std::vector<RGB> L, var(size_t(N) * N, RGB::Gray(kSd * kSd));
  for (int y = 0; y < N; ++y)
    for (int x = 0; x < N; ++x) {
      const RGB t = Truth(x, y);
      p.truth.push_back(t);
      L.push_back({t.r + previewNoise(rng), t.g + previewNoise(rng), t.b + previewNoise(rng)});
      r.workImage.push_back({t.r + exactNoise(rng), t.g + exactNoise(rng), t.b + exactNoise(rng)});
    }
  r.image = r.workImage;
  r.sampleMap.assign(size_t(N) * N, SampleReason::kCorner);
  p.preview = std::make_unique<ImagePreviewProvider>(N, N, N, N, std::move(L), std::vector<RGB>{},
                                                     std::vector<RGB>{}, std::move(var));
  return p;
}

double Mse(const std::vector<RGB>& a, const std::vector<RGB>& b) {
  double s = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    const RGB d = a[i] - b[i];
    s += double(d.r) * d.r + double(d.g) * d.g + double(d.b) * d.b;
  }
  return s / double(3 * a.size());
}

TEST(PreviewPooling, APooledExactPixelCarriesTheInverseVarianceMeansNoise) {
  Pair p = ExactAndPreview(3);
  const double v = double(kSd) * kSd;
  const double before = Mse(p.rec.workImage, p.truth);
  int64_t pooled = 0;
  ASSERT_TRUE(PoolExactWithPreview(*p.preview, kShare, 1, &p.rec, &pooled).ok());
  EXPECT_EQ(pooled, int64_t(N) * N);
  const double after = Mse(p.rec.workImage, p.truth);
  // 3 x 128^2 independent Gaussian errors: each mean square has a relative sd
  // of sqrt(2 / 49152) = 0.64 %; 4 % is six of them, and the pooled noise is
  // 11 % below the exact samples' (1 / (1 + s) with s = 1/8).
  EXPECT_NEAR(before / (kShare * v), 1.0, 0.04);
  EXPECT_NEAR(after / (PreviewPoolWeight(kShare) * v), 1.0, 0.04) << "before " << before << ", after " << after;
  EXPECT_DOUBLE_EQ(PreviewPoolWeight(kShare), kShare / (1 + kShare));
  EXPECT_EQ(p.rec.image, p.rec.workImage) << "the output is made again from the pooled working image";
}

TEST(PreviewPooling, OnlyExactPixelsMoveAndANaNStaysInItsPixel) {
  Pair p = ExactAndPreview(4);
  Reconstruction& r = p.rec;
  r.sampleMap[0] = SampleReason::kInterpolated;
  r.sampleMap[1] = SampleReason::kPreviewStandIn;
  r.sampleMap[2] = SampleReason::kRendered;  // a round's exact value, filled in: pooled as well
  const float nan = std::numeric_limits<float>::quiet_NaN();
  r.workImage[3] = RGB::Gray(nan);  // a NaN sample neither takes the preview nor gives it
  const std::vector<RGB> before = r.workImage;
  int64_t pooled = 0;
  ASSERT_TRUE(PoolExactWithPreview(*p.preview, kShare, 1, &r, &pooled).ok());
  EXPECT_EQ(pooled, int64_t(N) * N - 3);
  EXPECT_EQ(r.workImage[0], before[0]);
  EXPECT_EQ(r.workImage[1], before[1]);
  EXPECT_NE(r.workImage[2], before[2]);
  EXPECT_TRUE(std::isnan(r.workImage[3].r));
  for (size_t i = 4; i < r.workImage.size(); ++i) ASSERT_TRUE(IsFinite(r.workImage[i])) << "pixel " << i;
}

TEST(PreviewPooling, NoiseFreeExactSamplesTakeNothingAndTheOutputIsDownsampled) {
  Pair p = ExactAndPreview(5);
  const std::vector<RGB> before = p.rec.workImage;
  int64_t pooled = -1;
  ASSERT_TRUE(PoolExactWithPreview(*p.preview, 0, 1, &p.rec, &pooled).ok());
  EXPECT_EQ(pooled, 0);
  EXPECT_EQ(p.rec.workImage, before);
  ASSERT_TRUE(PoolExactWithPreview(*p.preview, kShare, 2, &p.rec, &pooled).ok());
  ASSERT_EQ(p.rec.width, N / 2);
  const RGB* w = p.rec.workImage.data();
  const RGB box = (w[0] + w[1] + w[N] + w[N + 1]) * 0.25f;
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(p.rec.image[0][c], box[c], 1e-6f);
  EXPECT_FALSE(PoolExactWithPreview(*p.preview, kShare, 0, &p.rec).ok()) << "downsample 0";
  ImagePreviewProvider small(N / 2, N / 2, N / 2, N / 2, std::vector<RGB>(size_t(N / 2) * (N / 2)));
  const Status s = PoolExactWithPreview(small, kShare, 1, &p.rec);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("64x64"), std::string::npos) << s.message();
}

TEST(PreviewPooling, APreviewPlannedRunPoolsItsExactPixelsAndItsEstimateCountsThePooledNoise) {
  // The analytic furnished scene, exact samples with noise of known variance
  // and a preview eight times as noisy on noise of its own: the run's exact
  // pixels (not denoised here, to see the share alone) come out with 1/(1+s)
  // of their squared error, and the preview's estimate rises with them.
  constexpr int M = 128;
  AnalyticProvider truth(M, M, FurnishedScene(M, M));
  const std::vector<RGB> ref = truth.FullRender();
  NoisyProvider exact(truth, NoiseModel{0.02f, 0.002f, 3, true});
  const float k = float(std::sqrt(1 / kShare));
  NoisyProvider previewSource(truth, NoiseModel{0.02f * k, 0.002f * k, 11, true});
  std::vector<RGB> var(ref.size());
  for (size_t i = 0; i < ref.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const float sd = (0.02f * std::fabs(ref[i][c]) + 0.002f) * k;
      var[i][c] = sd * sd;
    }
  ImagePreviewProvider preview(M, M, M, M, previewSource.NoisyFullRender(), {}, {}, var);
  ReconstructionOptions o;
  o.textureSplit = false;
  o.denoiseSamples = false;
  Reconstruction r[2];
  PreviewScheduleStats stats[2];
  for (int pool : {0, 1}) {
    PreviewScheduleOptions schedule;
    schedule.exactVarianceShare = kShare;
    schedule.poolPreview = pool;
    ASSERT_TRUE(ReconstructWithPreview(exact, preview, o, schedule, &r[pool], &stats[pool]).ok());
  }
  ASSERT_EQ(r[0].sampleMap, r[1].sampleMap) << "pooling comes after every decision";
  std::vector<RGB> got[2], want;
  for (size_t i = 0; i < ref.size(); ++i) {
    const SampleReason why = r[1].sampleMap[i];
    if (why == SampleReason::kInterpolated || why == SampleReason::kPreviewStandIn) {
      EXPECT_EQ(r[0].workImage[i], r[1].workImage[i]) << "pixel " << i;
      continue;
    }
    want.push_back(ref[i]);
    for (int pool : {0, 1}) got[pool].push_back(r[pool].workImage[i]);
  }
  EXPECT_EQ(stats[0].pooledPixels, 0);
  EXPECT_EQ(stats[1].pooledPixels, int64_t(want.size()));
  ASSERT_GT(want.size(), 1000u);
  // 1/(1+s) = 0.889. NoiseModel's noise is one deviate for R, G and B, so
  // about 1800 pixels count once each: the cross term of the exact and the
  // preview's noise moves the ratio by a sd of 2 w (1 - w) sqrt(8 / 1800) =
  // 0.013 (w = 1/9); 0.05 is nearly four of them, and far from 1.
  EXPECT_NEAR(Mse(got[1], want) / Mse(got[0], want), 1 / (1 + kShare), 0.05);
  EXPECT_GT(stats[1].correction.estimate.psnr, stats[0].correction.estimate.psnr)
      << "the estimate counts an exact pixel at the pooled share";
}

}  // namespace
}  // namespace dcm::testing
