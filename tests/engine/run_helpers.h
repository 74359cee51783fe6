// Small helpers shared by the engine tests.
#pragma once

#include <gtest/gtest.h>

#include <utility>
#include <vector>

#include "analytic_provider.h"
#include "dcm/reconstructor.h"
#include "dcm/round_schedule.h"

namespace dcm::testing {

/// Reconstructs and fails the test on an error.
inline Reconstruction ReconstructOrFail(SampleProvider& provider, const ReconstructionOptions& options) {
  Reconstruction r;
  const Status s = Reconstruct(provider, options, &r);
  EXPECT_TRUE(s.ok()) << s.message();
  return r;
}

/// Mean absolute luminance error over the pixels selected by `where`.
template <typename Pred>
double MeanLuminanceError(const Reconstruction& r, const std::vector<RGB>& ref, Pred where) {
  double sum = 0;
  int n = 0;
  for (int y = 0; y < r.workHeight; ++y)
    for (int x = 0; x < r.workWidth; ++x)
      if (where(x, y)) {
        const size_t i = size_t(y) * size_t(r.workWidth) + size_t(x);
        sum += std::fabs(Luminance(r.workImage[i]) - Luminance(ref[i]));
        ++n;
      }
  return n ? sum / n : 0;
}

/// The provider's L, L_i and L_c box-filtered to 1/`factor` of its resolution:
/// a preview a renderer would make at low resolution.
inline ImagePreviewProvider LowResolutionPreview(const AnalyticProvider& p, int w, int h, int factor) {
  const int pw = w / factor, ph = h / factor;
  std::vector<RGB> L(size_t(pw) * ph), Li(L.size()), Lc(L.size());
  const float weight = 1.f / float(factor * factor);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const PixelTruth t = p.Truth(x, y);
      const size_t k = size_t(y / factor) * pw + size_t(x / factor);
      L[k] += t.L() * weight;
      Li[k] += t.Li * weight;
      Lc[k] += t.Lc * weight;
    }
  return ImagePreviewProvider(w, h, pw, ph, L, Li, Lc);
}

/// Offers, after every Evaluate(), the pixels right of those asked for as extra
/// samples (TakeExtraSamples), with the values of `extraValues`: a renderer whose
/// round renders some pixels besides (Cycles with a wide pixel filter).
class ExtraRightProvider : public SampleProvider {
 public:
  ExtraRightProvider(SampleProvider& inner, SampleProvider& extraValues) : inner_(inner), values_(extraValues) {}
  ProviderCapabilities Capabilities() const override { return inner_.Capabilities(); }
  Status Guides(const Bounds2i& r, const GuideRequest& w, GuideImage* out) override { return inner_.Guides(r, w, out); }
  Status Evaluate(std::span<const Point2i> p, const SampleRequest& w, std::span<ExactSample> out) override {
    asked.emplace_back(p.begin(), p.end());
    DCM_RETURN_IF_ERROR(inner_.Evaluate(p, w, out));
    extra_.clear();
    for (const Point2i& q : p)
      if (q.x + 1 < inner_.Capabilities().width) extra_.push_back({q.x + 1, q.y});
    extraSamples_.resize(extra_.size());
    offered.push_back(extra_);
    return values_.Evaluate(extra_, w, extraSamples_);
  }
  void TakeExtraSamples(std::vector<Point2i>* pixels, std::vector<ExactSample>* samples) override {
    *pixels = std::exchange(extra_, {});
    *samples = std::exchange(extraSamples_, {});
  }
  std::vector<std::vector<Point2i>> asked, offered;  ///< per call

 private:
  SampleProvider& inner_;
  SampleProvider& values_;
  std::vector<Point2i> extra_;
  std::vector<ExactSample> extraSamples_;
};

}  // namespace dcm::testing
