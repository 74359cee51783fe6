// libFuzzer target: the image reading paths of dcm.
//  - tools/common ReadRgb (what `dcm render --compare` and the AOV tools use),
//    through OpenImageIO, with the memory guard CheckImageDimensions;
//  - when plugins/aov is built in (DCM_FUZZ_AOV), AovProvider::Open with the
//    generic and the Blender presets: the channel mapping of `dcm reconstruct`.
//
// The input is written to a file with the .exr extension (both readers take a
// path; OpenImageIO picks the reader by extension and falls back to sniffing,
// as it does for a user's file). The contract checked: no crash, no sanitizer
// report, no allocation beyond libFuzzer's -malloc_limit_mb; on success the
// sizes agree; on failure the message names the file.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <OpenImageIO/imageio.h>

#include "common/image_io.h"
#ifdef DCM_FUZZ_AOV
#include "dcm/aov/aov_provider.h"
#endif

namespace {

const std::string& InputPath() {
  // Never destroyed: the atexit handler below removes the file after static
  // destructors may have run.
  static const std::string* path = [] {
    std::error_code ec;
    std::filesystem::path dir = std::filesystem::temp_directory_path(ec);
    if (ec) dir = "/tmp";
    return new std::string((dir / ("dcm_fuzz_exr_" + std::to_string(::getpid()) + ".exr")).string());
  }();
  return *path;
}

[[noreturn]] void Violation(const std::string& what) {
  std::fprintf(stderr, "fuzz_exr: %s\n", what.c_str());
  std::abort();
}

void CheckNamesFile(const dcm::Status& st, const char* who) {
  if (!st.ok() && !st.pending() && st.message().find(InputPath()) == std::string::npos)
    Violation(std::string(who) + ": error message does not name the file: " + st.message());
}

/// False for an OpenEXR file whose first header declares an attribute larger
/// than the file: OpenEXR 3.1 allocates the declared size (up to 2 GiB)
/// before it finds the file short, which takes seconds and gigabytes per
/// input and starves the fuzzer. That behaviour is OpenEXR's, outside dcm's
/// reach (docs/FUZZING.md); such inputs are skipped so that the run explores
/// dcm's code. Anything else (other formats, malformed headers) goes through.
bool PlausibleExrHeader(const uint8_t* data, size_t size) {
  if (size < 8 || !(data[0] == 0x76 && data[1] == 0x2f && data[2] == 0x31 && data[3] == 0x01)) return true;
  size_t pos = 8;
  auto skipString = [&]() {
    while (pos < size && data[pos] != 0) ++pos;
    return pos++ < size;
  };
  while (pos < size && data[pos] != 0) {
    if (!skipString() || !skipString() || pos + 4 > size) return true;  // truncated: let OpenEXR say so
    const uint32_t n = uint32_t(data[pos]) | uint32_t(data[pos + 1]) << 8 | uint32_t(data[pos + 2]) << 16 |
                       uint32_t(data[pos + 3]) << 24;
    pos += 4;
    if (n > size - pos) return false;
    pos += n;
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // One thread: deterministic runs, no thread-pool start-up per input.
  OIIO::attribute("threads", 1);
  OIIO::attribute("exr_threads", 1);
  std::atexit([] {
    std::error_code ec;
    std::filesystem::remove(InputPath(), ec);
  });
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > (1u << 20) || !PlausibleExrHeader(data, size)) return 0;
  const std::string& path = InputPath();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
    if (!out) Violation("cannot write the input file " + path);
  }

  int w = 0, h = 0;
  std::vector<dcm::RGB> pixels;
  const dcm::Status st = dcm::toolkit::ReadRgb(path, &w, &h, &pixels);
  if (st.ok()) {
    if (w <= 0 || h <= 0 || pixels.size() != size_t(w) * size_t(h))
      Violation("ReadRgb returned " + std::to_string(w) + "x" + std::to_string(h) + " with " +
                std::to_string(pixels.size()) + " pixels");
  }
  CheckNamesFile(st, "ReadRgb");

#ifdef DCM_FUZZ_AOV
  for (dcm::aov::Preset preset : {dcm::aov::Preset::kGeneric, dcm::aov::Preset::kBlender}) {
    dcm::aov::AovOptions options;
    options.preset = preset;
    std::unique_ptr<dcm::aov::AovProvider> provider;
    const dcm::Status ast = dcm::aov::AovProvider::Open({path}, options, &provider);
#ifndef DCM_FUZZ_IGNORE_KNOWN  // finding 3 (docs/FUZZING.md): some mapping errors omit the file
    CheckNamesFile(ast, "AovProvider::Open");
#endif
    if (ast.ok()) {
      const dcm::ProviderCapabilities caps = provider->Capabilities();
      if (caps.width <= 0 || caps.height <= 0) Violation("AovProvider: empty image accepted");
      // Serve the guides of the whole image and one exact sample: the paths
      // the engine takes first.
      dcm::GuideImage g;
      dcm::GuideRequest what{caps.objectId, caps.shaderId, caps.texture};
      const dcm::Bounds2i all{{0, 0}, {caps.width, caps.height}};
      if (!provider->Guides(all, what, &g).ok()) continue;
      const size_t n = size_t(caps.width) * size_t(caps.height);
      if ((what.objectId && g.objectId.size() != n) || (what.shaderId && g.shaderId.size() != n) ||
          (what.texture && g.texture.size() != n))
        Violation("AovProvider::Guides: wrong guide sizes");
      const dcm::Point2i p[1] = {{caps.width - 1, caps.height - 1}};
      dcm::ExactSample s[1];
      (void)provider->Evaluate(p, dcm::SampleRequest{caps.splitRadiance, caps.variance}, s);
    }
  }
#endif
  return 0;
}
