// The index image of the paper (Figures 4, 5): which pixels were exact and why.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "dcm/reconstructor.h"

namespace dcm::toolkit {

/// sRGB colour of each reason (interpolated pixels are drawn dark gray):
/// corner white, border cyan-blue, first-order probe magenta, lazy centre
/// green, centre probe yellow, thin object red, fallback orange, full evaluation lavender.
std::array<uint8_t, 3> ReasonColor(SampleReason reason);

/// The sample map as 8-bit RGB (row-major, 3 bytes a pixel) at the working
/// resolution.
std::vector<uint8_t> SampleMapImage(const Reconstruction& r);

/// Writes the sample map (PNG) atomically.
Status WriteSampleMap(const std::string& path, const Reconstruction& r);

/// Difference of sRGB-encoded luminance that the error map draws at full scale
/// (white): 0.1, a tenth of the display range; smaller errors go through
/// black, blue, red, yellow.
inline constexpr float kErrorMapFullScale = 0.1f;

/// Writes a heat map of |image - reference| (luminance, display units) as PNG,
/// atomically. Non-finite pixels are drawn green.
Status WriteErrorMap(const std::string& path, std::span<const RGB> image,
                     std::span<const RGB> reference, int width, int height);

}  // namespace dcm::toolkit
