// Partial results (tiles, regions) and their assembly: a part is an EXR whose
// display window is the whole frame and whose data window is its region, with
// the region, the tile and a fingerprint of the settings in its metadata;
// MergeParts() checks that parts fit together and assembles the frame.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/image_io.h"
#include "common/output_exr.h"
#include "dcm/color.h"
#include "dcm/geometry.h"
#include "dcm/options.h"
#include "dcm/status.h"

namespace dcm::toolkit {

/// Metadata names of a part.
inline constexpr const char* kAttrTile = "dcm:tile";                ///< "I/N", 0-based I (only with --tile)
inline constexpr const char* kAttrRegion = "dcm:region";            ///< "x,y,w,h" in output pixels
inline constexpr const char* kAttrFingerprint = "dcm:fingerprint";  ///< 16 hex digits
inline constexpr const char* kAttrSettings = "dcm:part_settings";   ///< the JSON the fingerprint hashes
inline constexpr const char* kAttrPartStats = "dcm:part_stats";     ///< counts over the part's pixels (JSON)
/// The channels -d must leave alone (IDs, Cryptomatte hashes), comma-separated.
inline constexpr const char* kAttrRawChannels = "dcm:raw_channels";

/// 64-bit FNV-1a, continued from `seed`.
uint64_t HashBytes(std::span<const char> bytes, uint64_t seed = 14695981039346656037ull);

/// FNV-1a of a file's contents; the message names the file if it cannot be read.
Status HashFile(const std::string& path, uint64_t* hash);

/// 16 lower-case hex digits.
std::string HexHash(uint64_t hash);

/// The settings that decide a part's pixels, as JSON: the command, the dcm
/// version, the engine options (without threads, tile_size and batch_size,
/// which do not change a bit of the result) and `identity` (what the command
/// reads: scene or input files by content hash, sizes, provider flags).
nlohmann::json PartSettings(const std::string& command, const std::string& version,
                            const ReconstructionOptions& options, const nlohmann::json& identity);

/// The fingerprint of PartSettings(): HexHash of its compact dump.
std::string Fingerprint(const nlohmann::json& settings);

/// "x,y,w,h".
std::string RegionText(const Bounds2i& region);

/// Writes the output pixels of `region` (row-major, region-sized) as a part
/// of a frameWidth x frameHeight frame: display window = the frame, data
/// window = the region, float RGB (or RGBA with A = 1), zip, atomically.
Status WritePartExr(const std::string& path, int frameWidth, int frameHeight, const Bounds2i& region,
                    std::span<const RGB> pixels, const Metadata& metadata, bool alpha = false);

/// Writes `image` as a part: display window = the frame, data window = the
/// region, every channel in its stored type, `metadata` (the part attributes
/// among them) added to its attributes, and the raw channels recorded
/// (kAttrRawChannels) so that `dcm merge -d` leaves them alone; atomically.
Status WritePartImage(const std::string& path, OutputImage image, const Metadata& metadata);

/// One part as read back.
struct Part {
  std::string path;
  int frameWidth = 0, frameHeight = 0;
  Bounds2i region;
  std::vector<std::string> channels;
  std::vector<OIIO::TypeDesc> types;  ///< each channel's stored type: FLOAT, HALF or UINT
  std::vector<std::string> rawChannels;  ///< kAttrRawChannels
  std::vector<float> pixels;  ///< region-sized, channels interleaved (UINT channels: see ids)
  std::vector<std::vector<uint32_t>> ids;  ///< per channel: the UINT channels' values, region-sized
  std::string tile;           ///< "I/N" or empty
  std::string fingerprint;
  std::string settings;       ///< JSON text
  std::string partStats;      ///< JSON text or empty
  Metadata metadata;          ///< dcm's other attributes and Software
  OIIO::ParamValueList attributes;  ///< the inputs' (renderer's) attributes, structural ones excluded
};

/// Reads a part (its pixels too unless `withPixels` is false); the message
/// names the file and the attribute at fault.
Status ReadPart(const std::string& path, Part* part, bool withPixels = true);

/// The whole frame assembled from parts.
struct MergedFrame {
  int width = 0, height = 0;
  std::vector<std::string> channels;
  std::vector<OIIO::TypeDesc> types;       ///< as Part::types
  std::vector<std::string> rawChannels;    ///< as Part::rawChannels
  std::vector<float> pixels;  ///< width x height, channels interleaved
  std::vector<std::vector<uint32_t>> ids;  ///< per channel: the UINT channels' values, width x height
  Metadata metadata;          ///< the first part's, without the part attributes
  OIIO::ParamValueList attributes;  ///< the first part's inputs' attributes
  nlohmann::json stats;       ///< counts summed over the parts (null when a part has none)
};

/// Reads `paths` and assembles them. Fails, naming the parts and pixels, when
/// a part is unreadable or not a dcm part, when parts disagree on the frame,
/// the channels, the settings (fingerprint; the differing fields are named)
/// or the tile count, when two parts overlap, or when pixels are not covered.
Status MergeParts(const std::vector<std::string>& paths, MergedFrame* frame);

/// Writes a merged frame as an EXR (display window = data window), atomically,
/// stored as `format` says.
Status WriteMergedExr(const std::string& path, const MergedFrame& frame, const Metadata& extra,
                      const ExrFormat& format = {});

}  // namespace dcm::toolkit
