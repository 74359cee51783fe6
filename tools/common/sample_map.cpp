// The sample map (the paper's index image) and the error heat map.
#include "sample_map.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "image_io.h"
#include "metrics.h"

namespace dcm::toolkit {
namespace {

using OIIO::ImageBuf;
using OIIO::ROI;

constexpr int kFontSize = 12;  ///< pixels; a legend row is kRow high
constexpr int kRow = 16;
constexpr int kMargin = 4;

std::array<float, 3> Float(std::array<uint8_t, 3> c) { return {c[0] / 255.f, c[1] / 255.f, c[2] / 255.f}; }

/// A picture of width x height with a legend strip of `strip` pixels below,
/// at least `minWidth` wide, black; `rgb` (8-bit) drawn at its top left.
ImageBuf Canvas(int width, int height, std::span<const uint8_t> rgb, int strip, int minWidth) {
  ImageBuf canvas(OIIO::ImageSpec(std::max(width, minWidth), height + strip, 3, OIIO::TypeDesc::FLOAT));
  OIIO::ImageBufAlgo::zero(canvas);
  ImageBuf image(OIIO::ImageSpec(width, height, 3, OIIO::TypeDesc::UINT8), const_cast<uint8_t*>(rgb.data()));
  OIIO::ImageBufAlgo::paste(canvas, 0, 0, 0, 0, image);
  return canvas;
}

void Box(ImageBuf& canvas, int x0, int y0, int x1, int y1, std::array<float, 3> c) {
  OIIO::ImageBufAlgo::fill(canvas, c, ROI(x0, x1, y0, y1, 0, 1, 0, 3));
}

/// Draws `text` with its baseline at y, left-aligned at x (right-aligned
/// with `right`).
Status Text(ImageBuf& canvas, int x, int y, const std::string& text, bool right = false) {
  const float grey[3] = {0.9f, 0.9f, 0.9f};
  if (!OIIO::ImageBufAlgo::render_text(canvas, x, y, text, kFontSize, kLegendFont, grey,
                                       right ? OIIO::ImageBufAlgo::TextAlignX::Right
                                             : OIIO::ImageBufAlgo::TextAlignX::Left))
    return Status::Error(std::string("cannot draw the legend's text with the font ") + kLegendFont +
                         " (Debian package fonts-dejavu-core): " + canvas.geterror());
  return Status::Ok();
}

/// Writes the canvas as an 8-bit PNG whose description says where the
/// picture is, atomically.
Status WriteCanvas(const std::string& path, const ImageBuf& canvas, int width, int height, const std::string& what) {
  OIIO::ImageSpec spec(canvas.spec().width, canvas.spec().height, 3, OIIO::TypeDesc::UINT8);
  spec.attribute("ImageDescription", what + ": the image is the top left " + std::to_string(width) + "x" +
                                         std::to_string(height) + " pixels, the legend below it");
  std::vector<uint8_t> rgb(size_t(spec.width) * size_t(spec.height) * 3);
  if (!canvas.get_pixels(canvas.roi(), OIIO::TypeDesc::UINT8, rgb.data()))
    return Status::Error("cannot write '" + path + "': " + canvas.geterror());
  return WriteImage(path, spec, rgb.data(), OIIO::TypeDesc::UINT8);
}

std::string Fixed(double v, int digits) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

}  // namespace

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
    case SampleReason::kPreviewStandIn: return {120, 80, 160};  // dull purple
    case SampleReason::kRendered: return {140, 200, 170};       // sage
    case SampleReason::kValidation: return {255, 130, 190};     // pink
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
  if (r.sampleMap.empty() || r.sampleMap.size() != size_t(r.workWidth) * size_t(r.workHeight))
    return Status::Error("cannot write sample map '" + path + "': the reconstruction has no sample map");
  const auto rgb = SampleMapImage(r);
  std::array<int64_t, kSampleReasonCount> count{};
  for (SampleReason reason : r.sampleMap) ++count[std::min(size_t(reason), count.size() - 1)];
  // The legend: one entry per reason (swatch, name, share of the pixels),
  // as many columns as fit.
  const int columns = std::max(1, std::max(r.workWidth, kLegendEntryWidth) / kLegendEntryWidth);
  const int rows = (kSampleReasonCount + columns - 1) / columns;
  ImageBuf canvas = Canvas(r.workWidth, r.workHeight, rgb, 2 * kMargin + rows * kRow, kLegendEntryWidth);
  for (int i = 0; i < kSampleReasonCount; ++i) {
    const auto reason = SampleReason(i);
    const int x = (i % columns) * kLegendEntryWidth + kMargin, y = r.workHeight + kMargin + (i / columns) * kRow;
    Box(canvas, x, y + 2, x + 12, y + 14, {0.5f, 0.5f, 0.5f});  // a frame: dark swatches show on black
    Box(canvas, x + 1, y + 3, x + 11, y + 13, Float(ReasonColor(reason)));
    const double share = 100.0 * double(count[size_t(i)]) / double(r.sampleMap.size());
    DCM_RETURN_IF_ERROR(Text(canvas, x + 16, y + 12, std::string(ToString(reason)) + " " + Fixed(share, 2) + "%"));
  }
  return WriteCanvas(path, canvas, r.workWidth, r.workHeight, "dcm sample map");
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
  float largest = 0.f;
  int64_t nonFinite = 0;
  for (size_t i = 0; i < n; ++i) {
    std::array<uint8_t, 3> c;
    if (!IsFinite(image[i]) || !IsFinite(reference[i])) {
      c = kNonFiniteColor;
      ++nonFinite;
    } else {
      const float d = std::fabs(SrgbEncode(Luminance(image[i])) - SrgbEncode(Luminance(reference[i])));
      largest = std::max(largest, d);
      c = HeatColor(d / kErrorMapFullScale);
    }
    std::copy(c.begin(), c.end(), rgb.begin() + std::ptrdiff_t(i * 3));
  }
  // The colour bar: the ramp from 0 to full scale, its ends and middle
  // labelled, then what is measured and the largest error of this image.
  ImageBuf canvas = Canvas(width, height, rgb, 2 * kMargin + 12 + 3 * kRow, kErrorMapMinWidth);
  const int w = canvas.spec().width, x0 = kMargin, x1 = w - kMargin, y = height + kMargin;
  for (int x = x0; x < x1; ++x)
    Box(canvas, x, y, x + 1, y + 12, Float(HeatColor(float(x - x0) / float(std::max(1, x1 - x0 - 1)))));
  const int baseline = y + 12 + kRow - 3;
  DCM_RETURN_IF_ERROR(Text(canvas, x0, baseline, "0"));
  const std::string full = Fixed(kErrorMapFullScale, 2);
  DCM_RETURN_IF_ERROR(Text(canvas, (x0 + x1) / 2 - 12, baseline, Fixed(kErrorMapFullScale / 2, 3)));
  DCM_RETURN_IF_ERROR(Text(canvas, x1, baseline, ">= " + full, /*right=*/true));
  DCM_RETURN_IF_ERROR(Text(canvas, x0, baseline + kRow, "|sRGB(Y) - sRGB(Y ref)|, display 0-1"));
  std::string last = "max " + Fixed(largest, 4);
  if (nonFinite) last += ", green: " + std::to_string(nonFinite) + " NaN/Inf";
  DCM_RETURN_IF_ERROR(Text(canvas, x0, baseline + 2 * kRow, last));
  return WriteCanvas(path, canvas, width, height, "dcm error map");
}

}  // namespace dcm::toolkit
