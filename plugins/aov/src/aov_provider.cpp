// The EXR AOV provider: channel roles from presets and mappings, dense and
// sparse (round-trip) samples, Cryptomatte IDs, texture lookups.
#include "dcm/aov/aov_provider.h"

#include <OpenImageIO/strutil.h>
#include <OpenImageIO/texture.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <set>

#include "dcm/noise_estimate.h"
#include "exr_channels.h"

namespace dcm::aov {

using detail::ChannelSet;
using detail::CryptoLayer;
using detail::Quote;

namespace {

constexpr std::array<std::string_view, kRoleCount> kRoleNames = {
    "id",   "shader", "u",    "v",    "tau.R", "tau.G", "tau.B", "N.X",   "N.Y",   "N.Z", "shadow", "highlight", "albedo.R", "albedo.G", "albedo.B", "Li.R",  "Li.G",  "Li.B",
    "Lc.R", "Lc.G",   "Lc.B", "Lr.R", "Lr.G", "Lr.B", "L.R",  "L.G",   "L.B",   "var.R", "var.G", "var.B", "mask"};

constexpr const char* kComp[3] = {"R", "G", "B"};

/// First role of each RGB group.
constexpr Role kNormal = Role::kNX;
constexpr Role kTau = Role::kTauR, kLi = Role::kLiR, kLc = Role::kLcR, kL = Role::kLR,
               kVar = Role::kVarR, kAlbedo = Role::kAlbedoR, kLr = Role::kLrR;

Role Comp(Role first, int c) { return Role(int(first) + c); }

bool IsSampleRole(Role r) { return r >= Role::kLiR && r <= Role::kMask; }

/// A role's source: a Cryptomatte layer, or a sum of products of channels.
struct Expr {
  std::string crypto;
  std::vector<std::vector<std::string>> terms;

  std::string Text() const {
    if (!crypto.empty()) return "cryptomatte:" + crypto;
    std::string s;
    for (size_t t = 0; t < terms.size(); ++t) {
      if (t) s += "+";
      for (size_t f = 0; f < terms[t].size(); ++f) s += (f ? "*" : "") + terms[t][f];
    }
    return s;
  }
  bool single() const { return crypto.empty() && terms.size() == 1 && terms[0].size() == 1; }
};

Status ParseExpr(std::string_view text, Expr* e) {
  *e = Expr{};
  std::string t(OIIO::Strutil::strip(text));
  if (t.empty()) return Status::Error("empty channel expression");
  if (OIIO::Strutil::starts_with(t, "cryptomatte:")) {
    e->crypto = t.substr(12);
    if (e->crypto.empty()) return Status::Error("cryptomatte: needs a layer name");
    return Status::Ok();
  }
  for (const auto& term : OIIO::Strutil::splitsv(t, "+")) {
    std::vector<std::string> factors;
    for (const auto& f : OIIO::Strutil::splitsv(term, "*")) {
      std::string name(OIIO::Strutil::strip(f));
      if (name.empty()) return Status::Error("malformed channel expression '" + t + "'");
      factors.push_back(name);
    }
    if (factors.empty()) return Status::Error("malformed channel expression '" + t + "'");
    e->terms.push_back(std::move(factors));
  }
  if (e->terms.empty()) return Status::Error("malformed channel expression '" + t + "'");
  return Status::Ok();
}

Expr Channel(const std::string& name) {
  Expr e;
  e.terms = {{name}};
  return e;
}

using RoleExprs = std::array<std::optional<Expr>, kRoleCount>;

/// Checks that every channel of `e` exists in `set`.
Status CheckExpr(Role role, const Expr& e, const ChannelSet& set) {
  if (!e.crypto.empty()) {
    if (role != Role::kObjectId && role != Role::kShaderId)
      return Status::Error("role " + std::string(RoleName(role)) +
                           ": a Cryptomatte layer can only give IDs");
    const CryptoLayer* layer = nullptr;
    return set.FindCrypto(e.crypto, &layer);
  }
  if ((role == Role::kObjectId || role == Role::kShaderId) && !e.single())
    return Status::Error("role " + std::string(RoleName(role)) + ": an ID must be one channel, not '" +
                         e.Text() + "'");
  for (const auto& term : e.terms)
    for (const auto& name : term)
      if (!set.Has(name))
        return Status::Error("role " + std::string(RoleName(role)) + ": no channel " + Quote(name) +
                             " in the input; channels: " + set.Describe());
  return Status::Ok();
}

/// Blender view layers whose name starts with these hold a guide
/// (examples/blender/make_and_render.py --shadow-guide, --highlight-guide):
/// light visibility in their Combined pass, direct glossy light in their
/// GlossDir pass. They are never the layer of the passes.
constexpr const char* kShadowGuideLayer = "ShadowGuide";
constexpr const char* kHighlightGuideLayer = "HighlightGuide";

bool IsGuideLayerChannel(const std::string& name) {
  return OIIO::Strutil::starts_with(name, kShadowGuideLayer) || OIIO::Strutil::starts_with(name, kHighlightGuideLayer);
}

/// The Blender view-layer prefix ("ViewLayer." or "") of the passes in `set`.
Status DetectBlenderLayer(const ChannelSet& set, const std::string& wanted, std::string* prefix,
                          std::vector<std::string>* notes) {
  static const char* kPasses[] = {"Combined.R", "DiffCol.R", "DiffDir.R", "IndexOB.X",
                                  "IndexMA.X",  "UV.U",      "Emit.R",    "GlossDir.R"};
  std::set<std::string> layers;
  bool bare = false;
  for (const auto& name : set.Names()) {
    for (const char* pass : kPasses) {
      const std::string p(pass);
      if (name == p) bare = true;
      if (name.size() > p.size() + 1 && OIIO::Strutil::ends_with(name, "." + p) && !IsGuideLayerChannel(name))
        layers.insert(name.substr(0, name.size() - p.size() - 1));
    }
  }
  if (!wanted.empty()) {
    if (!layers.count(wanted))
      return Status::Error("no Blender view layer " + Quote(wanted) + " in " + set.Paths() +
                           "; channels: " + set.Describe());
    *prefix = wanted + ".";
    return Status::Ok();
  }
  // Cryptomatte channels ("ViewLayer.CryptoObject00.R") are not passes.
  if (layers.size() > 1) {
    std::string names;
    for (const auto& l : layers) names += (names.empty() ? "" : ", ") + Quote(l);
    return Status::Error("several Blender view layers in " + set.Paths() + " (" + names +
                         "): choose one with --layer");
  }
  if (layers.size() == 1) {
    *prefix = *layers.begin() + ".";
    if (notes) notes->push_back("Blender view layer " + Quote(*layers.begin()));
    return Status::Ok();
  }
  if (bare) {
    *prefix = "";
    return Status::Ok();
  }
  return Status::Error("no Blender passes (Combined, DiffCol, IndexOB, ...) in " + set.Paths() +
                       "; channels: " + set.Describe());
}

/// The role expressions a preset finds in `set` (guide roles or sample roles).
Status PresetExprs(Preset preset, const std::string& viewLayer, const ChannelSet& set,
                   bool samples, RoleExprs* roles, std::vector<std::string>* notes) {
  roles->fill(std::nullopt);
  auto set1 = [&](Role r, const std::string& name) {
    if (set.Has(name)) (*roles)[size_t(r)] = Channel(name);
  };
  auto setRgb = [&](Role first, const std::string& base) {
    for (int c = 0; c < 3; ++c) set1(Comp(first, c), base + kComp[c]);
  };
  if (preset == Preset::kGeneric) {
    if (!samples) {
      set1(Role::kObjectId, "id");
      set1(Role::kShaderId, "shader");
      set1(Role::kU, "u");
      set1(Role::kV, "v");
      setRgb(kTau, "tau.");
      for (int c = 0; c < 3; ++c) set1(Comp(kNormal, c), std::string("N.") + "XYZ"[c]);
      set1(Role::kShadow, "shadow");
      set1(Role::kHighlight, "highlight");
      setRgb(kAlbedo, "albedo.");
    }
    setRgb(kLi, "Li.");
    setRgb(kLc, "Lc.");
    setRgb(kLr, "Lr.");
    setRgb(kL, "");
    setRgb(kVar, "var.");
    if (samples) set1(Role::kMask, "mask");
    return Status::Ok();
  }
  // Blender Cycles.
  std::string p;
  Status st = DetectBlenderLayer(set, viewLayer, &p, samples ? nullptr : notes);
  if (!st.ok()) {
    // A samples file may hold only what the renderer wrote for the round.
    if (!samples) return st;
    p = viewLayer.empty() ? "" : viewLayer + ".";
  }
  if (!samples) {
    // Cryptomatte first: Blender's IndexOB/IndexMA are 0 unless pass indices
    // were set by hand, while Cryptomatte always tells objects apart.
    auto crypto = [&](Role r, const char* suffix, const std::string& index) {
      for (const auto& layer : set.Crypto()) {
        if (OIIO::Strutil::ends_with(layer.name, suffix) &&
            (p.empty() || OIIO::Strutil::starts_with(layer.name, p))) {
          Expr e;
          e.crypto = layer.name;
          (*roles)[size_t(r)] = e;
          return;
        }
      }
      set1(r, p + index);
    };
    crypto(Role::kObjectId, "CryptoObject", "IndexOB.X");
    crypto(Role::kShaderId, "CryptoMaterial", "IndexMA.X");
    set1(Role::kU, p + "UV.U");
    set1(Role::kV, p + "UV.V");
    setRgb(kTau, p + "DiffCol.");
    setRgb(kAlbedo, p + "Denoising Albedo.");
    for (int c = 0; c < 3; ++c) set1(Comp(kNormal, c), p + "Normal." + "XYZ"[c]);
    // The guides: the first ShadowGuide* layer's Combined and the first
    // HighlightGuide* layer's GlossDir, R + G + B each.
    auto guide = [&](Role r, const char* layer, const std::string& pass) {
      for (const auto& name : set.Names()) {
        if (!OIIO::Strutil::starts_with(name, layer) || !OIIO::Strutil::ends_with(name, pass + "R")) continue;
        const std::string base = name.substr(0, name.size() - 1);
        if (!set.Has(base + "G") || !set.Has(base + "B")) continue;
        Expr e;
        e.terms = {{base + "R"}, {base + "G"}, {base + "B"}};
        (*roles)[size_t(r)] = e;
        return;
      }
    };
    guide(Role::kShadow, kShadowGuideLayer, ".Combined.");
    guide(Role::kHighlight, kHighlightGuideLayer, ".GlossDir.");
  }
  setRgb(kL, p + "Combined.");
  for (int c = 0; c < 3; ++c) {
    const std::string comp = kComp[c];
    Expr li;
    for (const char* pass : {"DiffDir.", "DiffInd."})
      if (set.Has(p + pass + comp)) li.terms.push_back({p + pass + comp});
    if (!li.terms.empty()) (*roles)[size_t(Comp(kLi, c))] = li;
    // What a mirror reflects of the surfaces it shows. Light through glass
    // stays in L_c: through a glass ball it has edges as sharp as the texture
    // (the contact shadow under it, docs/NOISE.md).
    if (set.Has(p + "GlossCol." + comp) && set.Has(p + "GlossInd." + comp)) {
      Expr lr;
      lr.terms.push_back({p + "GlossCol." + comp, p + "GlossInd." + comp});
      (*roles)[size_t(Comp(kLr, c))] = lr;
    }
    // Without Combined, L_c is the sum of what Blender's compositor adds to
    // the diffuse: Gloss = GlossCol*(GlossDir+GlossInd), likewise Trans, then
    // Volume, Emit and Env. With Combined, L_c = Combined - L_i*tau (below).
    if (!set.Has(p + "Combined." + comp)) {
      Expr lc;
      for (const char* kind : {"Gloss", "Trans"})
        for (const char* part : {"Dir.", "Ind."})
          if (set.Has(p + kind + "Col." + comp) && set.Has(p + kind + part + comp))
            lc.terms.push_back({p + kind + "Col." + comp, p + kind + part + comp});
      for (const char* pass : {"VolumeDir.", "VolumeInd.", "Emit.", "Env."})
        if (set.Has(p + pass + comp)) lc.terms.push_back({p + pass + comp});
      if (!lc.terms.empty()) (*roles)[size_t(Comp(kLc, c))] = lc;
    }
  }
  if (samples) set1(Role::kMask, "mask");
  return Status::Ok();
}

/// Applies the --map overrides of one kind (guide or sample roles).
Status ApplyMappings(const std::vector<Mapping>& maps, const ChannelSet& set, bool samples,
                     RoleExprs* roles) {
  for (const auto& m : maps) {
    if (IsSampleRole(m.role) != samples) continue;
    Expr e;
    Status st = ParseExpr(m.expression, &e);
    if (!st.ok()) return Status::Error("--map " + std::string(RoleName(m.role)) + ": " + st.message());
    DCM_RETURN_IF_ERROR(CheckExpr(m.role, e, set));
    (*roles)[size_t(m.role)] = e;
  }
  return Status::Ok();
}

/// True when the three roles of an RGB group are present; error when only some are.
Status RgbPresent(const RoleExprs& roles, Role first, const ChannelSet& set, bool* present) {
  int n = 0;
  for (int c = 0; c < 3; ++c) n += roles[size_t(Comp(first, c))].has_value();
  if (n != 0 && n != 3) {
    std::string have, miss;
    for (int c = 0; c < 3; ++c) {
      std::string& list = roles[size_t(Comp(first, c))] ? have : miss;
      list += (list.empty() ? "" : ", ") + std::string(RoleName(Comp(first, c)));
    }
    return Status::Error("incomplete colour role in " + set.Paths() + ": " + have + " found but not " + miss);
  }
  *present = n == 3;
  return Status::Ok();
}

std::string RgbText(const RoleExprs& roles, Role first) {
  std::string s;
  for (int c = 0; c < 3; ++c) s += (c ? ", " : "") + roles[size_t(Comp(first, c))]->Text();
  return s;
}

/// Evaluates expressions plane by plane, reading each channel once.
class Evaluator {
 public:
  explicit Evaluator(const ChannelSet& set) : set_(set) {}

