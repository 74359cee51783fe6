// Display images through OpenColorIO.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "dcm/color.h"
#include "dcm/status.h"

namespace dcm::toolkit {

/// Encodes scene-linear `pixels` to 8-bit display RGB (3 bytes a pixel) with
/// the same transform as WritePreview. NaN/Inf are shown black. OpenColorIO
/// errors (a bad $OCIO config) come back as a Status.
Status DisplayEncode(int width, int height, std::span<const RGB> pixels, std::vector<uint8_t>* rgb);

/// Writes `pixels` (scene-linear) as an 8-bit display image. Uses the config in
/// $OCIO with its default display/view when set; otherwise the sRGB transfer
/// function built in OCIO 2.1 without a config file (values clipped to [0,1]).
/// The file is written atomically.
Status WritePreview(const std::string& path, int width, int height, std::span<const RGB> pixels);

}  // namespace dcm::toolkit
