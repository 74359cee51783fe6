#include <array>
#include <cmath>
#include <string>
#include <utility>

#include "dcm/options.h"

namespace dcm {

ReconstructionOptions ReconstructionOptions::Guo() {
  ReconstructionOptions o;
  o.elementaryBlock = 8;  // Guo's and the paper's elementary blocks
  o.noisyElementaryBlock = 0;
  o.SetContrastThreshold(0.06f);
  o.SetContrastMetric(ContrastMetric::kMitchell);
  o.SetDirections(8);
  o.objectTest = ObjectTest::kObjectId;
  o.SetThinObjects(ThinObjectTest::kOff);
  o.neighbourDirections = 0;
  o.surfaceAware = false;
  o.textureSplit = false;
  o.smoothRefinement = SmoothRefinement::kAlways;
  o.adaptiveBorders = false;
  o.crossingFillReach = 0;
  o.finestCentreProbe = false;
  o.gradientBlocksSimple = false;
  o.firstOrderFromGuides = false;
  o.checkerboard = false;
  o.simpleSurfaceChanges = 2;
  o.fallback = false;
  o.noiseSignificance = 0.f;
  o.creaseAngle = 0.f;
  o.denoiseSamples = false;
  return o;
}

ReconstructionOptions ReconstructionOptions::Paper() {
  ReconstructionOptions o = Guo();
  o.objectTest = ObjectTest::kObjectAndShader;
  o.SetThinObjects(ThinObjectTest::kNoneMatches);
  o.textureSplit = true;
  o.fallback = true;  // "switching back to a full sampling for these few critical cases"
  o.fallbackMaxChanges = 4;  // more than two edges: more than two objects on the border
  o.fallbackShadingChanges = -1;  // every change counts
  return o;
}

namespace {
bool IsPowerOfTwo(int v) { return v > 0 && (v & (v - 1)) == 0; }

template <typename E, size_t N>
Status ParseName(std::string_view text, const std::array<std::pair<std::string_view, E>, N>& names,
                 const char* what, E* out) {
  std::string valid;
  for (const auto& [name, value] : names) {
    if (text == name) {
      *out = value;
      return Status::Ok();
    }
    valid += (valid.empty() ? "" : ", ") + std::string(name);
  }
  return Status::Error(std::string(what) + ": unknown value '" + std::string(text) + "' (valid: " + valid + ")");
}

template <typename E, size_t N>
std::string_view NameOf(E value, const std::array<std::pair<std::string_view, E>, N>& names) {
  for (const auto& [name, v] : names)
    if (v == value) return name;
  return "?";
}

constexpr std::array<std::pair<std::string_view, ObjectTest>, 4> kObjectTests{{
    {"none", ObjectTest::kNone},
    {"id", ObjectTest::kObjectId},
    {"id+shader", ObjectTest::kObjectAndShader},
    {"id|shader", ObjectTest::kObjectOrShader}}};
constexpr std::array<std::pair<std::string_view, ThinObjectTest>, 4> kThinTests{{
    {"off", ThinObjectTest::kOff}, {"none-matches", ThinObjectTest::kNoneMatches},
    {"any-differs", ThinObjectTest::kAnyDiffers}, {"end-differs", ThinObjectTest::kEndDiffers}}};
constexpr std::array<std::pair<std::string_view, ContrastMetric>, 3> kMetrics{{
    {"mitchell", ContrastMetric::kMitchell},
    {"display", ContrastMetric::kDisplay},
    {"display-weighted", ContrastMetric::kDisplayWeighted}}};
constexpr std::array<std::pair<std::string_view, SmoothRefinement>, 3> kRefinements{{
    {"always", SmoothRefinement::kAlways}, {"centre-probe", SmoothRefinement::kCentreProbe},
    {"never", SmoothRefinement::kNever}}};
}  // namespace

std::string_view ToString(ObjectTest v) { return NameOf(v, kObjectTests); }
std::string_view ToString(ThinObjectTest v) { return NameOf(v, kThinTests); }
std::string_view ToString(ContrastMetric v) { return NameOf(v, kMetrics); }
std::string_view ToString(SmoothRefinement v) { return NameOf(v, kRefinements); }
Status Parse(std::string_view t, ObjectTest* o) { return ParseName(t, kObjectTests, "object test", o); }
Status Parse(std::string_view t, ThinObjectTest* o) { return ParseName(t, kThinTests, "thin-object test", o); }
Status Parse(std::string_view t, ContrastMetric* o) { return ParseName(t, kMetrics, "contrast metric", o); }
Status Parse(std::string_view t, SmoothRefinement* o) { return ParseName(t, kRefinements, "smooth refinement", o); }

Status ReconstructionOptions::Validate() const {
  auto bad = [](const std::string& field, const std::string& why) {
    return Status::Error("option " + field + ": " + why);
  };
  if (!IsPowerOfTwo(elementaryBlock) || elementaryBlock > 256)
    return bad("elementaryBlock", "must be a power of two from 1 to 256, got " + std::to_string(elementaryBlock));
  if (noisyElementaryBlock != 0 && (!IsPowerOfTwo(noisyElementaryBlock) || noisyElementaryBlock > 256))
    return bad("noisyElementaryBlock",
               "must be 0 or a power of two from 1 to 256, got " + std::to_string(noisyElementaryBlock));
  if (!IsPowerOfTwo(minBlock) || minBlock > elementaryBlock)
    return bad("minBlock", "must be a power of two from 1 to elementaryBlock (" + std::to_string(elementaryBlock) +
                               "), got " + std::to_string(minBlock));
  if (!(contrastThreshold >= 0) || !std::isfinite(contrastThreshold))
    return bad("contrastThreshold", "must be a finite number >= 0");
  if (!(contrastThresholdSupersampled >= 0) || !std::isfinite(contrastThresholdSupersampled))
    return bad("contrastThresholdSupersampled", "must be a finite number >= 0");
  if (directions < 1 || directions > 64) return bad("directions", "must be from 1 to 64, got " + std::to_string(directions));
  if (directionsSupersampled < 1 || directionsSupersampled > 64)
    return bad("directionsSupersampled", "must be from 1 to 64, got " + std::to_string(directionsSupersampled));
  if (!(creaseAngle >= 0 && creaseAngle <= 180)) return bad("creaseAngle", "must be from 0 to 180 degrees");
  if (!(noiseSignificance >= 0) || !std::isfinite(noiseSignificance))
    return bad("noiseSignificance", "must be a finite number >= 0");
  if (fallbackMaxChanges < 0) return bad("fallbackMaxChanges", "must be >= 0");
  if (fallbackShadingChanges < -1)
    return bad("fallbackShadingChanges", "must be >= -1 (-1: every change counts), got " +
                                             std::to_string(fallbackShadingChanges));
  if (simpleSurfaceChanges < 2 || simpleSurfaceChanges > 64)
    return bad("simpleSurfaceChanges", "must be from 2 to 64, got " + std::to_string(simpleSurfaceChanges));
  if (!(probeLcShare >= 0 && probeLcShare <= 1)) return bad("probeLcShare", "must be from 0 to 1");
  if (neighbourDirections < 0 || neighbourDirections > 32)
    return bad("neighbourDirections", "must be from 0 to 32 (directions / 2: every direction), got " +
                                          std::to_string(neighbourDirections));
  if (crossingFillReach < 0 || crossingFillReach > 256)
    return bad("crossingFillReach", "must be from 0 to 256, got " + std::to_string(crossingFillReach));
  if (downsample < 1 || downsample > 64) return bad("downsample", "must be from 1 to 64, got " + std::to_string(downsample));
  if (threads < 0) return bad("threads", "must be >= 0");
  if (tileSize < 1) return bad("tileSize", "must be >= 1");
  if (batchSize < 1) return bad("batchSize", "must be >= 1");
  return Status::Ok();
}

}  // namespace dcm