  Status Plane(const std::string& name, const std::vector<float>** plane) {
    auto it = cache_.find(name);
    if (it == cache_.end()) {
      std::vector<float> p;
      DCM_RETURN_IF_ERROR(set_.ReadFloat(name, &p));
      it = cache_.emplace(name, std::move(p)).first;
    }
    *plane = &it->second;
    return Status::Ok();
  }

  /// out[i] = sum over terms of the product of the term's channels.
  Status Eval(const Expr& e, std::vector<float>* out) {
    out->assign(set_.pixels(), 0.f);
    std::vector<float> term;
    for (size_t t = 0; t < e.terms.size(); ++t) {
      const std::vector<float>* first = nullptr;
      DCM_RETURN_IF_ERROR(Plane(e.terms[t][0], &first));
      term = *first;
      for (size_t f = 1; f < e.terms[t].size(); ++f) {
        const std::vector<float>* p = nullptr;
        DCM_RETURN_IF_ERROR(Plane(e.terms[t][f], &p));
        for (size_t i = 0; i < term.size(); ++i) term[i] *= (*p)[i];
      }
      if (t == 0) {
        out->swap(term);
      } else {
        for (size_t i = 0; i < term.size(); ++i) (*out)[i] += term[i];
      }
    }
    return Status::Ok();
  }

  Status EvalRgb(const RoleExprs& roles, Role first, std::vector<RGB>* out) {
    out->assign(set_.pixels(), RGB{});
    std::vector<float> plane;
    for (int c = 0; c < 3; ++c) {
      DCM_RETURN_IF_ERROR(Eval(*roles[size_t(Comp(first, c))], &plane));
      for (size_t i = 0; i < plane.size(); ++i) (*out)[i][c] = plane[i];
    }
    return Status::Ok();
  }

  /// Counts NaN/Inf and negative values of the channels of `roles` (only where
  /// `mask` is set, when given) and reports them per file and channel.
  Status Report(const RoleExprs& roles, std::initializer_list<Role> groups,
                const std::vector<uint8_t>* mask, std::vector<std::string>* warnings) {
    std::set<std::string> names;
    for (Role first : groups)
      for (int c = 0; c < 3; ++c)
        if (const auto& e = roles[size_t(Comp(first, c))])
          for (const auto& term : e->terms)
            for (const auto& n : term) names.insert(n);
    for (const auto& name : names) {
      const std::vector<float>* p = nullptr;
      DCM_RETURN_IF_ERROR(Plane(name, &p));
      int64_t nonFinite = 0, negative = 0;
      for (size_t i = 0; i < p->size(); ++i) {
        if (mask && !(*mask)[i]) continue;
        const float v = (*p)[i];
        if (!std::isfinite(v)) ++nonFinite;
        else if (v < 0.f) ++negative;
      }
      const std::string where = Quote(set_.Path(set_.Find(name)->file)) + ", channel " + Quote(name);
      if (nonFinite)
        warnings->push_back(where + ": " + std::to_string(nonFinite) +
                            " NaN/Inf values (kept to their pixels, never interpolated)");
      if (negative)
        warnings->push_back(where + ": " + std::to_string(negative) + " negative values (kept)");
    }
    return Status::Ok();
  }

