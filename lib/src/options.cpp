#include <array>
#include <cmath>
#include <iterator>
#include <optional>
#include <string>
#include <utility>

#include "dcm/options.h"
#include "dcm/option_names.h"
#include "dcm/reconstructor.h"

namespace dcm {

ReconstructionOptions ReconstructionOptions::Guo() {
  ReconstructionOptions o;
  // Every regime alike: the paper has one.
  o.elementaryBlock = 8;  // Guo's and the paper's elementary blocks
  o.contrastThreshold = 0.06f;
  o.contrastMetric = ContrastMetric::kMitchell;
  o.directions = 8;
  o.objectTest = ObjectTest::kObjectId;
  o.thinObjects = ThinObjectTest::kOff;
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
  o.thinObjects = ThinObjectTest::kNoneMatches;
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
  if (elementaryBlock && (!IsPowerOfTwo(*elementaryBlock) || *elementaryBlock > 256))
    return bad("elementaryBlock", "must be a power of two from 1 to 256, got " + std::to_string(*elementaryBlock));
  const int block = LargestElementaryBlock(*this);  // unset: a noisy regime's smaller block is raised to minBlock
  if (!IsPowerOfTwo(minBlock) || minBlock > block)
    return bad("minBlock", "must be a power of two from 1 to elementaryBlock (" + std::to_string(block) +
                               "), got " + std::to_string(minBlock));
  if (contrastThreshold && (!(*contrastThreshold >= 0) || !std::isfinite(*contrastThreshold)))
    return bad("contrastThreshold", "must be a finite number >= 0");
  if (directions && (*directions < 1 || *directions > 64))
    return bad("directions", "must be from 1 to 64, got " + std::to_string(*directions));
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
  // TBB crashes on absurd arenas; the CLI's --threads has the same bound.
  if (threads < 0 || threads > 1024) return bad("threads", "must be from 0 (all cores) to 1024, got " + std::to_string(threads));
  if (tileSize < 1) return bad("tileSize", "must be >= 1");
  if (batchSize < 1) return bad("batchSize", "must be >= 1");
  return Status::Ok();
}

namespace {
using Options = ReconstructionOptions;

/// A named option: a plain field, or one with a regime-aware default
/// (`regime`), which a sentinel value unsets (SetIntOption, SetFloatOption).
template <typename T>
struct NamedField {
  std::string_view name;
  T Options::*member = nullptr;
  std::optional<T> Options::*regime = nullptr;
};

constexpr NamedField<int> kIntOptions[] = {
    {"elementary_block", nullptr, &Options::elementaryBlock},
    {"min_block", &Options::minBlock},
    {"directions", nullptr, &Options::directions},
    {"fallback_max_changes", &Options::fallbackMaxChanges},
    {"fallback_shading_changes", &Options::fallbackShadingChanges},
    {"simple_surface_changes", &Options::simpleSurfaceChanges},
    {"neighbour_directions", &Options::neighbourDirections},
    {"crossing_fill_reach", &Options::crossingFillReach},
    {"downsample", &Options::downsample},
    {"threads", &Options::threads},
    {"tile_size", &Options::tileSize},
    {"batch_size", &Options::batchSize},
};
constexpr NamedField<float> kFloatOptions[] = {
    {"contrast_threshold", nullptr, &Options::contrastThreshold},
    {"noise_significance", &Options::noiseSignificance},
    {"probe_lc_share", &Options::probeLcShare},
    {"crease_angle", &Options::creaseAngle},
};
constexpr NamedField<bool> kBoolOptions[] = {
    {"surface_aware", &Options::surfaceAware},
    {"texture_split", &Options::textureSplit},
    {"adaptive_borders", &Options::adaptiveBorders},
    {"zero_order_test", &Options::zeroOrderTest},
    {"gradient_blocks_simple", &Options::gradientBlocksSimple},
    {"first_order_test", &Options::firstOrderTest},
    {"first_order_from_guides", &Options::firstOrderFromGuides},
    {"lazy_evaluation", &Options::lazyEvaluation},
    {"fallback", &Options::fallback},
    {"fallback_filled_borders", &Options::fallbackFilledBorders},
    {"finest_centre_probe", &Options::finestCentreProbe},
    {"checkerboard", &Options::checkerboard},
    {"full_evaluation", &Options::fullEvaluation},
    {"denoise_samples", &Options::denoiseSamples},
};
constexpr std::string_view kStringOptions[] = {
    "method", "object_test", "thin_objects", "contrast_metric", "smooth_refinement",
};
/// The value of a regime-aware string option that unsets it.
constexpr std::string_view kRegimeDefault = "default";

template <typename T, size_t N>
const NamedField<T>* Find(const NamedField<T> (&table)[N], std::string_view name) {
  for (const auto& e : table)
    if (name == e.name) return &e;
  return nullptr;
}

/// Sets the option `e` of `o`; `unset` restores a regime-aware one's default.
template <typename T>
void Assign(const NamedField<T>& e, Options& o, T value, bool unset) {
  if (!e.regime) o.*e.member = value;
  else if (unset) (o.*e.regime).reset();
  else o.*e.regime = value;
}

/// The value of the option `e` of `o`; `unset` for a regime-aware one without a value.
template <typename T>
T Read(const NamedField<T>& e, const Options& o, T unset) {
  return e.regime ? (o.*e.regime).value_or(unset) : o.*e.member;
}

/// A string option with a regime-aware default: kRegimeDefault unsets it.
template <typename E>
Status ParseRegime(std::string_view value, std::optional<E>* out) {
  if (value == kRegimeDefault) {
    out->reset();
    return Status::Ok();
  }
  E e;
  DCM_RETURN_IF_ERROR(Parse(value, &e));
  *out = e;
  return Status::Ok();
}
}  // namespace

OptionKind KindOfOption(std::string_view name) {
  for (std::string_view s : kStringOptions)
    if (name == s) return OptionKind::kString;
  if (Find(kIntOptions, name)) return OptionKind::kInt;
  if (Find(kFloatOptions, name)) return OptionKind::kFloat;
  if (Find(kBoolOptions, name)) return OptionKind::kBool;
  return OptionKind::kUnknown;
}

bool SetIntOption(Options& o, std::string_view name, int value) {
  const NamedField<int>* e = Find(kIntOptions, name);
  if (e) Assign(*e, o, value, value == 0);
  return e != nullptr;
}

bool SetFloatOption(Options& o, std::string_view name, float value) {
  const NamedField<float>* e = Find(kFloatOptions, name);
  if (e) Assign(*e, o, value, value < 0.f);
  return e != nullptr;
}

bool GetIntOption(const Options& o, std::string_view name, int* value) {
  const NamedField<int>* e = Find(kIntOptions, name);
  if (e) *value = Read(*e, o, 0);
  return e != nullptr;
}

bool GetFloatOption(const Options& o, std::string_view name, float* value) {
  const NamedField<float>* e = Find(kFloatOptions, name);
  if (e) *value = Read(*e, o, -1.f);
  return e != nullptr;
}

bool* FindBoolOption(Options& o, std::string_view name) {
  const NamedField<bool>* e = Find(kBoolOptions, name);
  return e ? &(o.*e->member) : nullptr;
}

Status ResetOption(Options* o, std::string_view name) {
  if (name == "thin_objects") return o->thinObjects.reset(), Status::Ok();
  if (name == "contrast_metric") return o->contrastMetric.reset(), Status::Ok();
  if (const NamedField<int>* e = Find(kIntOptions, name); e && e->regime) return Assign(*e, *o, 0, true), Status::Ok();
  if (const NamedField<float>* e = Find(kFloatOptions, name); e && e->regime)
    return Assign(*e, *o, 0.f, true), Status::Ok();
  return Status::Error("option " + std::string(name) + ": has no default that depends on the regime");
}

Status SetStringOption(Options* o, std::string_view name, std::string_view value) {
  if (name == "method") {
    if (value == "dcm") *o = Options{};
    else if (value == "paper") *o = Options::Paper();
    else if (value == "guo") *o = Options::Guo();
    else return Status::Error("method: unknown value '" + std::string(value) + "' (valid: dcm, paper, guo)");
    return Status::Ok();
  }
  if (name == "object_test") return Parse(value, &o->objectTest);
  if (name == "thin_objects") return ParseRegime(value, &o->thinObjects);
  if (name == "contrast_metric") return ParseRegime(value, &o->contrastMetric);
  if (name == "smooth_refinement") return Parse(value, &o->smoothRefinement);
  return Status::Error("unknown string option '" + std::string(name) + "'");
}

std::vector<std::string_view> OptionNames(OptionKind kind) {
  std::vector<std::string_view> names;
  switch (kind) {
    case OptionKind::kString: names.assign(std::begin(kStringOptions), std::end(kStringOptions)); break;
    case OptionKind::kInt: for (const auto& e : kIntOptions) names.push_back(e.name); break;
    case OptionKind::kFloat: for (const auto& e : kFloatOptions) names.push_back(e.name); break;
    case OptionKind::kBool: for (const auto& e : kBoolOptions) names.push_back(e.name); break;
    case OptionKind::kUnknown: break;
  }
  return names;
}

}  // namespace dcm
