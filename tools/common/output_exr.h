// Output EXRs of named channels of mixed stored types with the inputs'
// metadata, stored as oiiotool's -d, --compression and --ch ask.
#pragma once

#include <OpenImageIO/imageio.h>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "dcm/color.h"
#include "dcm/geometry.h"
#include "dcm/status.h"
#include "image_io.h"

namespace dcm::toolkit {

/// How an output EXR is stored: oiiotool's -d, --compression and --ch.
struct ExrFormat {
  /// -d: "" keeps each channel's type (the beauty float, a copied pass its
  /// input's), "half" or "float" stores every channel so except the raw ones
  /// (object and shader IDs, Cryptomatte hashes), which a conversion would
  /// destroy.
  std::string dataType;
  std::string compression = "zip";    ///< --compression: an OpenEXR compression (kExrCompressions)
  std::vector<std::string> channels;  ///< --ch: the channels written (OpenEXR sorts them by name); empty: all
};

/// The values --compression accepts (OpenEXR's, named as oiiotool names them).
inline constexpr const char* kExrCompressions[] = {"none", "zip",  "zips", "piz",  "rle",
                                                   "pxr24", "b44", "b44a", "dwaa", "dwab"};

/// Checks -d and --compression; the message names the flag and the values it
/// takes. A usage error.
Status CheckExrFormat(const ExrFormat& format);

/// One channel of an output image: a plane of its data window, row-major.
struct OutputChannel {
  std::string name;
  OIIO::TypeDesc type = OIIO::TypeDesc::FLOAT;  ///< stored type: FLOAT, HALF or UINT
  std::vector<float> values;                    ///< FLOAT or HALF channels
  std::vector<uint32_t> ids;                    ///< UINT channels
  bool raw = false;                             ///< -d leaves the type alone
};

/// An output image: its place in the frame, channels, header attributes.
struct OutputImage {
  Bounds2i display, data;
  std::vector<OutputChannel> channels;
  OIIO::ParamValueList attributes;
};

/// Header attributes that describe an image's structure (compression, line
/// order, chunk count, OpenImageIO's own "oiio:" hints) or an earlier dcm
/// run's provenance ("dcm:"): not carried from an input to an output.
bool IsStructuralAttribute(const std::string& name);

/// The indices in `available` of the channels `wanted` names, every one when
/// `wanted` is empty (error naming --ch and
/// listing the channels there are when one is missing or named twice).
Status SelectChannels(const std::vector<std::string>& available, const std::vector<std::string>& wanted,
                      std::vector<size_t>* order);

/// Writes `image` as an OpenEXR file, atomically (WriteImage), stored as
/// `format` says. The alpha channel is the one named "A" or ending in ".A".
Status WriteOutputExr(const std::string& path, const OutputImage& image, const ExrFormat& format);

/// WriteRgbExr (image_io.h) stored as `format` says: R, G, B (and A = 1 with
/// `alpha`) under --ch, -d and --compression.
Status WriteRgbExr(const std::string& path, const Bounds2i& display, const Bounds2i& data,
                   std::span<const RGB> pixels, const Metadata& metadata, bool alpha, const ExrFormat& format);

/// Adds `metadata` (strings and floats) to `attributes`, replacing same names.
void AddMetadata(const Metadata& metadata, OIIO::ParamValueList* attributes);

/// Records the command line (main() calls it once) for the provenance of
/// every output: "dcm:command_line".
void SetCommandLine(int argc, const char* const* argv);

/// The command line, each argument quoted for a POSIX shell when it needs it;
/// empty before SetCommandLine.
const std::string& CommandLine();

}  // namespace dcm::toolkit
