// Preview correction: where the reconstruction's interpolation departs from a
// dense, unbiased but noisy preview by more than the preview's noise explains,
// the interpolated pixels move toward the preview by that share (a local
// Wiener shrinkage). The preview a preview-planned run already paid for then
// also repairs what interpolation missed: texture, thin detail, soft shading.
#pragma once

#include <cstdint>

#include "dcm/reconstructor.h"
#include "dcm/sample_provider.h"
#include "dcm/status.h"

namespace dcm {

/// What a preview correction did.
struct PreviewCorrectionStats {
  int64_t pixels = 0;       ///< interpolated working pixels that moved (weight > 0 in a channel)
  double meanWeight = 0;    ///< mean weight over the interpolated pixels and channels, in [0, 1]
};

/// Corrects the interpolated pixels (SampleReason::kInterpolated) of `rec`
/// toward `preview`, which must give every working pixel's L and the variance
/// of that L. Per channel, with d = preview - reconstruction and v the
/// preview's variance, averaged over the (2 radius + 1)^2 window around the
/// pixel: b = max(mean d^2 - mean v, 0) is the squared bias the noise does not
/// explain, and the pixel moves by b / (b + mean v) of its d where b stands
/// out of the chance fluctuation of that difference. Exact pixels and
/// preview stand-ins keep their values; a pixel whose preview or variance is
/// not finite neither counts in a window nor moves. `rec->image` is made again
/// from the corrected working image, downsampled by `downsample` (the
/// reconstruction's ReconstructionOptions::downsample). radius 0: nothing changes.
Status CorrectTowardPreview(SampleProvider& preview, int radius, int downsample, Reconstruction* rec,
                            PreviewCorrectionStats* stats = nullptr);

}  // namespace dcm
