// Image files in and out. Every output is written through WriteAtomically
// (output_transaction.h), so a failure never leaves a partial or truncated
// file under the requested name.
#pragma once

#include <OpenImageIO/imageio.h>

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "dcm/color.h"
#include "dcm/geometry.h"
#include "dcm/status.h"
#include "output_transaction.h"

namespace dcm::toolkit {

/// String and float attributes for EXR metadata (provenance). Names follow the
/// "dcm:..." convention, e.g. "dcm:exact_fraction".
struct Metadata {
  std::vector<std::pair<std::string, std::string>> strings;
  std::vector<std::pair<std::string, float>> floats;
};

/// Writes float RGB (optionally with a fourth alpha channel of 1) as an EXR
/// (zip compression), atomically. Metadata become EXR header attributes.
Status WriteRgbExr(const std::string& path, int width, int height, std::span<const RGB> pixels,
                   const Metadata& metadata = {});

/// As above; with `alpha` a fourth channel A = 1 is written (RGBA).
Status WriteRgbExr(const std::string& path, int width, int height, std::span<const RGB> pixels,
                   const Metadata& metadata, bool alpha);

/// As above, for the `data` window of a frame whose display window is
/// `display` (EXR data and display windows: a render region or a tile, or
/// overscan); `pixels` cover the data window, row-major.
Status WriteRgbExr(const std::string& path, const Bounds2i& display, const Bounds2i& data,
                   std::span<const RGB> pixels, const Metadata& metadata, bool alpha);

/// A float image spec of `channels` channels for the `data` window of a
/// frame whose display window is `display` (EXR data and display windows).
OIIO::ImageSpec WindowedSpec(const Bounds2i& display, const Bounds2i& data, int channels);

/// Writes `pixels` (interleaved, `format`, covering spec's data window) with
/// `spec` atomically; the format comes from the extension. The one place
/// that drives OpenImageIO's writer: every image output goes through it.
Status WriteImage(const std::string& path, const OIIO::ImageSpec& spec, const void* pixels, OIIO::TypeDesc format);

/// Writes an 8-bit RGB image atomically (PNG, or any format OIIO picks from the extension).
Status WriteRgb8(const std::string& path, int width, int height, std::span<const uint8_t> rgb);

/// The memory guard: rejects dimensions <= 0, above 2^17 per side, or whose
/// float data (`channels` planes) would exceed dcm::MemoryBudget(). Checked
/// from the header, before allocating. The message names the file.
Status CheckImageDimensions(const std::string& path, int width, int height, int channels);

/// Reads the R, G, B channels of an image (by channel name; without them,
/// those of its one layer `*.Combined`, Blender's multilayer EXR; a 1-channel
/// image is read as gray): the pixels of its data window. The message names the file and what is wrong.
Status ReadRgb(const std::string& path, int* width, int* height, std::vector<RGB>* pixels);

}  // namespace dcm::toolkit
