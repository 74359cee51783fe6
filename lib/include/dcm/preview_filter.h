// Preview filter: the noisy preview averaged over the neighbours of each
// interpolated pixel that the guides and the corrected image say show the
// same thing (a cross-bilateral filter), so that what the preview correction
// takes of the preview carries less of its noise.
#pragma once

#include <span>
#include <vector>

#include "dcm/reconstructor.h"
#include "dcm/sample_provider.h"
#include "dcm/status.h"

namespace dcm {

/// The filtered preview of each working pixel, and where asked for, the same
/// with the centre's pilot moved by + and - a shift (NaN: none).
struct FilteredPreview {
  std::vector<RGB> value, plus, minus;
};

/// Computes, for each interpolated working pixel i (SampleReason::kInterpolated)
/// of a W x H image, the mean of `preview` over the other pixels j of the
/// (2 radius + 1)^2 window around it (j = i left out, so that the result does
/// not depend on the preview's noise at i but through the pilot), weighted by
///   [same object ID][same shader ID] (where `guides` has them)
///   * exp(-|n_j - n_i|^2 / (2 0.2^2))     unit normals (where given, both or neither)
///   * exp(-|tau_j - tau_i|^2 / (2 0.05^2)) texture guide, summed over R, G, B
///   * exp(-|P_j - P_i|^2 / (2 0.05^2))     `pilot` sRGB-encoded, summed over R, G, B;
/// a neighbour whose preview or pilot is not finite has weight 0. Where the
/// samples carry L_i and L_c (`split`) and the guides tau, L_i and L_c are
/// averaged apart and the value is mean(L_i) tau_i + mean(L_c): texture stays
/// sharp. `out->value` receives, per working pixel, that value where the
/// neighbours weigh more than 1e-3 in all, else NaN (exact pixels and
/// stand-ins too). With `centreShift` (one per pixel; empty: none),
/// `out->plus` and `out->minus` are the same with P_i moved by + and - its
/// shift in all three channels at once: how the value moves with the
/// centre's pilot where the noise has one sign in R, G and B. `guides` covers
/// the whole image (region 0..W, 0..H) or is empty.
Status FilterPreview(std::span<const ExactSample> preview, bool split, const GuideImage& guides,
                     std::span<const RGB> pilot, std::span<const RGB> centreShift,
                     std::span<const SampleReason> sampleMap, int W, int H, int radius, FilteredPreview* out);

}  // namespace dcm
