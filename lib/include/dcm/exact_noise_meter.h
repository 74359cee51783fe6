// How noisy the exact samples of a Monte Carlo renderer are, measured rather
// than assumed: a provider adapter that asks the renderer for one round's
// variance (two halves of the samples) and compares it with the preview's at
// the same pixels (PreviewScheduleOptions::measuredExactVarianceShare).
//
// Why: the preview's noise scaled by the ratio of samples assumes the error
// falls as 1 / samples; a stratified sampler's (Cycles') often falls faster,
// and on some scenes the scaled figure overstates the exact pixels' noise by
// 5 dB (docs/BLENDER.md, *Exact pixels with their variance*).
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "dcm/color.h"
#include "dcm/sample_provider.h"
#include "dcm/status.h"

namespace dcm {

/// Between an exact provider that can give its samples' variance and the
/// engine: the first Evaluate() of at least kMinPixels pixels asks for the
/// variance whether or not the caller did, and measures the exact samples'
/// variance as a share of the preview's own at the same pixels, each channel
/// weighted by the square of the display's slope at the exact value (the
/// share then scales display errors). The caller gets what it asked for: the
/// variance zeroed where it did not ask. Every other call passes through.
class ExactNoiseMeter final : public SampleProvider {
 public:
  /// Fewer pixels in a round: too few to measure a ratio of noises.
  static constexpr size_t kMinPixels = 256;

  explicit ExactNoiseMeter(SampleProvider& exact) : exact_(exact) {}

  /// The preview's own variance per pixel of the image (row-major), kept by
  /// pointer: set it before the rounds. Unset, empty or of another size:
  /// nothing is measured.
  void SetPreviewVariance(const std::vector<RGB>* own) { own_ = own; }
  /// Once the share is measured, a call that asks for the variance takes it
  /// from the preview instead: the preview's own at that pixel times the
  /// share, and the renderer renders without halves (one render call per round
  /// instead of two). The exact variance of a pixel from its own halves has one
  /// degree of freedom, as the preview's: per pixel neither is less noisy. But
  /// the share, measured on one round's pixels, is biased for others: a judge
  /// that weighs each pixel's own variance (validation pixels) needs halves.
  void SetVarianceFromPreview(bool on) { fromPreview_ = on; }
  /// The measured share; NaN until a round measured it.
  double share() const { return share_; }
  /// The pixels it was measured on (0: not measured).
  int64_t pixels() const { return pixels_; }

  ProviderCapabilities Capabilities() const override { return exact_.Capabilities(); }
  Status Guides(const Bounds2i& region, const GuideRequest& what, GuideImage* out) override {
    return exact_.Guides(region, what, out);
  }
  Status Evaluate(std::span<const Point2i> pixels, const SampleRequest& what, std::span<ExactSample> out) override;
  /// The exact provider's extra pixels, as the last Evaluate()'s caller asked for them.
  void TakeExtraSamples(std::vector<Point2i>* pixels, std::vector<ExactSample>* samples) override;

 private:
  /// out[i].variance = the preview's own at pixels[i] times the share (NaN outside the image).
  void ScaledPreviewVariance(std::span<const Point2i> pixels, std::span<ExactSample> out) const;

  SampleProvider& exact_;
  bool zeroExtraVariance_ = false;  ///< the last call asked for the variance its caller did not
  bool scaledExtraVariance_ = false;  ///< the last call took the variance from the preview
  bool fromPreview_ = false;
  const std::vector<RGB>* own_ = nullptr;
  double share_ = std::numeric_limits<double>::quiet_NaN();
  int64_t pixels_ = 0;
};

}  // namespace dcm
