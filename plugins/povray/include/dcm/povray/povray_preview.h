// The stand-in samples of a POV-Ray render planned on a preview
// (RoundSchedule::kPreview): the illumination of a low-resolution render, or of
// an exact sample next to the pixel on the same surface, times the pixel's own
// texture.
#pragma once

#include <vector>

#include "dcm/povray/povray_provider.h"
#include "dcm/sample_provider.h"

namespace dcm::povray {

/// A preview provider over a PovrayProvider whose guides are rendered.
/// A pixel's stand-in is L = L_i*tau + L_c with tau the pixel's own (from the
/// guides, so textures are sharp) and L_i, L_c from the nearest pixel within
/// `radius` that the provider rendered exactly and that shows the same object
/// and shader, else bilinear from the preview image. Pixels rendered exactly
/// meanwhile improve later stand-ins: the last round's leftovers (kept at
/// their preview value by the schedule) take their neighbours' light.
class PovrayPreview final : public SampleProvider {
 public:
  /// `Li`, `Lc`: the preview at `previewWidth` x `previewHeight`. `radius`
  /// below 0: the preview alone, whatever was rendered (the quality search
  /// needs stand-ins that do not take a validation pixel's own exact value).
  PovrayPreview(const PovrayProvider& exact, int previewWidth, int previewHeight, std::vector<RGB> Li,
                std::vector<RGB> Lc, int radius = 2);
  ProviderCapabilities Capabilities() const override;
  /// A preview has no guides (the schedule asks the exact provider).
  Status Guides(const Bounds2i& region, const GuideRequest& what, GuideImage* out) override;
  Status Evaluate(std::span<const Point2i> pixels, const SampleRequest& what,
                  std::span<ExactSample> out) override;

 private:
  const PovrayProvider& exact_;
  int width_, height_, previewWidth_, previewHeight_, radius_;
  std::vector<RGB> Li_, Lc_;
};

}  // namespace dcm::povray