 private:
  const ChannelSet& set_;
  std::map<std::string, std::vector<float>> cache_;
};

float SrgbDecode(float v) {
  if (v <= 0.04045f) return v / 12.92f;
  return std::pow((v + 0.055f) / 1.055f, 2.4f);
}

}  // namespace

std::string_view RoleName(Role role) {
  const int i = int(role);
  return i >= 0 && i < kRoleCount ? kRoleNames[size_t(i)] : std::string_view("?");
}

Status ParseRole(std::string_view name, Role* role) {
  for (int i = 0; i < kRoleCount; ++i) {
    if (kRoleNames[size_t(i)] == name) {
      *role = Role(i);
      return Status::Ok();
    }
  }
  std::string all;
  for (auto n : kRoleNames) all += (all.empty() ? "" : ", ") + std::string(n);
  return Status::Error("unknown role '" + std::string(name) + "' (roles: " + all +
                       "; tau, albedo, Li, Lc, Lr, L, var map all three components)");
}

Status ParsePreset(std::string_view name, Preset* preset) {
  if (name == "generic") *preset = Preset::kGeneric;
  else if (name == "blender") *preset = Preset::kBlender;
  else return Status::Error("unknown preset '" + std::string(name) + "' (blender, generic)");
  return Status::Ok();
}

Status ParseMapping(std::string_view text, std::vector<Mapping>* out) {
  const size_t eq = text.find('=');
  if (eq == std::string_view::npos || eq == 0 || eq + 1 == text.size())
    return Status::Error("--map '" + std::string(text) + "': expected ROLE=CHANNEL");
  const std::string role(OIIO::Strutil::strip(text.substr(0, eq)));
  const std::string expr(OIIO::Strutil::strip(text.substr(eq + 1)));
  for (const char* group : {"tau", "albedo", "Li", "Lc", "Lr", "L", "var", "N"}) {
    if (role == group) {
      const bool vector = role == "N";  // components X, Y, Z
      const char* const comps[3] = {vector ? "X" : "R", vector ? "Y" : "G", vector ? "Z" : "B"};
      Role first;
      DCM_RETURN_IF_ERROR(ParseRole(role + "." + comps[0], &first));
      for (int c = 0; c < 3; ++c) {
        // "tau=albedo" -> albedo.R, albedo.G, albedo.B (each channel name of
        // a sum or product gets the component).
        Expr e;
        DCM_RETURN_IF_ERROR(ParseExpr(expr, &e));
        if (!e.crypto.empty()) return Status::Error("--map " + role + ": Cryptomatte gives IDs only");
        for (auto& term : e.terms)
          for (auto& f : term) f += std::string(".") + comps[c];
        out->push_back({Comp(first, c), e.Text()});
      }
      return Status::Ok();
    }
  }
  Role r;
  Status st = ParseRole(role, &r);
  if (!st.ok()) return Status::Error("--map '" + std::string(text) + "': " + st.message());
  Expr e;
  st = ParseExpr(expr, &e);
  if (!st.ok()) return Status::Error("--map '" + std::string(text) + "': " + st.message());
  out->push_back({r, expr});
  return Status::Ok();
}

Status ParseTextureBinding(std::string_view text, TextureBinding* out) {
  const size_t eq = text.find('=');
  if (eq == std::string_view::npos || eq == 0 || eq + 1 == text.size())
    return Status::Error("--texture '" + std::string(text) + "': expected SHADER=FILE");
  out->shader = std::string(OIIO::Strutil::strip(text.substr(0, eq)));
  out->file = std::string(text.substr(eq + 1));
  return Status::Ok();
}

struct AovProvider::Data {
  detail::ImageWindows windows;  ///< the engine's image is the data window
  int width() const { return windows.data.width(); }
  int height() const { return windows.data.height(); }
  ProviderCapabilities caps;
  bool dense = true;
  std::vector<uint32_t> objectId, shaderId;
  std::vector<RGB> tau, L, Li, Lc, var;
  std::vector<RGB> albedo;  ///< Role::kAlbedoR..B; empty: none
  /// With the split and an albedo: 1 where tau is the albedo now
  /// (SplitThroughMirrors); empty: nowhere.
  std::vector<uint8_t> throughMirror;
  /// tau as the inputs give it, where throughMirror is set: L = L_i tau + L_c
  /// of an input without a beauty.
  std::vector<RGB> inputTau;
  std::vector<Vec3f> normal;
  /// Sparse mode: where a sample was read, 1 + the index of the last
  /// samples file that holds it (the one whose values the pixel has); 0 elsewhere.
  std::vector<uint32_t> have;
  int64_t haveCount = 0;
  std::vector<std::string> notes, warnings, sampleChannels;
  std::vector<std::string> beautyChannels;  ///< AovProvider::BeautyChannels
  std::vector<std::string> idChannels;      ///< AovProvider::IdChannels
  std::vector<std::string> maskChannels;    ///< AovProvider::MaskChannels
  AovProvider::NoiseInfo noise;
};

namespace {

using Data = AovProvider::Data;

/// Every channel the expressions of `roles` read (of a Cryptomatte layer: its
/// rank-0 IDs and every coverage channel), for ChannelSet::Want.
std::vector<std::string> ChannelsOf(const ChannelSet& set, const RoleExprs& roles) {
  std::vector<std::string> names;
  for (const auto& e : roles) {
    if (!e) continue;
    if (!e->crypto.empty()) {
      const CryptoLayer* layer = nullptr;
      if (set.FindCrypto(e->crypto, &layer).ok()) {
        names.push_back(layer->channel);
        names.insert(names.end(), layer->coverage.begin(), layer->coverage.end());
      }
      continue;
    }
    for (const auto& term : e->terms) names.insert(names.end(), term.begin(), term.end());
  }
  return names;
}

Status LoadId(const ChannelSet& set, const Expr& e, std::vector<uint32_t>* ids) {
  if (!e.crypto.empty()) {
    const CryptoLayer* layer = nullptr;
    DCM_RETURN_IF_ERROR(set.FindCrypto(e.crypto, &layer));
    return set.ReadCrypto(*layer, ids);
  }
  return set.ReadId(e.terms[0][0], ids);
}

std::string IdNote(const ChannelSet& set, const char* what, const Expr& e) {
  if (!e.crypto.empty()) {
    const CryptoLayer* layer = nullptr;
    if (set.FindCrypto(e.crypto, &layer).ok())
      return std::string(what) + ": Cryptomatte layer " + Quote(layer->name) + " (rank-0 channel " +
             Quote(layer->channel) + ", " + std::to_string(layer->manifest.size()) +
             " names in the manifest)";
  }
  return std::string(what) + ": channel " + Quote(e.Text());
}

/// A binary guide folded into the IDs: where its value exceeds `level`, the
/// IDs are XORed with `bit`, so the pixels above and below the level of one
/// object and shader become different surfaces. An edge of the guide is then
/// a surface change, and a region thinner than the lattice is found like a
/// thin object. Without IDs the guide alone gives them.
struct FoldedGuide {
  const char* what;   ///< "shadow guide"
  float level;        ///< above: the marked side
  uint32_t bit;       ///< XORed into the IDs of the marked pixels
  const char* marked; ///< "lit"
  const char* effect; ///< how the note ends
};

Status FoldGuide(const FoldedGuide& f, const ChannelSet& set, Evaluator& eval, const Expr& e, Data* d) {
  std::vector<float> g;
  DCM_RETURN_IF_ERROR(eval.Eval(e, &g));
  size_t marked = 0;
  for (size_t i = 0; i < g.size(); ++i) {
    if (!std::isfinite(g[i]))
      return Status::Error(std::string(f.what) + " " + Quote(e.Text()) + " in " + set.Paths() +
                           ": not finite at pixel " + d->windows.PixelText(i));
    marked += g[i] > f.level;
  }
  if (d->objectId.empty()) d->objectId.assign(g.size(), 0u);
  for (size_t i = 0; i < g.size(); ++i)
    if (g[i] > f.level) {
      d->objectId[i] ^= f.bit;
      if (!d->shaderId.empty()) d->shaderId[i] ^= f.bit;
    }
  const double percent = 100.0 * double(marked) / double(std::max<size_t>(g.size(), 1));
  char share[32];
  std::snprintf(share, sizeof share, percent < 1 ? "%.2f" : "%.0f", percent);
  d->notes.push_back(std::string(f.what) + ": " + e.Text() + " (" + f.marked + " where > " +
                     OIIO::Strutil::fmt::format("{}", f.level) + ": " + share + " % of the pixels; " + f.effect + ")");
  return Status::Ok();
}

// Constants far from small IDs and from Cryptomatte's float bit patterns'
// common values; a collision would only merge two surfaces.
constexpr FoldedGuide kShadowGuide{"shadow guide", 0.f, 0x9E3779B9u, "lit",
                                   "lit and unlit parts of a surface are different surfaces"};
FoldedGuide HighlightGuide(float level) {
  return {"highlight guide", level, 0x85EBCA6Bu, "a highlight",
          "a highlight and the rest of its surface are different surfaces"};
}

/// tau(u, v) from texture files for the bound shaders.
Status LookupTextures(const ChannelSet& set, const RoleExprs& roles,
                      const std::vector<TextureBinding>& bindings, const std::optional<Expr>& shaderExpr,
                      Data* d) {
  for (Role r : {Role::kU, Role::kV, Role::kShaderId})
    if (!roles[size_t(r)])
      return Status::Error("--texture needs the " + std::string(RoleName(r)) +
                           " role, which is missing; channels: " + set.Describe());
  const CryptoLayer* shaderLayer = nullptr;
  if (!shaderExpr->crypto.empty()) DCM_RETURN_IF_ERROR(set.FindCrypto(shaderExpr->crypto, &shaderLayer));
  Evaluator ev(set);
  std::vector<float> u, v;
  DCM_RETURN_IF_ERROR(ev.Eval(*roles[size_t(Role::kU)], &u));
  DCM_RETURN_IF_ERROR(ev.Eval(*roles[size_t(Role::kV)], &v));
  if (d->tau.empty()) d->tau.assign(set.pixels(), RGB::Gray(1.f));

  std::unique_ptr<OIIO::TextureSystem, void (*)(OIIO::TextureSystem*)> ts(
      OIIO::TextureSystem::create(false), [](OIIO::TextureSystem* t) { OIIO::TextureSystem::destroy(t); });
  OIIO::TextureOpt opt;
  // Point sampling with bilinear interpolation of the finest level: the ID
  // and UV passes are not anti-aliased either (one UV per pixel).
  opt.swrap = opt.twrap = OIIO::TextureOpt::WrapPeriodic;
  opt.interpmode = OIIO::TextureOpt::InterpBilinear;
  opt.mipmode = OIIO::TextureOpt::MipModeNoMIP;
  int64_t badUv = 0;
  for (const auto& b : bindings) {
    uint32_t id = 0;
    bool numeric = !b.shader.empty() && std::all_of(b.shader.begin(), b.shader.end(),
                                                    [](char c) { return c >= '0' && c <= '9'; });
    if (numeric) {
      try {
        id = uint32_t(std::stoul(b.shader));
      } catch (const std::exception&) {
        numeric = false;
      }
    }
    if (!numeric) {
      auto it = shaderLayer ? shaderLayer->manifest.find(b.shader) : decltype(shaderLayer->manifest.end()){};
      if (!shaderLayer || it == shaderLayer->manifest.end())
        return Status::Error("--texture " + b.shader + "=" + b.file + ": " + Quote(b.shader) +
                             " is neither a shader ID nor a material name of the Cryptomatte manifest");
      id = it->second;
    }
    const OIIO::ustring file(b.file);
    OIIO::ImageSpec spec;
    if (!ts->get_imagespec(file, 0, spec))
      return Status::Error("--texture " + b.shader + "=" + b.file + ": cannot read texture " +
                           Quote(b.file) + ": " + ts->geterror());
    const bool srgb = OIIO::Strutil::iequals(spec.get_string_attribute("oiio:ColorSpace"), "sRGB");
    const int nch = std::min(spec.nchannels, 3);
    int64_t used = 0;
    for (size_t i = 0; i < set.pixels(); ++i) {
      if (d->shaderId[i] != id) continue;
      ++used;
      if (!std::isfinite(u[i]) || !std::isfinite(v[i])) {
        ++badUv;
        d->tau[i] = RGB{};
        continue;
      }
      float res[3] = {0, 0, 0};
      // OIIO's t runs down the image; UV's v runs up (Blender, OpenGL).
      if (!ts->texture(file, opt, u[i], 1.f - v[i], 0, 0, 0, 0, nch, res))
        return Status::Error("texture lookup in " + Quote(b.file) + " failed: " + ts->geterror());
      RGB t = nch == 1 ? RGB::Gray(res[0]) : RGB{res[0], res[1], res[2]};
      // An sRGB-encoded 8-bit texture is decoded to linear after filtering.
      if (srgb) t = {SrgbDecode(t.r), SrgbDecode(t.g), SrgbDecode(t.b)};
      d->tau[i] = t;
    }
    d->notes.push_back("tau of shader " + b.shader + " (ID " + std::to_string(id) + ", " +
                       std::to_string(used) + " pixels) from texture " + Quote(b.file) +
                       (srgb ? " (sRGB decoded)" : ""));
  }
  if (badUv)
    d->warnings.push_back(std::to_string(badUv) + " pixels with NaN/Inf UV: tau set to 0 there");
  return Status::Ok();
}

/// Computes L (and Li, Lc with the split) for the pixels where `mask` is set
/// (all when null), from the sample roles of `set`.
Status ComputeSamples(const ChannelSet& set, Evaluator& ev, const RoleExprs& roles, bool split,
                      bool variance, const std::vector<uint8_t>* mask, Data* d) {
  bool hasL = false, hasLi = false, hasLc = false, hasVar = false, hasLr = false;
  DCM_RETURN_IF_ERROR(RgbPresent(roles, kL, set, &hasL));
  DCM_RETURN_IF_ERROR(RgbPresent(roles, kLi, set, &hasLi));
  DCM_RETURN_IF_ERROR(RgbPresent(roles, kLc, set, &hasLc));
  DCM_RETURN_IF_ERROR(RgbPresent(roles, kVar, set, &hasVar));
  const bool mirrors = split && !d->throughMirror.empty();
  if (mirrors) DCM_RETURN_IF_ERROR(RgbPresent(roles, kLr, set, &hasLr));
  std::vector<RGB> L, Li, Lc, Lr, var;
  if (hasL) DCM_RETURN_IF_ERROR(ev.EvalRgb(roles, kL, &L));
  if (hasLi) DCM_RETURN_IF_ERROR(ev.EvalRgb(roles, kLi, &Li));
  if (hasLc) DCM_RETURN_IF_ERROR(ev.EvalRgb(roles, kLc, &Lc));
  if (hasLr) DCM_RETURN_IF_ERROR(ev.EvalRgb(roles, kLr, &Lr));
  if (variance && hasVar) DCM_RETURN_IF_ERROR(ev.EvalRgb(roles, kVar, &var));
  const size_t n = set.pixels();
  for (size_t i = 0; i < n; ++i) {
    if (mask && !(*mask)[i]) continue;
    const RGB t = d->tau.empty() ? RGB::Gray(1.f) : d->tau[i];
    if (mirrors && d->throughMirror[i]) {
      // Through a mirror: the albedo modulates Lr (without it, all of L).
      d->L[i] = hasL ? L[i] : Li[i] * d->inputTau[i] + Lc[i];
      const RGB m = hasLr ? Lr[i] : d->L[i];
      d->Li[i] = RGB{m.r / t.r, m.g / t.g, m.b / t.b};
      d->Lc[i] = d->L[i] - d->Li[i] * t;
    } else if (split) {
      d->Li[i] = Li[i];
      if (hasLc) {
        d->Lc[i] = Lc[i];
        d->L[i] = hasL ? L[i] : Li[i] * t + Lc[i];
      } else {
        d->L[i] = L[i];
        d->Lc[i] = L[i] - Li[i] * t;
      }
    } else {
      d->L[i] = hasL ? L[i] : Li[i] * t + Lc[i];
    }
    if (variance) d->var[i] = var[i];
  }
  return Status::Ok();
}

/// Pixels i and j lie on the same surface for the noise estimates: equal
/// object and shader IDs where the inputs carry them.
bool SameSurface(const Data& d, size_t i, size_t j) {
  return (d.objectId.empty() || d.objectId[i] == d.objectId[j]) &&
         (d.shaderId.empty() || d.shaderId[i] == d.shaderId[j]);
}

/// The residual of pixel (x, y) of `v` against the mean of its finite
/// 4-neighbours on the same surface, and how many there are; false with
/// fewer than two.
bool NeighbourResidual(const Data& d, const std::vector<RGB>& v, int x, int y, RGB* res, int* count) {
  const int W = d.width(), H = d.height();
  const size_t i = size_t(y) * size_t(W) + size_t(x);
  RGB mean;
  *count = 0;
  for (auto [dx, dy] : {std::pair{-1, 0}, {1, 0}, {0, -1}, {0, 1}}) {
    const int nx = x + dx, ny = y + dy;
    if (nx < 0 || ny < 0 || nx >= W || ny >= H) continue;
    const size_t j = size_t(ny) * size_t(W) + size_t(nx);
    if (!SameSurface(d, i, j) || !IsFinite(v[j])) continue;
    mean += v[j];
    ++*count;
  }
  if (*count < 2) return false;
  *res = v[i] - mean * (1.f / float(*count));
  return true;
}

/// Below this a channel of tau is no diffuse colour (SplitThroughMirrors), and
/// an albedo channel is taken as this: a black surface then keeps its values
/// up to a constant factor.
constexpr float kAlbedoFloor = 0.02f;

/// VarianceFromOneRender of `v` with the albedo divided out (at least
/// kAlbedoFloor) and multiplied back in: a texture that `v` shows, also one
/// seen in a mirror, is then no residual that looks like noise. No albedo:
/// `v` as it is.
std::vector<RGB> VarianceWithAlbedoOut(const Data& d, const std::vector<RGB>& v) {
  const int W = d.width(), H = d.height();
  if (d.albedo.empty()) return dcm::VarianceFromOneRender(v, W, H, d.objectId, d.shaderId);
  std::vector<RGB> a(v.size()), q(v.size());
  for (size_t i = 0; i < v.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const float albedo = d.albedo[i][c];
      a[i][c] = std::isfinite(albedo) ? std::max(albedo, kAlbedoFloor) : kAlbedoFloor;
      q[i][c] = v[i][c] / a[i][c];
    }
  std::vector<RGB> var = dcm::VarianceFromOneRender(q, W, H, d.objectId, d.shaderId);
  for (size_t i = 0; i < var.size(); ++i) var[i] = var[i] * a[i] * a[i];
  return var;
}

/// The variance estimate of AovOptions::estimateVariance, in L units: with
/// the texture split, of L_i (the texture divided out; through mirrors the
/// albedo, SplitThroughMirrors) times tau^2 plus of L_c, whose noise hardly
/// correlates with L_i's (0.1 on the tuning room); without it, of L with the
/// albedo divided out where there is one.
std::vector<RGB> EstimateVarianceFromData(const Data& d) {
  const int W = d.width(), H = d.height();
  if (d.Li.empty() || d.Lc.empty() || d.tau.empty()) return VarianceWithAlbedoOut(d, d.L);
  std::vector<RGB> var = dcm::VarianceFromOneRender(d.Li, W, H, d.objectId, d.shaderId);
  const std::vector<RGB> c = dcm::VarianceFromOneRender(d.Lc, W, H, d.objectId, d.shaderId);
  for (size_t i = 0; i < var.size(); ++i) var[i] = var[i] * d.tau[i] * d.tau[i] + c[i];
  return var;
}

/// The texture split through mirrors: on a surface whose tau is below
/// kAlbedoFloor at most of its pixels (no diffuse colour: a mirror, metal,
/// glass, also the sky and black surfaces), tau becomes the albedo (at least
/// kAlbedoFloor per channel) at every pixel, and ComputeSamples makes L_i =
/// Lr / tau (all of L without Lr) and L_c the rest there. Cycles' Denoising
/// Albedo continues through sharp mirrors to the surface they show, so that
/// a reflected texture is re-applied per pixel as a diffuse one is, and the
/// engine interpolates the light the mirror reflects instead; `roles` name
/// the albedo's channels in the note it adds.
void SplitThroughMirrors(const RoleExprs& roles, Data* d) {
  d->throughMirror.clear();
  d->inputTau.clear();
  if (d->albedo.empty() || d->tau.empty()) return;
  auto dark = [&](size_t i) {
    const RGB t = d->tau[i];
    return t.r < kAlbedoFloor && t.g < kAlbedoFloor && t.b < kAlbedoFloor;
  };
  // A surface goes through wholly or not at all: its anti-aliased rim (some
  // diffuse colour of what lies behind) must not interpolate an L_i of
  // another meaning from its interior. Through: most of its pixels are dark.
  std::map<std::pair<uint32_t, uint32_t>, std::pair<int64_t, int64_t>> surfaces;  // (dark, all)
  auto key = [&](size_t i) {
    return std::pair{d->objectId.empty() ? 0u : d->objectId[i], d->shaderId.empty() ? 0u : d->shaderId[i]};
  };
  for (size_t i = 0; i < d->tau.size(); ++i) {
    auto& [darkCount, all] = surfaces[key(i)];
    darkCount += dark(i), ++all;
  }
  d->throughMirror.assign(d->tau.size(), 0);
  d->inputTau = d->tau;
  int64_t count = 0;
  for (size_t i = 0; i < d->tau.size(); ++i) {
    const auto [darkCount, all] = surfaces[key(i)];
    const RGB a = d->albedo[i];
    if (2 * darkCount <= all || !IsFinite(a)) continue;
    d->tau[i] = RGB{std::max(a.r, kAlbedoFloor), std::max(a.g, kAlbedoFloor), std::max(a.b, kAlbedoFloor)};
    d->throughMirror[i] = 1;
    ++count;
  }
  d->notes.push_back("tau through mirrors: " + RgbText(roles, kAlbedo) + " on the surfaces whose tau is below " +
                     OIIO::Strutil::fmt::format("{}", kAlbedoFloor) + " at most pixels (" + std::to_string(count) +
                     " pixels)");
}

/// What the notes say of the albedo that the noise estimate divides out.
std::string AlbedoNote(const Data& d, const RoleExprs& roles) {
  return d.albedo.empty() ? std::string() : ", " + RgbText(roles, kAlbedo) + " divided out";
}

/// The display-referred PSNR that the samples' noise alone would cost
/// (AovOptions::detectNoise): the noise's relative variance is the median over
/// the image's pixels of the squared residual against the same-surface
/// 4-neighbours, in L_i (the split's, the texture divided out), relative to
/// the squared value, over 0.455 (the median of a chi-square of one degree of
/// freedom: a renderer's noise is nearly the same in R, G and B); applied to L
/// through the slope of the sRGB encoding. One median over the image: real
/// detail the guides do not explain (hard shadow edges, aliased geometry) is
/// large at few pixels, noise is at every pixel. +Inf when no pixel shows any.
double NoisePsnrFromData(const Data& d) {
  const int W = d.width(), H = d.height();
  const std::vector<RGB>& v = d.Li;  // the caller's condition: the split, the texture divided out
  std::vector<float> rel;
  rel.reserve(v.size());
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const size_t i = size_t(y) * size_t(W) + size_t(x);
      if (!IsFinite(v[i])) continue;
      const float energy = v[i].r * v[i].r + v[i].g * v[i].g + v[i].b * v[i].b;
      // Black pixels say nothing about a relative noise (and divide by 0).
      if (!(v[i].r + v[i].g + v[i].b > 3e-3f)) continue;
      RGB res;
      int count = 0;
      if (!NeighbourResidual(d, v, x, y, &res, &count)) continue;
      rel.push_back((res.r * res.r + res.g * res.g + res.b * res.b) / (1.f + 1.f / float(count)) / energy);
    }
  if (rel.empty()) return std::numeric_limits<double>::infinity();
  std::nth_element(rel.begin(), rel.begin() + rel.size() / 2, rel.end());
  const double rho2 = rel[rel.size() / 2] / 0.455;
  double sum = 0;
  size_t count = 0;
  for (const RGB& L : d.L) {
    if (!IsFinite(L)) continue;
    for (int c = 0; c < 3; ++c) sum += rho2 * double(SrgbRelativeSlope(L[c])) * SrgbRelativeSlope(L[c]);
    count += 3;
  }
  if (!(sum > 0)) return std::numeric_limits<double>::infinity();
  return -10 * std::log10(sum / double(count));
}

/// Which sample roles `split`/non-split needs; message when they are absent.
Status CheckSampleRoles(const RoleExprs& roles, bool split, bool tau, const ChannelSet& set,
                        const std::string& what) {
  bool hasL = false, hasLi = false, hasLc = false;
  DCM_RETURN_IF_ERROR(RgbPresent(roles, kL, set, &hasL));
  DCM_RETURN_IF_ERROR(RgbPresent(roles, kLi, set, &hasLi));
  DCM_RETURN_IF_ERROR(RgbPresent(roles, kLc, set, &hasLc));
  if (split ? (hasLi && (hasL || hasLc)) : (hasL || (hasLi && hasLc && tau))) return Status::Ok();
  return Status::Error(what + ": no exact samples: need the beauty (L.R/G/B) " +
                       std::string(split ? "with Li.R/G/B, or Li and Lc" : "or Li, Lc and tau") +
                       " (see --preset and --map); channels: " + set.Describe());
}

}  // namespace

