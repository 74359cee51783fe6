// A small scanline EXR made to declare another size: the tiny files that
// claim huge images, for the tests of the memory guards.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>

namespace dcm::testing {

/// `exr` (the bytes of a one-part scanline EXR whose pixels fit in one chunk
/// of `linesPerChunk` scanlines) with its data and display windows patched to
/// side x side pixels and an offset table of one entry per `linesPerChunk`
/// scanlines, all pointing at the one real chunk: OpenEXR opens it.
inline std::string DeclareExrSize(std::string exr, int side, int linesPerChunk) {
  // Header: magic, version, then attributes (name\0 type\0 int32 size,
  // value) up to an empty name.
  size_t p = 8;
  while (exr[p] != 0) {
    const size_t nameEnd = exr.find('\0', p), typeEnd = exr.find('\0', nameEnd + 1);
    int32_t size = 0;
    std::memcpy(&size, &exr[typeEnd + 1], 4);
    const std::string name = exr.substr(p, nameEnd - p);
    if (name == "dataWindow" || name == "displayWindow") {
      const int32_t maxv = side - 1;
      std::memcpy(&exr[typeEnd + 5 + 8], &maxv, 4);
      std::memcpy(&exr[typeEnd + 5 + 12], &maxv, 4);
    }
    p = typeEnd + 5 + size_t(size);
  }
  const std::string header = exr.substr(0, p + 1);
  uint64_t chunkAt = 0;
  std::memcpy(&chunkAt, &exr[p + 1], 8);
  const uint64_t chunks = (uint64_t(side) + uint64_t(linesPerChunk) - 1) / uint64_t(linesPerChunk);
  const uint64_t newAt = header.size() + 8 * chunks;
  std::string lying = header;
  for (uint64_t i = 0; i < chunks; ++i) lying.append(reinterpret_cast<const char*>(&newAt), 8);
  return lying + exr.substr(chunkAt);
}

}  // namespace dcm::testing
