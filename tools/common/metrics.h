// Error of an image against a reference.
#pragma once

#include <span>
#include <vector>

#include "dcm/color.h"

namespace dcm::toolkit {

/// Error of an image against a reference.
struct ImageError {
  double psnr = 0;    ///< dB, on sRGB-encoded values clipped to [0,1] (display-referred)
  double rmse = 0;    ///< linear values
  double relmse = 0;  ///< mean of (x-ref)^2 / (ref^2 + 0.01), per channel
  double ssim = 0;    ///< mean SSIM of sRGB-encoded luminance, 8x8 windows
  long nonFinite = 0; ///< pixels of `image` with NaN/Inf (excluded from the means)
};

/// Compares `image` with `reference` (same size, row-major). Pixels where
/// either image is not finite are left out of PSNR, RMSE and relMSE (and count
/// as black in SSIM). PSNR is +infinity for identical images; all fields are
/// NaN when nothing can be compared (empty or too short spans).
ImageError Compare(std::span<const RGB> image, std::span<const RGB> reference, int width, int height);

/// sRGB encoding of a linear value clipped to [0,1]: the engine's.
using dcm::SrgbEncode;

}  // namespace dcm::toolkit
