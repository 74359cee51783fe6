// libFuzzer target: image textures of the internal ray tracer
// (plugins/embree/src/textures.cpp: the declared-size check, then OpenImageIO's
// TextureSystem). The first byte picks the extension the file is written
// with (OpenImageIO chooses its reader by it, then by the content); the rest
// is the file. The texture is created and looked up at three points with a
// footprint, which reads and MIP-maps the image.
//
// The contract checked besides crashes and sanitizer reports: no allocation
// beyond libFuzzer's -malloc_limit_mb (DCM_MEMORY_LIMIT is set to 256 MiB
// here, and a header declaring more than its file can hold is refused from
// the header); an error names the material and the file.
#include <unistd.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "dcm/embree/textures.h"

namespace {

const char* const kExtensions[] = {".png", ".ppm", ".tga", ".exr", ".jpg", ".bmp", ".hdr", ".tif"};
constexpr size_t kExtensionCount = sizeof kExtensions / sizeof kExtensions[0];

/// The input file for extension `e`; never destroyed (see fuzz_exr.cpp).
const std::string& InputPath(size_t e) {
  static const std::string* base = [] {
    std::error_code ec;
    std::filesystem::path dir = std::filesystem::temp_directory_path(ec);
    if (ec) dir = "/tmp";
    return new std::string((dir / ("dcm_fuzz_texture_" + std::to_string(::getpid()))).string());
  }();
  static std::string* paths[kExtensionCount] = {};
  if (!paths[e]) paths[e] = new std::string(*base + kExtensions[e]);
  return *paths[e];
}

[[noreturn]] void Violation(const std::string& what) {
  std::fprintf(stderr, "fuzz_texture: %s\n", what.c_str());
  std::abort();
}

}  // namespace

// OpenImageIO 2.4.7's TextureSystem::destroy() deletes the implementation
// through its base class (a new-delete-type-mismatch), so the implementation's
// destructor never runs and what it holds (per-thread buffers, the error
// messages of its files) leaks (scripts/sanitize-lsan.supp); not dcm's memory.
extern "C" const char* __asan_default_options() { return "new_delete_type_mismatch=0"; }
extern "C" const char* __lsan_default_suppressions() { return "leak:libOpenImageIO.so\n"; }

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  OIIO::attribute("threads", 1);
  OIIO::attribute("exr_threads", 1);
  ::setenv("DCM_MEMORY_LIMIT", "256M", 1);
  std::atexit([] {
    std::error_code ec;
    for (size_t e = 0; e < kExtensionCount; ++e) std::filesystem::remove(InputPath(e), ec);
  });
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1 || size > (1u << 20)) return 0;
  const std::string& path = InputPath(data[0] % kExtensionCount);
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data + 1), std::streamsize(size - 1));
    if (!out) Violation("cannot write the input file " + path);
  }
  dcm::embree::TextureDesc desc;
  desc.kind = dcm::embree::TextureKind::kImage;
  desc.file = path;
  // A fresh texture system per input: OpenImageIO caches files by name.
  dcm::embree::TextureCache cache;
  std::unique_ptr<dcm::embree::Texture> texture;
  const dcm::Status st = cache.Create(desc, "fuzz.json: materials.m.texture", &texture);
  if (!st.ok()) {
    if (st.message().rfind("fuzz.json: materials.m.texture: ", 0) != 0 || st.message().find(path) == std::string::npos)
      Violation("error does not name the material and the file: " + st.message());
    return 0;
  }
  const dcm::embree::TexCoord at[3] = {
      {{0.25f, 0.75f}, {0.f, 0.f}, {0.f, 0.f}},
      {{0.5f, 0.5f}, {0.01f, 0.f}, {0.f, 0.01f}},
      {{0.9f, 0.1f}, {0.3f, 0.1f}, {0.f, 0.5f}},
  };
  for (const auto& tc : at) (void)texture->Eval(tc);  // reads and MIP-maps the image
  return 0;
}
