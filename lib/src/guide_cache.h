// The guides a provider gave, kept per region and kind: a provider that wraps
// a slow renderer asks it for each once (round_schedule.cpp, quality_preview.cpp).
#pragma once

#include <tuple>
#include <vector>

#include "dcm/sample_provider.h"
#include "dcm/status.h"

namespace dcm {

class GuideCache {
 public:
  /// The guides of `region` and kind `what`: kept from an earlier call, else
  /// asked of `source` and kept when it gives them.
  Status Get(SampleProvider& source, const Bounds2i& region, const GuideRequest& what, GuideImage* out) {
    for (const auto& [r, w, image] : kept_)
      if (r == region && w.objectId == what.objectId && w.shaderId == what.shaderId && w.texture == what.texture &&
          w.normal == what.normal) {
        *out = image;
        return Status::Ok();
      }
    DCM_RETURN_IF_ERROR(source.Guides(region, what, out));
    kept_.push_back({region, what, *out});
    return Status::Ok();
  }

 private:
  std::vector<std::tuple<Bounds2i, GuideRequest, GuideImage>> kept_;
};

}  // namespace dcm
