#include "noisy_provider.h"

#include <cmath>
#include <cstdint>

namespace dcm::testing {

namespace {

uint32_t Hash(uint32_t v) {
  v ^= v >> 16;
  v *= 0x7feb352du;
  v ^= v >> 15;
  v *= 0x846ca68bu;
  v ^= v >> 16;
  return v;
}

/// A standard normal deviate fixed by (x, y, seed) (Box-Muller).
float Gaussian(int x, int y, uint32_t seed) {
  const uint32_t h1 = Hash(uint32_t(x) * 0x9e3779b1u ^ Hash(uint32_t(y) ^ Hash(seed)));
  const uint32_t h2 = Hash(h1 ^ 0x85ebca6bu);
  const double u1 = (double(h1 >> 8) + 0.5) * 0x1p-24, u2 = double(h2 >> 8) * 0x1p-24;
  return float(std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2));
}

}  // namespace

ProviderCapabilities NoisyProvider::Capabilities() const {
  ProviderCapabilities c = exact_.Capabilities();
  c.variance = model_.reportVariance;
  c.name = "noisy-analytic";
  return c;
}

ExactSample NoisyProvider::Sample(int x, int y) const {
  const PixelTruth t = exact_.Truth(x, y);
  const float n = Gaussian(x, y, model_.seed);
  ExactSample s;
  const RGB L = t.L();
  for (int c = 0; c < 3; ++c) {
    const float sd = model_.relative * std::fabs(L[c]) + model_.absolute;
    // The same relative error on L_i and L_c keeps L = L_i tau + L_c.
    const float scale = L[c] != 0.f ? 1.f + n * sd / L[c] : 1.f;
    s.L[c] = L[c] != 0.f ? L[c] * scale : n * sd;
    s.Li[c] = t.Li[c] * scale;
    s.Lc[c] = L[c] != 0.f ? t.Lc[c] * scale : n * sd;
    s.variance[c] = sd * sd;
  }
  return s;
}

Status NoisyProvider::Evaluate(std::span<const Point2i> pixels, const SampleRequest& what,
                               std::span<ExactSample> out) {
  // Counts the evaluations in the wrapped provider.
  DCM_RETURN_IF_ERROR(exact_.Evaluate(pixels, what, out));
  for (size_t k = 0; k < pixels.size(); ++k) {
    ExactSample s = Sample(pixels[k].x, pixels[k].y);
    if (!what.split) s.Li = s.Lc = RGB{};
    if (!what.variance) s.variance = RGB{};
    out[k] = s;
  }
  return Status::Ok();
}

std::vector<RGB> NoisyProvider::NoisyFullRender() const {
  const ProviderCapabilities c = exact_.Capabilities();
  std::vector<RGB> img(size_t(c.width) * size_t(c.height));
  for (int y = 0; y < c.height; ++y)
    for (int x = 0; x < c.width; ++x) img[size_t(y) * size_t(c.width) + size_t(x)] = Sample(x, y).L;
  return img;
}

}  // namespace dcm::testing
