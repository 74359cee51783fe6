// Display previews through OpenColorIO 2.1.
#include "preview.h"

#include <OpenColorIO/OpenColorIO.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

#include "image_io.h"

namespace OCIO = OCIO_NAMESPACE;

namespace dcm::toolkit {

namespace {

std::string List(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

/// The config of `t`: --colorconfig, else $OCIO; null when neither.
OCIO::ConstConfigRcPtr LoadConfig(const DisplayTransform& t, std::string* source) {
  if (!t.config.empty()) {
    *source = t.config;
    return OCIO::Config::CreateFromFile(t.config.c_str());
  }
  const char* env = std::getenv("OCIO");
  if (!env || !*env) return nullptr;
  *source = std::string("$OCIO=") + env;
  return OCIO::Config::CreateFromEnv();
}

/// Resolves `t` against its config (OpenColorIO exceptions escape): the
/// display, view and looks, checked; null config: the built-in sRGB curve.
Status Resolve(const DisplayTransform& t, OCIO::ConstConfigRcPtr* config, std::string* display, std::string* view,
               std::string* description) {
  std::string source;
  try {
    *config = LoadConfig(t, &source);
  } catch (const OCIO::Exception& e) {
    return Status::Error((t.config.empty() ? std::string("$OCIO") : "--colorconfig " + t.config) + ": " + e.what());
  }
  if (!*config) {
    for (const auto& [flag, value] : {std::pair{"--display", &t.display}, {"--view", &t.view}, {"--look", &t.look}})
      if (!value->empty())
        return Status::Error(std::string(flag) + " " + *value +
                             ": needs an OpenColorIO config (--colorconfig FILE or $OCIO)");
    *description = "built-in sRGB";
    return Status::Ok();
  }
  const auto& c = **config;
  std::vector<std::string> displays;
  for (int i = 0; i < c.getNumDisplays(); ++i) displays.push_back(c.getDisplay(i));
  *display = t.display.empty() ? c.getDefaultDisplay() : t.display;
  if (std::find(displays.begin(), displays.end(), *display) == displays.end())
    return Status::Error("--display " + *display + ": not a display of " + source + " (displays: " + List(displays) +
                         ")");
  std::vector<std::string> views;
  for (int i = 0; i < c.getNumViews(display->c_str()); ++i) views.push_back(c.getView(display->c_str(), i));
  *view = t.view.empty() ? c.getDefaultView(display->c_str()) : t.view;
  if (std::find(views.begin(), views.end(), *view) == views.end())
    return Status::Error("--view " + *view + ": not a view of display " + *display + " in " + source +
                         " (views: " + List(views) + ")");
  if (!t.look.empty()) {
    std::vector<std::string> looks;
    for (int i = 0; i < c.getNumLooks(); ++i) looks.push_back(c.getLookNameByIndex(i));
    std::string rest = t.look;
    while (!rest.empty()) {
      const size_t comma = rest.find(',');
      std::string name = rest.substr(0, comma);
      if (!name.empty() && (name[0] == '+' || name[0] == '-')) name.erase(0, 1);  // OCIO: apply / invert
      rest = comma == std::string::npos ? "" : rest.substr(comma + 1);
      if (!c.getLook(name.c_str()))
        return Status::Error("--look " + name + ": not a look of " + source + " (looks: " +
                             (looks.empty() ? std::string("none") : List(looks)) + ")");
    }
  }
  *description = "ocio: config " + source + ", display " + *display + ", view " + *view +
                 (t.look.empty() ? "" : ", look " + t.look);
  return Status::Ok();
}

/// The processor from scene-linear to display: the config's display and view
/// (DisplayTransform), else the sRGB encoding (IEC 61966-2-1: exponent 2.4,
/// offset 0.055, with its linear segment) applied as the inverse of OCIO's
/// ExponentWithLinearTransform on a raw config. `clipFirst` tells whether the
/// input must be clipped to [0,1] first (the raw transfer function is only
/// defined there; a view transform handles HDR itself).
Status MakeProcessor(const DisplayTransform& t, bool* clipFirst, OCIO::ConstCPUProcessorRcPtr* cpu) {
  OCIO::ConstConfigRcPtr config;
  std::string display, view, description;
  DCM_RETURN_IF_ERROR(Resolve(t, &config, &display, &view, &description));
  if (config) {
    auto dvt = OCIO::DisplayViewTransform::Create();
    dvt->setSrc(OCIO::ROLE_SCENE_LINEAR);
    dvt->setDisplay(display.c_str());
    dvt->setView(view.c_str());
    auto vt = OCIO::LegacyViewingPipeline::Create();
    vt->setDisplayViewTransform(dvt);
    if (!t.look.empty()) {
      vt->setLooksOverrideEnabled(true);
      vt->setLooksOverride(t.look.c_str());
    }
    *clipFirst = false;
    *cpu = vt->getProcessor(config, config->getCurrentContext())->getDefaultCPUProcessor();
    return Status::Ok();
  }
  config = OCIO::Config::CreateRaw();
  auto srgb = OCIO::ExponentWithLinearTransform::Create();
  const double gamma[4] = {2.4, 2.4, 2.4, 1.0};
  const double offset[4] = {0.055, 0.055, 0.055, 0.0};
  srgb->setGamma(gamma);
  srgb->setOffset(offset);
  srgb->setDirection(OCIO::TRANSFORM_DIR_INVERSE);
  *clipFirst = true;
  *cpu = config->getProcessor(srgb)->getDefaultCPUProcessor();
  return Status::Ok();
}

}  // namespace

Status CheckDisplayTransform(const DisplayTransform& t, std::string* description) {
  OCIO::ConstConfigRcPtr config;
  std::string display, view;
  try {
    return Resolve(t, &config, &display, &view, description);
  } catch (const OCIO::Exception& e) {
    return Status::Error(std::string("OpenColorIO: ") + e.what());
  }
}

Status DisplayEncode(int width, int height, std::span<const RGB> pixels, std::vector<uint8_t>* rgb,
                     const DisplayTransform& t) {
  const size_t n = size_t(std::max(width, 0)) * size_t(std::max(height, 0));
  if (n == 0 || pixels.size() != n)
    return Status::Error("preview: " + std::to_string(pixels.size()) + " pixels given for a " +
                         std::to_string(width) + "x" + std::to_string(height) + " image");
  std::vector<float> buffer(n * 3);
  try {
    bool clipFirst = true;
    OCIO::ConstCPUProcessorRcPtr cpu;
    DCM_RETURN_IF_ERROR(MakeProcessor(t, &clipFirst, &cpu));
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

Status WritePreview(const std::string& path, int width, int height, std::span<const RGB> pixels,
                    const DisplayTransform& t) {
  std::vector<uint8_t> rgb;
  Status st = DisplayEncode(width, height, pixels, &rgb, t);
  if (!st.ok()) return Status::Error("cannot write preview '" + path + "': " + st.message());
  return WriteRgb8(path, width, height, rgb);
}

}  // namespace dcm::toolkit
