// A Monte Carlo renderer in miniature: the exact samples of an analytic scene
// with Gaussian noise of a known, reported standard deviation. Ground truth is
// the noise-free scene; the noisy full render is what a path tracer delivers.
#pragma once

#include "analytic_provider.h"

namespace dcm::testing {

/// Noise of one pixel's estimate: sd = relative * L + absolute (per channel),
/// one standard normal deviate per pixel shared by the channels and by L_i,
/// L_c (so L = L_i * tau + L_c holds for the noisy sample too).
struct NoiseModel {
  float relative = 0.1f;
  float absolute = 0.01f;
  uint32_t seed = 1;
  bool reportVariance = true;  ///< false: a renderer that does not say how noisy it is
};

/// Wraps an AnalyticProvider; Evaluate() adds the noise of `model`, and
/// reports its variance when the engine asks and the model allows.
class NoisyProvider : public SampleProvider {
 public:
  NoisyProvider(AnalyticProvider& exact, NoiseModel model) : exact_(exact), model_(model) {}
  ProviderCapabilities Capabilities() const override;
  Status Guides(const Bounds2i& region, const GuideRequest& what, GuideImage* out) override {
    return exact_.Guides(region, what, out);
  }
  Status Evaluate(std::span<const Point2i> pixels, const SampleRequest& what,
                  std::span<ExactSample> out) override;
  /// Every pixel with its noise: the full noisy render.
  std::vector<RGB> NoisyFullRender() const;

 private:
  /// The noisy sample of pixel (x, y) and its variance.
  ExactSample Sample(int x, int y) const;
  AnalyticProvider& exact_;
  NoiseModel model_;
};

}  // namespace dcm::testing
