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

/// The font of the legends: DejaVu Sans (Debian package fonts-dejavu-core),
/// found by OpenImageIO's text rendering (FreeType) in the system's fonts.
inline constexpr const char* kLegendFont = "DejaVuSans";
/// Width of one legend entry of the sample map (swatch, reason, share), and
/// so the least width of the PNG.
inline constexpr int kLegendEntryWidth = 176;
/// The least width of the error map's PNG: its colour bar's captions fit.
inline constexpr int kErrorMapMinWidth = 260;

/// Writes the sample map (PNG) atomically: SampleMapImage() at the top left,
/// below it a legend, one entry per reason: its colour, its name and the
/// share of the working pixels it marks (interpolated: the rest). The PNG is
/// at least kLegendEntryWidth wide; its ImageDescription says where the map is.
Status WriteSampleMap(const std::string& path, const Reconstruction& r);

/// Difference of sRGB-encoded luminance that the error map draws at full scale
/// (white): 0.1, a tenth of the display range; smaller errors go through
/// black, blue, red, yellow.
inline constexpr float kErrorMapFullScale = 0.1f;

/// The colour of a pixel where the image or the reference is NaN/Inf (not on the ramp).
inline constexpr std::array<uint8_t, 3> kNonFiniteColor = {0, 255, 0};

/// Writes a heat map of |image - reference| (luminance, display units) as PNG,
/// atomically. Non-finite pixels are drawn green. Below the map a colour bar
/// of the ramp labelled 0 to kErrorMapFullScale, what is measured, and the
/// largest error of the image (and the count of NaN/Inf pixels); the PNG is
/// at least kErrorMapMinWidth wide.
Status WriteErrorMap(const std::string& path, std::span<const RGB> image,
                     std::span<const RGB> reference, int width, int height);

}  // namespace dcm::toolkit
