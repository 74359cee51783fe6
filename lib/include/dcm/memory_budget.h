// The memory budget: how much memory one input file may make dcm allocate,
// checked from what the file declares before anything is allocated.
#pragma once

#include <cstdint>
#include <string>

#include "dcm/status.h"

namespace dcm {

/// Default budget for what one input (an image, a mesh, a texture) may cost:
/// 8 GiB, the figure of the guards it replaced: far above any input of the
/// examples, below the RAM of the machines dcm is run on.
inline constexpr int64_t kDefaultMemoryBudget = int64_t(8) << 30;

/// The largest ratio of decoded pixel bytes to file bytes believed of a
/// compressed image. Deflate (PNG, TIFF and EXR ZIP) stays below 1032:1 and
/// OpenEXR's most compressive method, DWA (a flat 8x8 block becomes one DC
/// value and an end-of-block code, then deflate), below about 33000:1; twice
/// that leaves a margin. Only images that hold no information (a constant
/// WebP) compress further, and a texture or AOV of that kind is never needed.
inline constexpr double kMaxCompressionRatio = 65536.0;

/// The budget in bytes: DCM_MEMORY_LIMIT when it is set to a valid size
/// (bytes, or a number with K, M, G or T for KiB..TiB: "512M", "2G",
/// "2GiB"), else kDefaultMemoryBudget.
int64_t MemoryBudget();

/// Parses a DCM_MEMORY_LIMIT value; false when it is not a positive size.
bool ParseByteSize(const std::string& text, int64_t* bytes);

/// "3.5 GiB", "12.0 MiB", "800 bytes": a size for messages.
std::string ByteText(double bytes);

/// OK when `bytes` fits MemoryBudget(); else an error
/// "<what> would need about X GiB, more than the memory limit of Y ...".
Status CheckMemoryBudget(const std::string& what, double bytes);

}  // namespace dcm