AovProvider::AovProvider(std::unique_ptr<Data> data) : d_(std::move(data)) {}
AovProvider::~AovProvider() = default;

Status AovProvider::Open(const std::vector<std::string>& inputs, const AovOptions& options,
                         std::unique_ptr<AovProvider>* out) {
  if (inputs.empty()) return Status::Error("no input files");
  auto d = std::make_unique<Data>();
  ChannelSet guides;
  for (const auto& path : inputs) DCM_RETURN_IF_ERROR(guides.Add(path));
  d->windows = guides.windows();
  if (d->windows.cropped())
    d->notes.push_back("pixels: the " + d->windows.Text() + "; the outputs keep both");
  const size_t n = guides.pixels();

  // Guide roles.
  RoleExprs roles;
  DCM_RETURN_IF_ERROR(PresetExprs(options.preset, options.viewLayer, guides, /*samples=*/false,
                                  &roles, &d->notes));
  DCM_RETURN_IF_ERROR(ApplyMappings(options.mappings, guides, /*samples=*/false, &roles));
  // Dense mode: the sample roles, read from the same files (an error in
  // them is reported below, where they are used).
  RoleExprs sroles;
  Status sampleRolesStatus;
  if (!options.sparse) {
    sampleRolesStatus = PresetExprs(options.preset, options.viewLayer, guides, /*samples=*/true, &sroles, nullptr);
    sroles[size_t(Role::kMask)].reset();
    if (sampleRolesStatus.ok())
      sampleRolesStatus = ApplyMappings(options.mappings, guides, /*samples=*/true, &sroles);
  }
  {
    // The channels the guides and the samples will read: the file is
    // decoded once for all of them.
    std::vector<std::string> wanted = ChannelsOf(guides, roles);
    if (!options.sparse && sampleRolesStatus.ok()) {
      const auto more = ChannelsOf(guides, sroles);
      wanted.insert(wanted.end(), more.begin(), more.end());
    }
    guides.Want(wanted);
  }
  {
    // The beauty's own channel names, for the output's layout: those of the
    // sample roles as they would be read from the inputs.
    RoleExprs lroles;
    if (PresetExprs(options.preset, options.viewLayer, guides, /*samples=*/true, &lroles, nullptr).ok() &&
        ApplyMappings(options.mappings, guides, /*samples=*/true, &lroles).ok()) {
      for (int c = 0; c < 3; ++c) {
        const auto& e = lroles[size_t(Comp(kL, c))];
        if (e && e->crypto.empty() && e->terms.size() == 1 && e->terms[0].size() == 1)
          d->beautyChannels.push_back(e->terms[0][0]);
      }
      if (d->beautyChannels.size() != 3) d->beautyChannels.clear();
    }
  }
  const auto& idExpr = roles[size_t(Role::kObjectId)];
  const auto& shaderExpr = roles[size_t(Role::kShaderId)];
  for (const auto* e : {&idExpr, &shaderExpr})
    if (*e && (*e)->crypto.empty()) d->idChannels.push_back((*e)->terms[0][0]);
  if (idExpr) {
    DCM_RETURN_IF_ERROR(LoadId(guides, *idExpr, &d->objectId));
    d->notes.push_back(IdNote(guides, "object ID", *idExpr));
  }
  if (shaderExpr) {
    DCM_RETURN_IF_ERROR(LoadId(guides, *shaderExpr, &d->shaderId));
    d->notes.push_back(IdNote(guides, "shader ID", *shaderExpr));
  }
  if (!idExpr && shaderExpr) {
    // The engine's surface test keys on the object ID; a shader ID alone
    // serves as the object ID.
    d->objectId = d->shaderId;
    d->shaderId.clear();
    d->notes.push_back("no object IDs: the shader IDs act as object IDs");
  } else if (!idExpr && !roles[size_t(Role::kShadow)] && !roles[size_t(Role::kHighlight)]) {
    d->notes.push_back("no object or shader IDs: the object and thin-object tests are off (contrast only)");
  } else if (!shaderExpr) {
    d->notes.push_back("no shader IDs: surfaces change where the object ID changes");
  }

  Evaluator guideEval(guides);
  if (const auto& shadowExpr = roles[size_t(Role::kShadow)])
    DCM_RETURN_IF_ERROR(FoldGuide(kShadowGuide, guides, guideEval, *shadowExpr, d.get()));
  if (const auto& highlightExpr = roles[size_t(Role::kHighlight)]) {
    if (!(options.highlightLevel >= 0.f) || !std::isfinite(options.highlightLevel))
      return Status::Error("highlight level " + OIIO::Strutil::fmt::format("{}", options.highlightLevel) +
                           ": expected a finite value >= 0");
    DCM_RETURN_IF_ERROR(FoldGuide(HighlightGuide(options.highlightLevel), guides, guideEval, *highlightExpr, d.get()));
  }
  bool hasTau = false;
  DCM_RETURN_IF_ERROR(RgbPresent(roles, kTau, guides, &hasTau));
  if (hasTau) {
    DCM_RETURN_IF_ERROR(guideEval.EvalRgb(roles, kTau, &d->tau));
    d->notes.push_back("tau: " + RgbText(roles, kTau));
    DCM_RETURN_IF_ERROR(guideEval.Report(roles, {kTau}, nullptr, &d->warnings));
  }
  bool hasAlbedo = false;
  DCM_RETURN_IF_ERROR(RgbPresent(roles, kAlbedo, guides, &hasAlbedo));
  if (hasAlbedo) {
    DCM_RETURN_IF_ERROR(guideEval.EvalRgb(roles, kAlbedo, &d->albedo));
    DCM_RETURN_IF_ERROR(guideEval.Report(roles, {kAlbedo}, nullptr, &d->warnings));
  }
  bool hasNormal = false;
  DCM_RETURN_IF_ERROR(RgbPresent(roles, kNormal, guides, &hasNormal));
  if (hasNormal) {
    std::vector<RGB> xyz;
    DCM_RETURN_IF_ERROR(guideEval.EvalRgb(roles, kNormal, &xyz));
    d->normal.resize(xyz.size());
    for (size_t i = 0; i < xyz.size(); ++i) d->normal[i] = {xyz[i].r, xyz[i].g, xyz[i].b};
    d->notes.push_back("normal: " + RgbText(roles, kNormal) + " (creases inside one object are surface changes)");
  }
  if (!options.textures.empty()) {
    DCM_RETURN_IF_ERROR(LookupTextures(guides, roles, options.textures, shaderExpr, d.get()));
    hasTau = true;
  }

  // Sample roles.
  bool split = false;
  if (!options.sparse) {
    DCM_RETURN_IF_ERROR(sampleRolesStatus);
    bool hasLi = false, hasL = false, hasLc = false, hasVar = false;
    DCM_RETURN_IF_ERROR(RgbPresent(sroles, kLi, guides, &hasLi));
    DCM_RETURN_IF_ERROR(RgbPresent(sroles, kL, guides, &hasL));
    DCM_RETURN_IF_ERROR(RgbPresent(sroles, kLc, guides, &hasLc));
    DCM_RETURN_IF_ERROR(RgbPresent(sroles, kVar, guides, &hasVar));
    split = options.split && hasTau && hasLi && (hasL || hasLc);
    if (split) SplitThroughMirrors(roles, d.get());
    DCM_RETURN_IF_ERROR(CheckSampleRoles(sroles, split, hasTau, guides, guides.Paths()));
    d->L.assign(n, RGB{});
    if (split) {
      d->Li.assign(n, RGB{});
      d->Lc.assign(n, RGB{});
    }
    if (hasVar) d->var.assign(n, RGB{});
    Evaluator ev(guides);
    DCM_RETURN_IF_ERROR(ComputeSamples(guides, ev, sroles, split, hasVar, nullptr, d.get()));
    DCM_RETURN_IF_ERROR(ev.Report(sroles, {kL, kLi, kLc, kLr, kVar}, nullptr, &d->warnings));
    if (hasL) d->notes.push_back("L: " + RgbText(sroles, kL));
    if (split) {
      d->notes.push_back("L_i: " + RgbText(sroles, kLi));
      d->notes.push_back(hasLc ? "L_c: " + RgbText(sroles, kLc) : "L_c: L - L_i*tau");
      if (!d->throughMirror.empty()) {
        bool hasLr = false;
        DCM_RETURN_IF_ERROR(RgbPresent(sroles, kLr, guides, &hasLr));
        d->notes.push_back("through mirrors: L_i = " + (hasLr ? RgbText(sroles, kLr) : std::string("L")) +
                           " over tau, L_c = L - L_i*tau");
      }
    }
    if (hasVar) {
      d->notes.push_back("variance: " + RgbText(sroles, kVar));
      d->noise.variance = "channels";
    }
    if (hasVar && (!options.secondRender.empty() || options.estimateVariance))
      return Status::Error("the inputs carry variance (" + RgbText(sroles, kVar) +
                           "): a second render or an estimate from the data would replace it; use one");
    if (!options.secondRender.empty()) {
      // An independent render: the mean of the two, and the variance of that
      // mean from their difference.
      ChannelSet second;
      for (const auto& path : options.secondRender) DCM_RETURN_IF_ERROR(second.Add(path));
      if (!(second.windows() == d->windows))
        return Status::Error("second render " + Quote(options.secondRender[0]) + " is " + second.windows().Text() +
                             ", " + Quote(inputs[0]) + " is " + d->windows.Text());
      RoleExprs roles2;
      DCM_RETURN_IF_ERROR(PresetExprs(options.preset, options.viewLayer, second, /*samples=*/true, &roles2, nullptr));
      roles2[size_t(Role::kMask)].reset();
      DCM_RETURN_IF_ERROR(ApplyMappings(options.mappings, second, /*samples=*/true, &roles2));
      DCM_RETURN_IF_ERROR(CheckSampleRoles(roles2, split, hasTau, second, "second render " + Quote(options.secondRender[0])));
      Data b;
      b.tau = d->tau;
      b.throughMirror = d->throughMirror;
      b.inputTau = d->inputTau;
      b.L.assign(n, RGB{});
      if (split) b.Li.assign(n, RGB{}), b.Lc.assign(n, RGB{});
      second.Want(ChannelsOf(second, roles2));
      Evaluator ev2(second);
      DCM_RETURN_IF_ERROR(ComputeSamples(second, ev2, roles2, split, false, nullptr, &b));
      DCM_RETURN_IF_ERROR(ev2.Report(roles2, {kL, kLi, kLc}, nullptr, &d->warnings));
      std::vector<RGB> diff2(n);
      for (size_t i = 0; i < n; ++i) {
        diff2[i] = HalvesVariance(d->L[i], b.L[i], 1, 1);
        d->L[i] = (d->L[i] + b.L[i]) * 0.5f;
        if (split) {
          d->Li[i] = (d->Li[i] + b.Li[i]) * 0.5f;
          d->Lc[i] = (d->Lc[i] + b.Lc[i]) * 0.5f;
        }
      }
      d->var = dcm::SurfaceWindowRelativeMean(diff2, d->L, d->width(), d->height(), d->objectId, d->shaderId, 2);
      d->noise.variance = "second render";
      d->notes.push_back("samples: the mean of the inputs and the second render " + Quote(options.secondRender[0]) +
                         "; variance from their difference (5x5 window on each surface)");
    } else if (options.estimateVariance) {
      d->var = EstimateVarianceFromData(*d);
      d->noise.variance = "estimated";
      d->notes.push_back("variance: estimated from the data (residual against the 4-neighbours, 5x5 window on "
                         "each surface)" + AlbedoNote(*d, roles));
    } else if (options.detectNoise && !hasVar && !split) {
      // Without the split a texture at the pixel scale would look like noise at most pixels.
      d->notes.push_back("samples: taken as noise-free (no texture split to tell noise from texture; "
                         "--estimate-variance for a noisy render)");
    } else if (options.detectNoise && !hasVar) {
      const double psnr = NoisePsnrFromData(*d);
      d->noise.detectedPsnr = psnr;
      const std::string figure = OIIO::Strutil::fmt::format("{:.1f}", psnr);
      if (psnr < kNoisyPsnr) {
        d->var = EstimateVarianceFromData(*d);
        d->noise.variance = "detected";
        d->notes.push_back("samples: noisy (their noise alone would cost about " + figure +
                           " dB PSNR): variance estimated from the data, as --estimate-variance" +
                           AlbedoNote(*d, roles) + " (--no-detect-noise: take them as noise-free)");
      } else {
        d->notes.push_back("samples: taken as noise-free (their noise, if any, would cost about " + figure +
                           " dB PSNR, above " + OIIO::Strutil::fmt::format("{:.0f}", kNoisyPsnr) + " dB)");
      }
    }
    d->dense = true;
  } else {
    if (!options.secondRender.empty() || options.estimateVariance)
      return Status::Error("a second render and a variance estimate from the data need dense inputs; in the "
                           "sparse round trip the samples carry their variance (var.R/G/B with --map var=...)");
    // Capabilities come from the guides and the options alone, so that they
    // are the same in every round; the samples must then match them.
    split = options.split && hasTau;
    if (split) SplitThroughMirrors(roles, d.get());
    d->dense = false;
    d->L.assign(n, RGB{});
    if (split) {
      d->Li.assign(n, RGB{});
      d->Lc.assign(n, RGB{});
    }
    bool variance = false;
    for (const auto& m : options.mappings) variance |= (m.role == Role::kVarR);
    if (variance) {
      d->var.assign(n, RGB{});
      d->noise.variance = "channels";
    }
    d->have.assign(n, 0);
    for (size_t file = 0; file < options.samples.size(); ++file) {
      const std::string& path = options.samples[file];
      ChannelSet s;
      DCM_RETURN_IF_ERROR(s.Add(path));
      if (!(s.windows() == d->windows))
        return Status::Error("inputs of different resolutions or data windows: samples file " + Quote(path) +
                             " is " + s.windows().Text() + ", " + Quote(inputs[0]) + " is " + d->windows.Text());
      RoleExprs fileRoles;
      DCM_RETURN_IF_ERROR(PresetExprs(options.preset, options.viewLayer, s, true, &fileRoles, nullptr));
      DCM_RETURN_IF_ERROR(ApplyMappings(options.mappings, s, true, &fileRoles));
      if (!fileRoles[size_t(Role::kMask)])
        return Status::Error("samples file " + Quote(path) +
                             ": no mask channel (which pixels were rendered; 'mask' or --map "
                             "mask=CHANNEL); channels: " + s.Describe());
      DCM_RETURN_IF_ERROR(CheckSampleRoles(fileRoles, split, hasTau, s, "samples file " + Quote(path)));
      if (split) {
        bool hasLi = false;
        DCM_RETURN_IF_ERROR(RgbPresent(fileRoles, kLi, s, &hasLi));
        if (!hasLi)
          return Status::Error("samples file " + Quote(path) +
                               ": the guides carry tau, so the samples need L_i (Li.R/G/B, or "
                               "--no-texture-split); channels: " + s.Describe());
      }
      if (variance) {
        bool hasVar = false;
        DCM_RETURN_IF_ERROR(RgbPresent(fileRoles, kVar, s, &hasVar));
        if (!hasVar) return Status::Error("samples file " + Quote(path) + ": no variance channels");
      }
      s.Want(ChannelsOf(s, fileRoles));
      Evaluator ev(s);
      // The names the output gives the beauty and leaves out: the
      // samples' own (the inputs carry no beauty in sparse mode).
      for (const auto& term : fileRoles[size_t(Role::kMask)]->terms)
        for (const auto& name : term)
          if (std::find(d->maskChannels.begin(), d->maskChannels.end(), name) == d->maskChannels.end())
            d->maskChannels.push_back(name);
      if (file == 0 && d->beautyChannels.empty()) {
        for (int c = 0; c < 3; ++c) {
          const auto& e = fileRoles[size_t(Comp(kL, c))];
          if (e && e->crypto.empty() && e->terms.size() == 1 && e->terms[0].size() == 1)
            d->beautyChannels.push_back(e->terms[0][0]);
        }
        if (d->beautyChannels.size() != 3) d->beautyChannels.clear();
      }
      std::vector<float> maskPlane;
      DCM_RETURN_IF_ERROR(ev.Eval(*fileRoles[size_t(Role::kMask)], &maskPlane));
      std::vector<uint8_t> mask(n);
      for (size_t i = 0; i < n; ++i) mask[i] = maskPlane[i] > 0.f ? 1 : 0;
      DCM_RETURN_IF_ERROR(ComputeSamples(s, ev, fileRoles, split, variance, &mask, d.get()));
      DCM_RETURN_IF_ERROR(ev.Report(fileRoles, {kL, kLi, kLc, kLr, kVar}, &mask, &d->warnings));
      int64_t count = 0;
      for (size_t i = 0; i < n; ++i) {
        count += mask[i];
        if (mask[i]) d->have[i] = uint32_t(file + 1);
      }
      d->notes.push_back("samples file " + Quote(path) + ": " + std::to_string(count) + " pixels");
    }
    for (size_t i = 0; i < n; ++i) d->haveCount += d->have[i] != 0;
    d->sampleChannels.clear();
    auto names = [&](const std::string& base) {
      for (int c = 0; c < 3; ++c) d->sampleChannels.push_back(base + kComp[c]);
    };
    if (options.preset == Preset::kGeneric) {
      if (split) {
        names("Li.");
        names("Lc.");
      } else {
        names("");
      }
    } else {
      std::string p = options.viewLayer.empty() ? "" : options.viewLayer + ".";
      if (options.viewLayer.empty()) {
        std::string detected;
        if (DetectBlenderLayer(guides, "", &detected, nullptr).ok()) p = detected;
      }
      names(p + "Combined.");
      if (split) {
        names(p + "DiffDir.");
        names(p + "DiffInd.");
      }
    }
    d->sampleChannels.push_back("mask");
  }
  if (!split && hasTau)
    d->notes.push_back(options.split ? "no L_i: the texture split is off"
                                     : "texture split switched off (--no-texture-split)");
  if (!hasTau) d->notes.push_back("no tau: the texture split is off");

  ProviderCapabilities& c = d->caps;
  c.width = d->width();
  c.height = d->height();
  c.objectId = !d->objectId.empty();
  c.shaderId = !d->shaderId.empty();
  c.texture = split;
  c.splitRadiance = split;
  c.normal = !d->normal.empty();
  c.variance = !d->var.empty();
  // The shadow guide folded into the IDs marks the hard shadows' edges (for
  // a Cycles render, the sun's; renderers with several such lights give one
  // guide of all of them).
  c.hardShadowsGuided = roles[size_t(Role::kShadow)].has_value();
  c.threadSafe = true;
  c.name = "aov:" + inputs[0];
  if (!split) d->tau.clear();
  out->reset(new AovProvider(std::move(d)));
  return Status::Ok();
}

