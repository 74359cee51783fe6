// The exact samples' noise as a share of the preview's, measured on a round.
#include "dcm/exact_noise_meter.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dcm {

namespace {

/// d(SrgbEncode)/dx at x: the linear segment's 12.92 at and below 0.
double SrgbSlope(float x) {
  return x > 0.f ? double(SrgbRelativeSlope(x)) / double(std::min(x, 1.f)) : 12.92;
}

}  // namespace

Status ExactNoiseMeter::Evaluate(std::span<const Point2i> pixels, const SampleRequest& what,
                                 std::span<ExactSample> out) {
  const ProviderCapabilities caps = exact_.Capabilities();
  const size_t n = size_t(std::max(caps.width, 0)) * size_t(std::max(caps.height, 0));
  const bool haveOwn = own_ && own_->size() == n && n > 0;
  const bool measure = pixels_ == 0 && caps.variance && haveOwn && pixels.size() >= kMinPixels;
  zeroExtraVariance_ = measure && !what.variance;
  scaledExtraVariance_ = pixels_ > 0 && haveOwn && fromPreview_ && what.variance;
  if (scaledExtraVariance_) {
    SampleRequest once = what;
    once.variance = false;
    DCM_RETURN_IF_ERROR(exact_.Evaluate(pixels, once, out));
    ScaledPreviewVariance(pixels, out);
    return Status::Ok();
  }
  if (!measure) return exact_.Evaluate(pixels, what, out);
  SampleRequest halves = what;
  halves.variance = true;
  DCM_RETURN_IF_ERROR(exact_.Evaluate(pixels, halves, out));
  double exact = 0, preview = 0;
  int64_t used = 0;
  for (size_t i = 0; i < pixels.size(); ++i) {
    const Point2i& p = pixels[i];
    if (p.x < 0 || p.y < 0 || p.x >= caps.width || p.y >= caps.height) continue;
    const RGB& v = out[i].variance;
    const RGB& o = (*own_)[size_t(p.y) * size_t(caps.width) + size_t(p.x)];
    // A NaN or infinite sample stays out of the ratio, as out of its pixel's neighbours.
    if (!IsFinite(out[i].L) || !IsFinite(v) || !IsFinite(o)) continue;
    ++used;
    for (int c = 0; c < 3; ++c) {
      const double slope = SrgbSlope(out[i].L[c]);
      const double w = slope * slope;
      exact += w * std::max(double(v[c]), 0.0);
      preview += w * std::max(double(o[c]), 0.0);
    }
  }
  if (used >= int64_t(kMinPixels) && preview > 0 && std::isfinite(exact / preview)) {
    share_ = exact / preview;
    pixels_ = used;
  }
  if (!what.variance)
    for (ExactSample& s : out) s.variance = RGB{};
  return Status::Ok();
}

void ExactNoiseMeter::TakeExtraSamples(std::vector<Point2i>* pixels, std::vector<ExactSample>* samples) {
  exact_.TakeExtraSamples(pixels, samples);
  if (zeroExtraVariance_)
    for (ExactSample& s : *samples) s.variance = RGB{};
  if (scaledExtraVariance_) ScaledPreviewVariance(*pixels, *samples);
}

void ExactNoiseMeter::ScaledPreviewVariance(std::span<const Point2i> pixels, std::span<ExactSample> out) const {
  const ProviderCapabilities caps = exact_.Capabilities();
  const float share = float(share_);
  for (size_t i = 0; i < pixels.size() && i < out.size(); ++i) {
    const Point2i& p = pixels[i];
    const bool inside = p.x >= 0 && p.y >= 0 && p.x < caps.width && p.y < caps.height;
    out[i].variance = inside ? (*own_)[size_t(p.y) * size_t(caps.width) + size_t(p.x)] * share
                             : RGB::Gray(std::numeric_limits<float>::quiet_NaN());
  }
}

}  // namespace dcm
