// The exact samples' noise measured on a round: the ratio of their variance to
// the preview's at the same pixels, weighted as display errors are; once, on
// the first round big enough; the caller gets what it asked for.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "analytic_provider.h"
#include "dcm/exact_noise_meter.h"
#include "noisy_provider.h"

namespace dcm::testing {
namespace {

constexpr int M = 64;

/// Records whether each call asked for the variance.
class AskLog : public SampleProvider {
 public:
  explicit AskLog(SampleProvider& inner) : inner_(inner) {}
  ProviderCapabilities Capabilities() const override { return inner_.Capabilities(); }
  Status Guides(const Bounds2i& r, const GuideRequest& w, GuideImage* out) override { return inner_.Guides(r, w, out); }
  Status Evaluate(std::span<const Point2i> pixels, const SampleRequest& what, std::span<ExactSample> out) override {
    askedVariance.push_back(what.variance);
    return inner_.Evaluate(pixels, what, out);
  }
  std::vector<bool> askedVariance;

 private:
  SampleProvider& inner_;
};

std::vector<Point2i> Pixels(int first, int count) {
  std::vector<Point2i> p;
  for (int i = first; i < first + count; ++i) p.push_back({i % M, i / M});
  return p;
}

/// d(sRGB)/dx from the standard's formula, 1.055 / 2.4 x^(1/2.4 - 1) above the linear segment.
double Slope(float x) {
  if (x <= 0.0031308f) return 12.92;
  return 1.055 / 2.4 * std::pow(double(std::min(x, 1.f)), 1 / 2.4 - 1);
}

struct Fixture {
  AnalyticProvider truth{M, M, FurnishedScene(M, M)};
  NoisyProvider noisy{truth, NoiseModel{0.1f, 0.01f, 3, true}};
  AskLog log{noisy};
  /// Each pixel's exact variance (NoiseModel: sd = 0.1 L + 0.01 per channel).
  std::vector<RGB> ExactVariance() {
    std::vector<RGB> v = truth.FullRender();
    for (RGB& c : v)
      for (int k = 0; k < 3; ++k) c[k] = (0.1f * std::fabs(c[k]) + 0.01f) * (0.1f * std::fabs(c[k]) + 0.01f);
    return v;
  }
};

TEST(ExactNoiseMeter, APreviewFourTimesAsNoisyMeasuresAQuarter) {
  Fixture f;
  std::vector<RGB> own = f.ExactVariance();
  for (RGB& c : own) c = c * 4.f;
  ExactNoiseMeter meter(f.log);
  meter.SetPreviewVariance(&own);
  const std::vector<Point2i> px = Pixels(0, 1000);
  std::vector<ExactSample> out(px.size());
  ASSERT_TRUE(meter.Evaluate(px, SampleRequest{}, out).ok());
  // The same ratio at every pixel: any weighting gives it (float rounding of 4x).
  EXPECT_NEAR(meter.share(), 0.25, 1e-6);
  EXPECT_EQ(meter.pixels(), 1000);
  EXPECT_EQ(f.log.askedVariance, std::vector<bool>{true}) << "the round is rendered with its variance";
  for (const ExactSample& s : out) EXPECT_EQ(s.variance, RGB{}) << "not asked for: not given";
  // The next round passes as asked, and the share stays the first round's.
  ASSERT_TRUE(meter.Evaluate(Pixels(1000, 1000), SampleRequest{}, out).ok());
  EXPECT_EQ(f.log.askedVariance, (std::vector<bool>{true, false}));
  EXPECT_EQ(meter.pixels(), 1000);
}

TEST(ExactNoiseMeter, LaterRoundsTakeThePreviewsVarianceTimesTheShare) {
  // The preview four times as noisy: after the first round measured a quarter,
  // a round that asks for the variance is rendered without it (one render
  // call) and gets the preview's own variance times the quarter, which is the
  // exact variance here; without SetVarianceFromPreview it is rendered in halves.
  Fixture f;
  const std::vector<RGB> exact = f.ExactVariance();
  std::vector<RGB> own = exact;
  for (RGB& c : own) c = c * 4.f;
  for (const bool fromPreview : {true, false}) {
    f.log.askedVariance.clear();
    ExactNoiseMeter meter(f.log);
    meter.SetPreviewVariance(&own);
    meter.SetVarianceFromPreview(fromPreview);
    std::vector<ExactSample> out(1000);
    ASSERT_TRUE(meter.Evaluate(Pixels(0, 1000), SampleRequest{false, true}, out).ok());
    ASSERT_NEAR(meter.share(), 0.25, 1e-6);
    const std::vector<Point2i> later = Pixels(1000, 1000);
    ASSERT_TRUE(meter.Evaluate(later, SampleRequest{false, true}, out).ok());
    EXPECT_EQ(f.log.askedVariance, (std::vector<bool>{true, !fromPreview}));
    for (size_t i = 0; i < later.size(); ++i) {
      const RGB& want = exact[size_t(later[i].y) * M + size_t(later[i].x)];
      // 4 x and x 0.25: float rounding only.
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(out[i].variance[c], want[c], 1e-6f * want[c]) << i;
    }
    // Not asked for: none, from the preview or not.
    ASSERT_TRUE(meter.Evaluate(later, SampleRequest{}, out).ok());
    for (const ExactSample& s : out) EXPECT_EQ(s.variance, RGB{});
  }
}

TEST(ExactNoiseMeter, DarkPixelsWeighAsTheDisplaysSlopeSays) {
  // The preview four times as noisy where the truth is dark, sixteen times
  // where it is bright: the share is the ratio of the display-weighted sums.
  Fixture f;
  const std::vector<RGB> ref = f.truth.FullRender();
  const std::vector<RGB> var = f.ExactVariance();
  std::vector<RGB> own = var;
  for (size_t i = 0; i < own.size(); ++i) own[i] = own[i] * (Luminance(ref[i]) < 0.1f ? 4.f : 16.f);
  ExactNoiseMeter meter(f.log);
  meter.SetPreviewVariance(&own);
  const std::vector<Point2i> px = Pixels(0, M * M);
  std::vector<ExactSample> out(px.size());
  ASSERT_TRUE(meter.Evaluate(px, SampleRequest{false, true}, out).ok());
  double num = 0, den = 0;
  for (size_t i = 0; i < px.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double w = Slope(out[i].L[c]) * Slope(out[i].L[c]);
      num += w * var[i][c];
      den += w * own[i][c];
      EXPECT_EQ(out[i].variance[c], var[i][c]) << "asked for: given as rendered";
    }
  EXPECT_NEAR(meter.share(), num / den, 1e-6 * num / den);
  const double dark = 0.25, bright = 1.0 / 16;
  EXPECT_GT(meter.share(), bright);
  EXPECT_LT(meter.share(), dark);
}

TEST(ExactNoiseMeter, NothingIsMeasuredWithoutWhatItNeeds) {
  Fixture f;
  std::vector<RGB> own = f.ExactVariance();
  std::vector<ExactSample> out(M * M);
  {
    // A round too small to measure, then one that is big enough.
    ExactNoiseMeter meter(f.log);
    meter.SetPreviewVariance(&own);
    ASSERT_TRUE(meter.Evaluate(Pixels(0, int(ExactNoiseMeter::kMinPixels) - 1), SampleRequest{}, out).ok());
    EXPECT_TRUE(std::isnan(meter.share()));
    ASSERT_TRUE(meter.Evaluate(Pixels(300, 300), SampleRequest{}, out).ok());
    EXPECT_NEAR(meter.share(), 1.0, 1e-6);
    EXPECT_EQ(f.log.askedVariance, (std::vector<bool>{false, true}));
  }
  {
    // No preview variance, or one of another size.
    ExactNoiseMeter meter(f.noisy);
    ASSERT_TRUE(meter.Evaluate(Pixels(0, 1000), SampleRequest{}, out).ok());
    std::vector<RGB> wrong(10);
    meter.SetPreviewVariance(&wrong);
    ASSERT_TRUE(meter.Evaluate(Pixels(0, 1000), SampleRequest{}, out).ok());
    EXPECT_EQ(meter.pixels(), 0);
  }
  {
    // A renderer that does not report its variance.
    NoisyProvider silent(f.truth, NoiseModel{0.1f, 0.01f, 3, false});
    ExactNoiseMeter meter(silent);
    meter.SetPreviewVariance(&own);
    ASSERT_TRUE(meter.Evaluate(Pixels(0, 1000), SampleRequest{}, out).ok());
    EXPECT_EQ(meter.pixels(), 0);
  }
  {
    // NaN samples stay out of the ratio.
    std::vector<RGB> nanOwn = own;
    for (int i = 0; i < 500; ++i) nanOwn[size_t(i)] = RGB::Gray(std::nanf(""));
    ExactNoiseMeter meter(f.noisy);
    meter.SetPreviewVariance(&nanOwn);
    ASSERT_TRUE(meter.Evaluate(Pixels(0, 1000), SampleRequest{}, out).ok());
    EXPECT_EQ(meter.pixels(), 500);
    EXPECT_NEAR(meter.share(), 1.0, 1e-6);
  }
}

}  // namespace
}  // namespace dcm::testing