ProviderCapabilities AovProvider::Capabilities() const { return d_->caps; }

Status AovProvider::Guides(const Bounds2i& region, const GuideRequest& what, GuideImage* out) {
  const Bounds2i full{{0, 0}, {d_->width(), d_->height()}};
  if (Intersect(region, full) != region)
    return Status::Error("guides requested outside the image");
  if ((what.objectId && d_->objectId.empty()) || (what.shaderId && d_->shaderId.empty()) ||
      (what.texture && d_->tau.empty()) || (what.normal && d_->normal.empty()))
    return Status::Error("guides requested that the inputs do not carry");
  out->region = region;
  const size_t count = size_t(region.area());
  auto copy = [&](const auto& src, auto* dst) {
    dst->resize(count);
    size_t k = 0;
    for (int y = region.min.y; y < region.max.y; ++y) {
      const size_t row = size_t(y) * size_t(d_->width());
      for (int x = region.min.x; x < region.max.x; ++x) (*dst)[k++] = src[row + size_t(x)];
    }
  };
  out->objectId.clear();
  out->shaderId.clear();
  out->texture.clear();
  out->normal.clear();
  if (what.normal) copy(d_->normal, &out->normal);
  if (what.objectId) copy(d_->objectId, &out->objectId);
  if (what.shaderId) copy(d_->shaderId, &out->shaderId);
  if (what.texture) copy(d_->tau, &out->texture);
  return Status::Ok();
}

