// Stand-in samples from the preview and from exact neighbours.
#include "dcm/povray/povray_preview.h"

#include <algorithm>

#include "dcm/round_schedule.h"

namespace dcm::povray {

PovrayPreview::PovrayPreview(const PovrayProvider& exact, int previewWidth, int previewHeight, std::vector<RGB> Li,
                             std::vector<RGB> Lc, int radius)
    : exact_(exact),
      width_(exact.Capabilities().width),
      height_(exact.Capabilities().height),
      previewWidth_(previewWidth),
      previewHeight_(previewHeight),
      radius_(radius),
      Li_(std::move(Li)),
      Lc_(std::move(Lc)) {}

ProviderCapabilities PovrayPreview::Capabilities() const {
  ProviderCapabilities caps;
  caps.width = width_;
  caps.height = height_;
  caps.splitRadiance = true;
  caps.threadSafe = false;
  caps.name = "povray preview";
  return caps;
}

Status PovrayPreview::Guides(const Bounds2i&, const GuideRequest&, GuideImage*) {
  return Status::Error("a preview has no guides");
}

Status PovrayPreview::Evaluate(std::span<const Point2i> pixels, const SampleRequest& what,
                               std::span<ExactSample> out) {
  const size_t n = size_t(previewWidth_) * size_t(previewHeight_);
  if (previewWidth_ < 1 || previewHeight_ < 1 || Li_.size() != n || Lc_.size() != n)
    return Status::Error("povray preview: the preview image does not hold " + std::to_string(previewWidth_) + "x" +
                         std::to_string(previewHeight_) + " pixels");
  const auto& rendered = exact_.rendered();
  const auto& samples = exact_.samples();
  const auto& ids = exact_.objectIds();
  const auto& shaders = exact_.shaderIds();
  const auto& tau = exact_.texture();
  for (size_t k = 0; k < pixels.size(); ++k) {
    const Point2i p = pixels[k];
    const size_t i = size_t(p.y) * size_t(width_) + size_t(p.x);
    // The nearest exact sample on the same surface, if any.
    int best = -1, bestD = 1 << 30;
    for (int dy = -radius_; dy <= radius_; ++dy)
      for (int dx = -radius_; dx <= radius_; ++dx) {
        const int x = p.x + dx, y = p.y + dy, d = dx * dx + dy * dy;
        if (x < 0 || y < 0 || x >= width_ || y >= height_ || d >= bestD) continue;
        const size_t j = size_t(y) * size_t(width_) + size_t(x);
        if (rendered[j] && ids[j] == ids[i] && shaders[j] == shaders[i]) best = int(j), bestD = d;
      }
    ExactSample s;
    if (best >= 0) {
      s.Li = samples[size_t(best)].Li;
      s.Lc = samples[size_t(best)].Lc;
    } else {
      s.Li = UpsampleBilinear(Li_, previewWidth_, previewHeight_, width_, height_, p);
      s.Lc = UpsampleBilinear(Lc_, previewWidth_, previewHeight_, width_, height_, p);
    }
    s.L = s.Li * tau[i] + s.Lc;
    if (!what.split) s.Li = s.Lc = RGB{};
    out[k] = s;
  }
  return Status::Ok();
}

}  // namespace dcm::povray
