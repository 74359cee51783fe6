// Display images through OpenColorIO.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "dcm/color.h"
#include "dcm/status.h"

namespace dcm::toolkit {

/// The display transform of the previews, as oiiotool names it:
/// --colorconfig FILE (else $OCIO), --display, --view, --look. All empty and
/// no $OCIO: the built-in sRGB transfer function.
struct DisplayTransform {
  std::string config;   ///< an OpenColorIO config file; empty: $OCIO
  std::string display;  ///< empty: the config's default display
  std::string view;     ///< empty: the display's default view
  std::string look;     ///< looks applied before the view ("a,b"); empty: the view's own
};

/// Checks `t` against its config: the file loads, the display, view and looks
/// exist (the message names the flag and lists the names the config has);
/// --display, --view or --look without a config is an error. `description`
/// says which transform is used: "ocio: config FILE, display D, view V[,
/// look L]" or "built-in sRGB". A usage error.
Status CheckDisplayTransform(const DisplayTransform& t, std::string* description);

/// Encodes scene-linear `pixels` to 8-bit display RGB (3 bytes a pixel) with
/// the transform `t`. NaN/Inf are shown black. OpenColorIO errors come back
/// as a Status.
Status DisplayEncode(int width, int height, std::span<const RGB> pixels, std::vector<uint8_t>* rgb,
                     const DisplayTransform& t = {});

/// Writes `pixels` (scene-linear) as an 8-bit display image through `t`: the
/// config's (--colorconfig, else $OCIO) display and view, by default its
/// defaults; without a config the sRGB transfer function built in OCIO 2.1
/// without a config file (values clipped to [0,1]). Atomically.
Status WritePreview(const std::string& path, int width, int height, std::span<const RGB> pixels,
                    const DisplayTransform& t = {});

}  // namespace dcm::toolkit