Status AovProvider::Evaluate(std::span<const Point2i> pixels, const SampleRequest& what,
                             std::span<ExactSample> out) {
  if (out.size() != pixels.size()) return Status::Error("Evaluate: output size differs from input size");
  if (what.split && d_->Li.empty()) return Status::Error("Evaluate: split requested without L_i");
  if (what.variance && d_->var.empty()) return Status::Error("Evaluate: variance requested without variance");
  int64_t missing = 0;
  for (size_t k = 0; k < pixels.size(); ++k) {
    const Point2i p = pixels[k];
    if (p.x < 0 || p.y < 0 || p.x >= d_->width() || p.y >= d_->height())
      return Status::Error("Evaluate: pixel (" + std::to_string(p.x) + ", " + std::to_string(p.y) +
                           ") outside the image");
    const size_t i = size_t(p.y) * size_t(d_->width()) + size_t(p.x);
    if (!d_->have.empty() && !d_->have[i]) {
      ++missing;
      continue;
    }
    ExactSample& s = out[k];
    s.L = d_->L[i];
    if (what.split) {
      s.Li = d_->Li[i];
      s.Lc = d_->Lc[i];
    }
    if (what.variance) s.variance = d_->var[i];
  }
  if (missing)
    return Status::Pending(std::to_string(missing) + " of " + std::to_string(pixels.size()) +
                           " requested pixels have no sample yet");
  return Status::Ok();
}

