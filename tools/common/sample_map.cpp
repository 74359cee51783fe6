// The sample map (the paper's index image) and the error heat map.
#include "sample_map.h"

#include <algorithm>
#include <cmath>

#include "image_io.h"
#include "metrics.h"

namespace dcm::toolkit {

std::array<uint8_t, 3> ReasonColor(SampleReason reason) {
  switch (reason) {
    case SampleReason::kInterpolated: return {40, 40, 40};      // dark gray
    case SampleReason::kCorner: return {255, 255, 255};         // white
    case SampleReason::kBorder: return {0, 190, 255};           // cyan-blue
    case SampleReason::kFirstOrderProbe: return {255, 0, 255};  // magenta
    case SampleReason::kLazyCentre: return {0, 220, 0};         // green
    case SampleReason::kCentreProbe: return {255, 255, 0};      // yellow
    case SampleReason::kThinObject: return {255, 40, 40};       // red
    case SampleReason::kFallback: return {255, 170, 0};         // orange
    case SampleReason::kFull: return {150, 150, 255};           // lavender
    case SampleReason::kCount: break;
  }
  return {128, 64, 0};  // brown: an unknown reason (never expected)
}

std::vector<uint8_t> SampleMapImage(const Reconstruction& r) {
  const size_t n = size_t(std::max(r.workWidth, 0)) * size_t(std::max(r.workHeight, 0));
  std::vector<uint8_t> rgb(n * 3);
  for (size_t i = 0; i < n; ++i) {
    const SampleReason reason = i < r.sampleMap.size() ? r.sampleMap[i] : SampleReason::kInterpolated;
    const auto c = ReasonColor(reason);
    std::copy(c.begin(), c.end(), rgb.begin() + std::ptrdiff_t(i * 3));
  }
  return rgb;
}

Status WriteSampleMap(const std::string& path, const Reconstruction& r) {
  if (r.sampleMap.size() != size_t(r.workWidth) * size_t(r.workHeight))
    return Status::Error("cannot write sample map '" + path + "': the reconstruction has no sample map");
  const auto rgb = SampleMapImage(r);
  return WriteRgb8(path, r.workWidth, r.workHeight, rgb);
}

namespace {

/// A perceptually ordered ramp black -> blue -> red -> yellow -> white for t in [0,1].
std::array<uint8_t, 3> HeatColor(float t) {
  static constexpr float kStops[5][3] = {
      {0, 0, 0}, {30, 40, 200}, {220, 30, 40}, {255, 220, 0}, {255, 255, 255}};
  t = std::clamp(t, 0.f, 1.f) * 4.f;
  const int i = std::min(3, int(t));
  const float f = t - float(i);
  std::array<uint8_t, 3> c{};
  for (int k = 0; k < 3; ++k)
    c[size_t(k)] = uint8_t(std::lround(kStops[i][k] + f * (kStops[i + 1][k] - kStops[i][k])));
  return c;
}

}  // namespace

Status WriteErrorMap(const std::string& path, std::span<const RGB> image,
                     std::span<const RGB> reference, int width, int height) {
  const size_t n = size_t(std::max(width, 0)) * size_t(std::max(height, 0));
  if (n == 0 || image.size() != n || reference.size() != n)
    return Status::Error("cannot write error map '" + path + "': image and reference differ in size");
  std::vector<uint8_t> rgb(n * 3);
  for (size_t i = 0; i < n; ++i) {
    std::array<uint8_t, 3> c;
    if (!IsFinite(image[i]) || !IsFinite(reference[i])) {
      c = {0, 255, 0};  // green marks non-finite pixels (not on the ramp)
    } else {
      const float d = std::fabs(SrgbEncode(Luminance(image[i])) - SrgbEncode(Luminance(reference[i])));
      c = HeatColor(d / kErrorMapFullScale);
    }
    std::copy(c.begin(), c.end(), rgb.begin() + std::ptrdiff_t(i * 3));
  }
  return WriteRgb8(path, width, height, rgb);
}

}  // namespace dcm::toolkit
