// Display previews through OpenColorIO 2.1.
#include "preview.h"

#include <OpenColorIO/OpenColorIO.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <vector>

#include "image_io.h"

namespace OCIO = OCIO_NAMESPACE;

namespace dcm::toolkit {

namespace {

/// The processor from scene-linear to display: $OCIO's default display and view
/// when $OCIO is set, else the sRGB encoding (IEC 61966-2-1: exponent 2.4,
/// offset 0.055, with its linear segment) applied as the inverse of OCIO's
/// ExponentWithLinearTransform on a raw config. `clipFirst` tells whether the
/// input must be clipped to [0,1] first (the raw transfer function is only
/// defined there; a view transform handles HDR itself).
OCIO::ConstCPUProcessorRcPtr MakeProcessor(bool* clipFirst, std::string* description) {
  const char* env = std::getenv("OCIO");
  if (env && *env) {
    OCIO::ConstConfigRcPtr config = OCIO::Config::CreateFromEnv();
    const char* display = config->getDefaultDisplay();
    const char* view = config->getDefaultView(display);
    auto dvt = OCIO::DisplayViewTransform::Create();
    dvt->setSrc(OCIO::ROLE_SCENE_LINEAR);
    dvt->setDisplay(display);
    dvt->setView(view);
    *clipFirst = false;
    *description = std::string("$OCIO=") + env + ", display '" + display + "', view '" + view + "'";
    return config->getProcessor(dvt)->getDefaultCPUProcessor();
  }
  OCIO::ConstConfigRcPtr config = OCIO::Config::CreateRaw();
  auto srgb = OCIO::ExponentWithLinearTransform::Create();
  const double gamma[4] = {2.4, 2.4, 2.4, 1.0};
  const double offset[4] = {0.055, 0.055, 0.055, 0.0};
  srgb->setGamma(gamma);
  srgb->setOffset(offset);
  srgb->setDirection(OCIO::TRANSFORM_DIR_INVERSE);
  *clipFirst = true;
  *description = "sRGB transfer function";
  return config->getProcessor(srgb)->getDefaultCPUProcessor();
}

}  // namespace

Status DisplayEncode(int width, int height, std::span<const RGB> pixels, std::vector<uint8_t>* rgb) {
  const size_t n = size_t(std::max(width, 0)) * size_t(std::max(height, 0));
  if (n == 0 || pixels.size() != n)
    return Status::Error("preview: " + std::to_string(pixels.size()) + " pixels given for a " +
                         std::to_string(width) + "x" + std::to_string(height) + " image");
  std::vector<float> buffer(n * 3);
  try {
    bool clipFirst = true;
    std::string description;
    auto cpu = MakeProcessor(&clipFirst, &description);
    for (size_t i = 0; i < n; ++i) {
      for (int c = 0; c < 3; ++c) {
        float v = pixels[i][c];
        if (!std::isfinite(v)) v = 0.f;  // NaN/Inf pixels are shown black
        if (clipFirst) v = std::clamp(v, 0.f, 1.f);
        buffer[i * 3 + size_t(c)] = v;
      }
    }
    OCIO::PackedImageDesc desc(buffer.data(), width, height, 3);
    cpu->apply(desc);
  } catch (const OCIO::Exception& e) {
    return Status::Error(std::string("OpenColorIO: ") + e.what());
  }
  rgb->resize(n * 3);
  for (size_t i = 0; i < n * 3; ++i) {
    float v = buffer[i];
    if (!std::isfinite(v)) v = 0.f;
    (*rgb)[i] = uint8_t(std::lround(std::clamp(v, 0.f, 1.f) * 255.f));
  }
  return Status::Ok();
}

Status WritePreview(const std::string& path, int width, int height, std::span<const RGB> pixels) {
  std::vector<uint8_t> rgb;
  Status st = DisplayEncode(width, height, pixels, &rgb);
  if (!st.ok()) return Status::Error("cannot write preview '" + path + "': " + st.message());
  return WriteRgb8(path, width, height, rgb);
}

}  // namespace dcm::toolkit