int AovProvider::width() const { return d_->width(); }
int AovProvider::height() const { return d_->height(); }
Bounds2i AovProvider::DataWindow() const { return d_->windows.data; }
Bounds2i AovProvider::DisplayWindow() const { return d_->windows.display; }
bool AovProvider::dense() const { return d_->dense; }
bool AovProvider::HasSample(Point2i p) const {
  if (p.x < 0 || p.y < 0 || p.x >= d_->width() || p.y >= d_->height()) return false;
  return d_->have.empty() || d_->have[size_t(p.y) * size_t(d_->width()) + size_t(p.x)] != 0;
}
int AovProvider::SamplesFileOf(Point2i p) const {
  return d_->have.empty() ? -1 : int(d_->have[size_t(p.y) * size_t(d_->width()) + size_t(p.x)]) - 1;
}

int64_t AovProvider::SampleCount() const {
  return d_->have.empty() ? int64_t(d_->width()) * d_->height() : d_->haveCount;
}
const std::vector<RGB>& AovProvider::Beauty() const { return d_->L; }
const std::vector<std::string>& AovProvider::BeautyChannels() const { return d_->beautyChannels; }
const std::vector<std::string>& AovProvider::IdChannels() const { return d_->idChannels; }
const std::vector<std::string>& AovProvider::MaskChannels() const { return d_->maskChannels; }
const std::vector<std::string>& AovProvider::Notes() const { return d_->notes; }
const std::vector<std::string>& AovProvider::Warnings() const { return d_->warnings; }
const AovProvider::NoiseInfo& AovProvider::Noise() const { return d_->noise; }
std::vector<std::string> AovProvider::SampleChannels() const { return d_->sampleChannels; }

}  // namespace dcm::aov
