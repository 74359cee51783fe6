// Preview correction: where the reconstruction's interpolation departs from a
// dense, unbiased but noisy preview by more than the preview's noise explains,
// the interpolated pixels move toward the preview by that share (a local
// Wiener shrinkage). The preview a preview-planned run already paid for then
// also repairs what interpolation missed: texture, thin detail, soft shading.
#pragma once

#include <cstdint>
#include <limits>
#include <span>

#include "dcm/quality_target.h"
#include "dcm/reconstructor.h"
#include "dcm/sample_provider.h"
#include "dcm/status.h"

namespace dcm {

/// Below this display-referred PSNR of the preview's own noise, its estimate
/// of the result's error is not made: through the encoding's curve and clip,
/// so noisy a preview errs on the side of error by several dB (chosen on the
/// tuning set, docs/TUNING.md).
inline constexpr double kMinPreviewPsnrForEstimate = 25;

/// What a preview correction did.
struct PreviewCorrectionStats {
  int64_t pixels = 0;       ///< interpolated working pixels that moved (weight > 0 in a channel, or filtered)
  int64_t filtered = 0;     ///< interpolated working pixels that took half their filtered preview
  double meanWeight = 0;    ///< mean weight over the interpolated pixels and channels, in [0, 1]
  /// The corrected image's display-referred PSNR (sRGB, clipped, as the
  /// stats' PSNR) against the converged image, estimated from the preview at
  /// every pixel; NaN where not made (downsample > 1, no pixel to estimate,
  /// or a preview whose own noise costs more than 25 dB: there the
  /// display's curve and clip bias the estimate low by several dB). The
  /// preview p is taken as the mean of two halves with independent noise,
  /// whose encodings are A and B: where the encoding X of an interpolated
  /// value does not depend on p's noise, E[(X - A)(X - B)] is X's squared
  /// error; a corrected pixel x + k (p - x) has (1 - k)^2 times that plus
  /// k^2 the preview's display variance (k taken as fixed). An exact pixel
  /// counts its own noise, `exactShare` times the preview's variance through
  /// the display at its value; a preview stand-in the preview's display
  /// variance. The interval is that of independent pixels.
  PsnrEstimate estimate{std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(),
                        std::numeric_limits<double>::quiet_NaN()};
  /// The preview's own display-referred PSNR against the converged image,
  /// from its variance (NaN with downsample > 1).
  double previewPsnr = std::numeric_limits<double>::quiet_NaN();
  /// The full render's own display-referred PSNR against the converged
  /// image: every pixel at `exactShare` of the preview's variance, through
  /// the display at its value in the result (NaN where the estimate is not
  /// made or `exactShare` is 0).
  double renderPsnr = std::numeric_limits<double>::quiet_NaN();
};

/// The display-referred PSNR of `preview`'s own noise against the converged
/// image (PreviewCorrectionStats::previewPsnr) before any correction, from
/// `ownVariance` (empty: the preview's variance); NaN where the preview has
/// no variance or cannot be read.
double PreviewNoisePsnr(SampleProvider& preview, std::span<const RGB> ownVariance = {});

/// Corrects the interpolated pixels (SampleReason::kInterpolated) of `rec`
/// toward `preview`, which must give every working pixel's L and the variance
/// of that L. Per channel, with d = preview - reconstruction and v the
/// preview's variance, averaged over the (2 radius + 1)^2 window around the
/// pixel: b = max(mean d^2 - mean v, 0) is the squared bias the noise does not
/// explain, and the pixel moves by b / (b + mean v) of its d where b stands
/// out of the chance fluctuation of that difference. Where `ownVariance` is
/// given (the preview's variance measured on its halves), each pixel then
/// takes, of none, that share and all of its d, the one whose cross-fit error
/// between the halves is least over a 7 x 7 window. Exact pixels and
/// preview stand-ins keep their values; a pixel whose preview or variance is
/// not finite neither counts in a window nor moves. `rec->image` is made again
/// from the corrected working image, downsampled by `downsample` (the
/// reconstruction's ReconstructionOptions::downsample). radius 0: nothing changes.
/// `ownVariance` (empty, or one per working pixel): each pixel's own variance
/// of the preview, from two halves of its samples, for the estimate; empty:
/// the preview's. `exactShare`: the exact samples' variance as a share of the
/// preview's (PreviewScheduleOptions::exactVarianceShare).
/// `textureCovariance` (empty, or one per working pixel): where `rec` used the
/// texture split with the preview's own texture guide, each channel's
/// covariance of the preview's estimates of tau and of L
/// (PreviewScheduleOptions::previewTextureCovariance); the estimate takes
/// out what the interpolation shares with the preview's noise through tau.
/// `filterRadius` > 0: each interpolated pixel that FilterPreview() gives a
/// value (over that radius, with `guides` of the whole working image or
/// none, the corrected image as pilot) ends as the mean of its corrected
/// value and that one. The filter leaves the pixel's own preview out; what it
/// takes of it through the pilot, the estimate counts (the value made with
/// the pilot's centre moved by +- the preview's sd, in R, G and B at once).
/// `excess` (where the estimate is made): per working pixel, how far the
/// interpolated pixel's estimated squared display error exceeds what it
/// would carry rendered (`exactShare` of the preview's variance), in units of
/// the preview's display variance there, the noise of that estimate; NaN
/// where the pixel is not interpolated or has no estimate.
/// `exactPooled`: the exact pixels will be pooled with their preview afterwards
/// (PoolExactWithPreview): the estimate and `excess` count an exact pixel's
/// noise at PreviewPoolWeight(exactShare) of the preview's variance.
Status CorrectTowardPreview(SampleProvider& preview, int radius, int downsample, Reconstruction* rec,
                            PreviewCorrectionStats* stats = nullptr, std::span<const RGB> ownVariance = {},
                            double exactShare = 0, std::span<const RGB> textureCovariance = {},
                            int filterRadius = 0, const GuideImage& guides = {},
                            std::vector<float>* excess = nullptr, bool exactPooled = false);

}  // namespace dcm
