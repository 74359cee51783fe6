// The AOV provider in-process: presets, mappings, IDs, Cryptomatte, textures,
// sparse samples and bad input.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "dcm/aov/aov_provider.h"
#include "dcm/reconstructor.h"
#include "test_util.h"

namespace dcm::aov::test {
namespace {

using ::testing::HasSubstr;

std::unique_ptr<AovProvider> MustOpen(const std::vector<std::string>& inputs, const AovOptions& o = {}) {
  std::unique_ptr<AovProvider> p;
  Status st = AovProvider::Open(inputs, o, &p);
  EXPECT_TRUE(st.ok()) << st.message();
  return p;
}

Status OpenError(const std::vector<std::string>& inputs, const AovOptions& o = {}) {
  std::unique_ptr<AovProvider> p;
  return AovProvider::Open(inputs, o, &p);
}

ExactSample Sample(AovProvider& p, int x, int y, bool split = false) {
  Point2i px{x, y};
  ExactSample s;
  SampleRequest req;
  req.split = split;
  Status st = p.Evaluate(std::span(&px, 1), req, std::span(&s, 1));
  EXPECT_TRUE(st.ok()) << st.message();
  return s;
}

GuideImage AllGuides(AovProvider& p, GuideRequest req) {
  GuideImage g;
  Status st = p.Guides({{0, 0}, {p.width(), p.height()}}, req, &g);
  EXPECT_TRUE(st.ok()) << st.message();
  return g;
}

TEST(AovProvider, GenericBeautyDense) {
  ScratchDir dir;
  Scene sc{40, 24};
  WriteExr(dir / "in.exr", sc.width, sc.height, sc.GenericChannels(false));
  auto p = MustOpen({dir / "in.exr"});
  ASSERT_TRUE(p);
  const auto caps = p->Capabilities();
  EXPECT_EQ(caps.width, 40);
  EXPECT_EQ(caps.height, 24);
  EXPECT_TRUE(caps.objectId);
  EXPECT_TRUE(caps.shaderId);
  EXPECT_FALSE(caps.texture);
  EXPECT_FALSE(caps.splitRadiance);
  EXPECT_TRUE(caps.threadSafe);
  EXPECT_TRUE(p->dense());
  // Samples are the stored floats, bit for bit.
  for (auto [x, y] : {std::pair{0, 0}, {39, 23}, {17, 13}, {5, 20}})
    EXPECT_EQ(Sample(*p, x, y).L, sc.L(x, y)) << x << "," << y;
  const GuideImage g = AllGuides(*p, {true, true, false});
  ASSERT_EQ(g.objectId.size(), size_t(40 * 24));
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 40; ++x) {
      ASSERT_EQ(g.objectId[size_t(y * 40 + x)], sc.ObjectId(x, y));
      ASSERT_EQ(g.shaderId[size_t(y * 40 + x)], sc.ShaderId(x, y));
    }
  // A sub-region comes back row-major over the region.
  GuideImage sub;
  ASSERT_TRUE(p->Guides({{10, 5}, {13, 7}}, {true, false, false}, &sub).ok());
  ASSERT_EQ(sub.objectId.size(), 6u);
  EXPECT_EQ(sub.objectId[4], sc.ObjectId(11, 6));
  EXPECT_FALSE(p->Guides({{30, 0}, {41, 2}}, {true, false, false}, &sub).ok());
}

TEST(AovProvider, GenericSplitDense) {
  ScratchDir dir;
  Scene sc{32, 32};
  WriteExr(dir / "in.exr", sc.width, sc.height, sc.GenericChannels(true));
  auto p = MustOpen({dir / "in.exr"});
  ASSERT_TRUE(p);
  EXPECT_TRUE(p->Capabilities().splitRadiance);
  EXPECT_TRUE(p->Capabilities().texture);
  const ExactSample s = Sample(*p, 14, 17, true);
  EXPECT_EQ(s.Li, sc.Li(14, 17));
  EXPECT_EQ(s.Lc, sc.Lc(14, 17));
  // Without a beauty channel, L = L_i*tau + L_c computed in float as the scene does.
  EXPECT_EQ(s.L, sc.L(14, 17));
  const GuideImage g = AllGuides(*p, {false, false, true});
  EXPECT_EQ(g.texture[size_t(17 * 32 + 14)], sc.Tau(14, 17));

  // Switching the split off keeps L only.
  AovOptions o;
  o.split = false;
  auto q = MustOpen({dir / "in.exr"}, o);
  EXPECT_FALSE(q->Capabilities().splitRadiance);
  EXPECT_FALSE(q->Capabilities().texture);
  EXPECT_EQ(Sample(*q, 14, 17).L, sc.L(14, 17));
}

TEST(AovProvider, NormalGuides) {
  // Generic N.X/Y/Z, --map N=..., and the Blender Normal pass become the
  // normal guide; an incomplete set is an error naming what is missing.
  ScratchDir dir;
  const Scene sc{16, 8};
  std::vector<TestChannel> ch = sc.GenericChannels(false);
  ch.push_back(Fill("N.X", 16, 8, [](int x, int) { return x < 8 ? 1.f : 0.f; }));
  ch.push_back(Fill("N.Y", 16, 8, [](int x, int) { return x < 8 ? 0.f : 1.f; }));
  ch.push_back(Fill("N.Z", 16, 8, [](int, int y) { return 0.1f * float(y); }));
  WriteExr(dir / "n.exr", 16, 8, ch);
  auto p = MustOpen({dir / "n.exr"});
  ASSERT_TRUE(p);
  EXPECT_TRUE(p->Capabilities().normal);
  GuideRequest req;
  req.normal = true;
  const GuideImage g = AllGuides(*p, req);
  ASSERT_EQ(g.normal.size(), size_t(16 * 8));
  EXPECT_EQ(g.normal[size_t(3 * 16 + 2)].x, 1.f);
  EXPECT_EQ(g.normal[size_t(3 * 16 + 12)].y, 1.f);
  EXPECT_FLOAT_EQ(g.normal[size_t(3 * 16 + 12)].z, 0.3f);

  std::vector<TestChannel> other = sc.GenericChannels(false);
  for (const char* c : {"nrm.X", "nrm.Y", "nrm.Z"}) other.push_back(Fill(c, 16, 8, [](int, int) { return 0.5f; }));
  WriteExr(dir / "m.exr", 16, 8, other);
  AovOptions o;
  ASSERT_TRUE(ParseMapping("N=nrm", &o.mappings).ok());
  auto q = MustOpen({dir / "m.exr"}, o);
  ASSERT_TRUE(q);
  EXPECT_EQ(AllGuides(*q, req).normal[5].y, 0.5f);

  std::vector<TestChannel> partial = sc.GenericChannels(false);
  partial.push_back(Fill("N.X", 16, 8, [](int, int) { return 1.f; }));
  WriteExr(dir / "p.exr", 16, 8, partial);
  const Status st = OpenError({dir / "p.exr"});
  EXPECT_NE(st.message().find("N.X found but not N.Y, N.Z"), std::string::npos) << st.message();
}

TEST(AovProvider, ShadowGuideSplitsLitAndUnlitSurfaces) {
  // Generic "shadow" (> 0: lit) folds into both IDs: a lit and an unlit
  // pixel of one object and shader get different object and shader IDs, two
  // lit (or two unlit) ones keep equal IDs; without IDs the guide gives them.
  ScratchDir dir;
  const Scene sc{16, 8};
  std::vector<TestChannel> ch = sc.GenericChannels(false);
  const auto lit = [](int x, int) { return x == 9 ? 0.f : 0.5f + 0.01f * float(x); };
  ch.push_back(Fill("shadow", 16, 8, lit));
  WriteExr(dir / "s.exr", 16, 8, ch);
  auto p = MustOpen({dir / "s.exr"});
  ASSERT_TRUE(p);
  GuideRequest req;
  req.objectId = req.shaderId = true;
  const GuideImage g = AllGuides(*p, req);
  const auto at = [](int x, int y) { return size_t(y * 16 + x); };
  ASSERT_EQ(sc.ObjectId(8, 7), sc.ObjectId(9, 7));
  ASSERT_EQ(sc.ShaderId(8, 7), sc.ShaderId(9, 7));
  EXPECT_NE(g.objectId[at(8, 7)], g.objectId[at(9, 7)]);
  EXPECT_NE(g.shaderId[at(8, 7)], g.shaderId[at(9, 7)]);
  for (int x = 0; x + 1 < 16; ++x) {
    if (x != 8 && x != 9 && sc.ObjectId(x, 7) == sc.ObjectId(x + 1, 7)) {
      EXPECT_EQ(g.objectId[at(x, 7)], g.objectId[at(x + 1, 7)]) << x;
    }
  }
  bool said = false;
  for (const auto& n : p->Notes()) said |= n.find("shadow guide: shadow") != std::string::npos;
  EXPECT_TRUE(said);
  // The guide shows the hard shadows: no centre probes of smooth blocks.
  EXPECT_TRUE(p->Capabilities().hardShadowsGuided);

  WriteExr(dir / "beauty.exr", 16, 8, {ch[2], ch[3], ch[4], ch.back()});
  auto q = MustOpen({dir / "beauty.exr"});
  ASSERT_TRUE(q);
  EXPECT_TRUE(q->Capabilities().objectId);
  req.shaderId = false;
  const GuideImage h = AllGuides(*q, req);
  EXPECT_NE(h.objectId[at(8, 2)], h.objectId[at(9, 2)]);
  EXPECT_EQ(h.objectId[at(2, 2)], h.objectId[at(12, 2)]);

  // Not finite: an error naming the channel and the pixel.
  ch.back() = Fill("shadow", 16, 8, [](int x, int y) { return x == 3 && y == 5 ? std::nanf("") : 1.f; });
  WriteExr(dir / "nan.exr", 16, 8, ch);
  const Status st = OpenError({dir / "nan.exr"});
  EXPECT_THAT(st.message(), HasSubstr("shadow guide 'shadow'"));
  EXPECT_THAT(st.message(), HasSubstr("(3, 5)"));
}

/// The mean |G - value| over the pixels of an n x n input where `where`
/// holds, reconstructed with the engine's defaults.
template <typename Pred>
double MeanGreenError(const std::string& file, const AovOptions& o, int n, Pred where, float value) {
  auto p = MustOpen({file}, o);
  Reconstruction r;
  const Status st = Reconstruct(*p, ReconstructionOptions{}, &r);
  EXPECT_TRUE(st.ok()) << st.message();
  double sum = 0;
  int count = 0;
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
      if (where(x, y)) sum += std::fabs(r.image[size_t(y * n + x)].g - value), ++count;
  return sum / count;
}

TEST(AovProvider, ShadowGuideFindsShadowsThinnerThanTheLattice) {
  // A lit floor (0.8, one object, one shader) crossed by three thin hard
  // shadows (0.15) of legs, 1-2 pixels wide, as the sun casts on a Cycles
  // floor. Without a guide most of their pixels lie between lattice samples
  // and are interpolated over; with the shadow guide their edges are
  // surface changes. Measured mean error on the shadow pixels: 0.27 without
  // the guide, 0 with it (every such pixel exact or interpolated from its
  // own shadow); 1/10 of the blind error is asked.
  ScratchDir dir;
  constexpr int n = 128;
  const auto inShadow = [](int x, int y) {
    for (int leg : {20, 55, 90})
      if (std::abs(2 * x - y - 2 * leg) <= 2) return true;
    return false;
  };
  std::vector<TestChannel> ch;
  for (const char* c : {"R", "G", "B"})
    ch.push_back(Fill(c, n, n, [&](int x, int y) { return inShadow(x, y) ? 0.15f : 0.8f; }));
  ch.push_back(Fill("id", n, n, [](int, int) { return 1.f; }));
  ch.push_back(Fill("shader", n, n, [](int, int) { return 1.f; }));
  WriteExr(dir / "blind.exr", n, n, ch);
  ch.push_back(Fill("shadow", n, n, [&](int x, int y) { return inShadow(x, y) ? 0.f : 1.f; }));
  WriteExr(dir / "guided.exr", n, n, ch);
  const double blind = MeanGreenError(dir / "blind.exr", {}, n, inShadow, 0.15f);
  const double guided = MeanGreenError(dir / "guided.exr", {}, n, inShadow, 0.15f);
  EXPECT_LT(guided * 10, blind) << "guided " << guided << ", blind " << blind;
}

TEST(AovProvider, HighlightGuideFindsHighlightsSmallerThanTheLattice) {
  // A glossy surface (0.4, one object, one shader) with small sharp
  // highlights (3.0, 3x2 pixels, as a ceiling light makes on a red vase in
  // Cycles) that lie between the lattice lines: no corner, border or probe
  // of a 4x4 block falls on them, so without a guide they are interpolated
  // over (error 2.6). The highlight guide (direct glossy light, R + G + B:
  // 0.6 on the surface, 9 on a highlight) marks them as surfaces of their
  // own, which the thin-object test then evaluates. Measured mean error on
  // the highlight pixels: 2.6 without the guide, 0 with it; 1/10 of the
  // blind error is asked. A level above the guide's highlights (10) marks
  // nothing and changes nothing.
  ScratchDir dir;
  const HighlightScene scene;
  const int n = scene.size;
  const auto inHighlight = HighlightScene::InHighlight;
  std::vector<TestChannel> ch = scene.Channels();
  WriteExr(dir / "blind.exr", n, n, ch);
  ch.push_back(scene.Guide());
  WriteExr(dir / "guided.exr", n, n, ch);
  auto highlightError = [&](const std::string& file, float level) {
    AovOptions o;
    o.highlightLevel = level;
    return MeanGreenError(file, o, n, inHighlight, 3.f);
  };
  const double blind = highlightError(dir / "blind.exr", 1.5f);
  const double guided = highlightError(dir / "guided.exr", 1.5f);
  EXPECT_GT(blind, 1.f) << "the highlights must lie off the lattice for this test to mean anything";
  EXPECT_LT(guided * 10, blind) << "guided " << guided << ", blind " << blind;
  EXPECT_EQ(highlightError(dir / "guided.exr", 10.f), blind);

  // The note says what was marked; a guide that is not finite, or a level
  // that is not a number >= 0, is an error naming it.
  auto p = MustOpen({dir / "guided.exr"});
  bool said = false;
  for (const auto& note : p->Notes()) said |= note.find("highlight guide: highlight (a highlight where > 1.5") != std::string::npos;
  EXPECT_TRUE(said);
  AovOptions bad;
  bad.highlightLevel = -1.f;
  EXPECT_THAT(OpenError({dir / "guided.exr"}, bad).message(), HasSubstr("highlight level -1"));
  ch.back() = Fill("highlight", n, n, [](int x, int y) { return x == 7 && y == 2 ? INFINITY : 0.f; });
  WriteExr(dir / "inf.exr", n, n, ch);
  const Status st = OpenError({dir / "inf.exr"});
  EXPECT_THAT(st.message(), HasSubstr("highlight guide 'highlight'"));
  EXPECT_THAT(st.message(), HasSubstr("(7, 2)"));
}

TEST(AovProvider, SeveralInputFilesAndMissingOptionalRoles) {
  ScratchDir dir;
  Scene sc{16, 16};
  auto all = sc.GenericChannels(false);
  // Beauty in one file, IDs in another; no shader IDs at all.
  WriteExr(dir / "beauty.exr", 16, 16, {all[2], all[3], all[4]});
  WriteExr(dir / "ids.exr", 16, 16, {all[0]});
  auto p = MustOpen({dir / "beauty.exr", dir / "ids.exr"});
  EXPECT_TRUE(p->Capabilities().objectId);
  EXPECT_FALSE(p->Capabilities().shaderId);
  bool said = false;
  for (const auto& n : p->Notes()) said |= n.find("no shader IDs") != std::string::npos;
  EXPECT_TRUE(said);
  // Beauty only: contrast only, and the notes say so.
  auto q = MustOpen({dir / "beauty.exr"});
  EXPECT_FALSE(q->Capabilities().objectId);
  said = false;
  for (const auto& n : q->Notes()) said |= n.find("contrast only") != std::string::npos;
  EXPECT_TRUE(said);
}

/// Blender passes with per-pass values chosen so that the sums are exact.
std::vector<TestChannel> BlenderChannels(const std::string& layer, int w, int h, bool combined,
                                         bool crypto = false) {
  std::vector<TestChannel> ch;
  const std::string p = layer.empty() ? "" : layer + ".";
  auto f = [&](const std::string& name, float base) {
    ch.push_back(Fill(p + name, w, h, [=](int x, int y) { return base + 0.25f * float((x + 2 * y) % 4); }));
  };
  const char* comp[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    const float k = 0.125f * float(c);
    f(std::string("DiffCol.") + comp[c], 0.5f + k);
    f(std::string("DiffDir.") + comp[c], 1.0f + k);
    f(std::string("DiffInd.") + comp[c], 0.25f);
    f(std::string("GlossCol.") + comp[c], 0.5f);
    f(std::string("GlossDir.") + comp[c], 0.5f + k);
    f(std::string("GlossInd.") + comp[c], 0.125f);
    f(std::string("Emit.") + comp[c], 0.0625f);
    f(std::string("Env.") + comp[c], 0.f);
  }
  if (combined) {
    // Combined = DiffCol*(DiffDir+DiffInd) + GlossCol*(GlossDir+GlossInd) + Emit + Env,
    // summed in double and rounded once, as a renderer's own accumulation would.
    for (int c = 0; c < 3; ++c) {
      auto get = [&](const std::string& name, size_t i) {
        for (const auto& t : ch)
          if (t.name == p + name + "." + comp[c]) return double(t.values[i]);
        ADD_FAILURE() << name;
        return 0.0;
      };
      TestChannel t;
      t.name = p + "Combined." + comp[c];
      for (size_t i = 0; i < size_t(w * h); ++i)
        t.values.push_back(float(get("DiffCol", i) * (get("DiffDir", i) + get("DiffInd", i)) +
                                 get("GlossCol", i) * (get("GlossDir", i) + get("GlossInd", i)) +
                                 get("Emit", i) + get("Env", i)));
      ch.push_back(t);
    }
    ch.push_back(Fill(p + "Combined.A", w, h, [](int, int) { return 1.f; }));
  }
  ch.push_back(Fill(p + "IndexOB.X", w, h, [](int x, int) { return x < 5 ? 1.f : 2.f; }));
  ch.push_back(Fill(p + "IndexMA.X", w, h, [](int, int y) { return y < 3 ? 7.f : 8.f; }));
  ch.push_back(Fill(p + "UV.U", w, h, [=](int x, int) { return float(x) / float(w); }));
  ch.push_back(Fill(p + "UV.V", w, h, [=](int, int y) { return float(y) / float(h); }));
  (void)crypto;
  return ch;
}

float Get(const std::vector<TestChannel>& ch, const std::string& name, int i) {
  for (const auto& t : ch)
    if (t.name == name) return t.values[size_t(i)];
  ADD_FAILURE() << "no " << name;
  return 0;
}

TEST(AovProvider, BlenderPresetWithCombined) {
  ScratchDir dir;
  const int w = 12, h = 8;
  auto ch = BlenderChannels("ViewLayer", w, h, true);
  WriteExr(dir / "blender.exr", w, h, ch);
  AovOptions o;
  o.preset = Preset::kBlender;
  auto p = MustOpen({dir / "blender.exr"}, o);
  ASSERT_TRUE(p);
  const auto caps = p->Capabilities();
  EXPECT_TRUE(caps.objectId && caps.shaderId && caps.splitRadiance && caps.texture);
  bool said = false;
  for (const auto& n : p->Notes()) said |= n.find("'ViewLayer'") != std::string::npos;
  EXPECT_TRUE(said) << "the detected view layer is reported";
  const GuideImage g = AllGuides(*p, {true, true, true});
  for (int i : {0, 7, 50, 95}) {
    const int x = i % w, y = i / w;
    const ExactSample s = Sample(*p, x, y, true);
    RGB tau, combined, li;
    const char* comp[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c) {
      tau[c] = Get(ch, std::string("ViewLayer.DiffCol.") + comp[c], i);
      combined[c] = Get(ch, std::string("ViewLayer.Combined.") + comp[c], i);
      li[c] = Get(ch, std::string("ViewLayer.DiffDir.") + comp[c], i) +
              Get(ch, std::string("ViewLayer.DiffInd.") + comp[c], i);
    }
    EXPECT_EQ(g.texture[size_t(i)], tau);          // tau = DiffCol
    EXPECT_EQ(s.Li, li);                           // L_i = DiffDir + DiffInd
    EXPECT_EQ(s.L, combined);                      // L = Combined
    EXPECT_EQ(s.Lc, combined - li * tau);          // L_c = the rest
    // L_i*tau + L_c = Combined up to the two float roundings of the
    // subtraction and the re-addition: 2 ulp of values below 4.
    const RGB back = s.Li * tau + s.Lc;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(back[c], combined[c], 2 * 4 * std::numeric_limits<float>::epsilon());
    EXPECT_EQ(g.objectId[size_t(i)], x < 5 ? 1u : 2u);   // IndexOB
    EXPECT_EQ(g.shaderId[size_t(i)], y < 3 ? 7u : 8u);   // IndexMA
  }
}

TEST(AovProvider, BlenderPresetWithoutCombinedSumsThePasses) {
  ScratchDir dir;
  const int w = 8, h = 8;
  auto ch = BlenderChannels("", w, h, false);  // compositor File Output: no layer prefix
  WriteExr(dir / "passes.exr", w, h, ch);
  AovOptions o;
  o.preset = Preset::kBlender;
  auto p = MustOpen({dir / "passes.exr"}, o);
  ASSERT_TRUE(p);
  for (int i : {0, 9, 63}) {
    const ExactSample s = Sample(*p, i % w, i / w, true);
    for (int c = 0; c < 3; ++c) {
      const std::string k = std::string(".") + "RGB"[c];
      const double gloss = double(Get(ch, "GlossCol" + k, i)) *
                           (double(Get(ch, "GlossDir" + k, i)) + double(Get(ch, "GlossInd" + k, i)));
      const double lc = gloss + Get(ch, "Emit" + k, i) + Get(ch, "Env" + k, i);
      // Binary fractions with few bits: every sum and product is exact in float.
      EXPECT_EQ(double(s.Lc[c]), lc);
      const double diffuse = double(Get(ch, "DiffCol" + k, i)) *
                             (double(Get(ch, "DiffDir" + k, i)) + double(Get(ch, "DiffInd" + k, i)));
      EXPECT_EQ(double(s.L[c]), diffuse + lc);
    }
  }
}

TEST(AovProvider, BlenderViewLayers) {
  ScratchDir dir;
  auto a = BlenderChannels("Front", 8, 8, true);
  auto b = BlenderChannels("Back", 8, 8, true);
  a.insert(a.end(), b.begin(), b.end());
  WriteExr(dir / "two.exr", 8, 8, a);
  AovOptions o;
  o.preset = Preset::kBlender;
  Status st = OpenError({dir / "two.exr"}, o);
  ASSERT_FALSE(st.ok());
  EXPECT_THAT(st.message(), HasSubstr("several Blender view layers"));
  EXPECT_THAT(st.message(), HasSubstr("--layer"));
  o.viewLayer = "Back";
  auto p = MustOpen({dir / "two.exr"}, o);
  ASSERT_TRUE(p);
  EXPECT_EQ(Sample(*p, 3, 3).L.r, Get(b, "Back.Combined.R", 27));
  o.viewLayer = "Side";
  st = OpenError({dir / "two.exr"}, o);
  EXPECT_THAT(st.message(), HasSubstr("no Blender view layer 'Side'"));
}

TEST(AovProvider, BlenderGuideLayers) {
  // A ShadowGuide view layer (examples/blender/make_and_render.py
  // --shadow-guide) is taken as the shadow guide, its Combined R + G + B
  // (lit where > 0); a HighlightGuide one (--highlight-guide) as the
  // highlight guide, its GlossDir R + G + B (a highlight where > 1.5).
  // Neither is a candidate for the layer of the passes, although the
  // highlight guide has a GlossDir pass as the passes' layer does.
  struct Layer {
    std::string pass;   // "ShadowGuide.Combined."
    std::string note;   // what the notes say
    float marked, rest; // per channel, left (x < 4) and right
  };
  for (const Layer& l : {Layer{"ShadowGuide.Combined.", "shadow guide: ", 1.f, 0.f},
                         Layer{"HighlightGuide.GlossDir.", "highlight guide: ", 1.f, 0.1f}}) {
    SCOPED_TRACE(l.pass);
    ScratchDir dir;
    auto ch = BlenderChannels("ViewLayer", 8, 8, true);
    for (const char* c : {"R", "G", "B"})
      ch.push_back(Fill(l.pass + c, 8, 8, [&](int x, int) { return x < 4 ? l.marked : l.rest; }));
    WriteExr(dir / "room.exr", 8, 8, ch);
    AovOptions o;
    o.preset = Preset::kBlender;
    auto p = MustOpen({dir / "room.exr"}, o);
    ASSERT_TRUE(p);
    bool said = false;
    for (const auto& n : p->Notes())
      said |= n.find(l.note + l.pass + "R+" + l.pass + "G+" + l.pass + "B") != std::string::npos;
    EXPECT_TRUE(said);
    GuideRequest req;
    req.objectId = true;
    const GuideImage g = AllGuides(*p, req);
    EXPECT_NE(g.objectId[3], g.objectId[4]);  // same IndexOB (x < 5), marked and not
    EXPECT_EQ(g.objectId[0], g.objectId[3]);
  }
}

TEST(AovProvider, MapOverrides) {
  ScratchDir dir;
  Scene sc{16, 16};
  std::vector<TestChannel> ch;
  const char* comp[3] = {"R", "G", "B"};
  ch.push_back(Fill("objid", 16, 16, [&](int x, int y) { return float(sc.ObjectId(x, y)); }));
  for (int c = 0; c < 3; ++c) {
    ch.push_back(Fill(std::string("albedo.") + comp[c], 16, 16, [&](int x, int y) { return sc.Tau(x, y)[c]; }));
    ch.push_back(Fill(std::string("direct.") + comp[c], 16, 16, [&](int x, int y) { return 0.5f * sc.Li(x, y)[c]; }));
    ch.push_back(Fill(std::string("indirect.") + comp[c], 16, 16, [&](int x, int y) { return 0.5f * sc.Li(x, y)[c]; }));
    ch.push_back(Fill(std::string("beauty.") + comp[c], 16, 16, [&](int x, int y) { return sc.L(x, y)[c]; }));
  }
  WriteExr(dir / "custom.exr", 16, 16, ch);
  AovOptions o;
  for (const char* m : {"id=objid", "tau=albedo", "Li=direct+indirect", "L=beauty"})
    ASSERT_TRUE(ParseMapping(m, &o.mappings).ok()) << m;
  auto p = MustOpen({dir / "custom.exr"}, o);
  ASSERT_TRUE(p);
  EXPECT_TRUE(p->Capabilities().objectId);
  EXPECT_TRUE(p->Capabilities().splitRadiance);
  const ExactSample s = Sample(*p, 9, 4, true);
  EXPECT_EQ(s.L, sc.L(9, 4));
  EXPECT_EQ(s.Li, sc.Li(9, 4) * 0.5f + sc.Li(9, 4) * 0.5f);
  EXPECT_EQ(s.Lc, sc.L(9, 4) - s.Li * sc.Tau(9, 4));

  // A mapping to a channel that is not there lists the channels that are.
  AovOptions bad;
  ASSERT_TRUE(ParseMapping("id=objectid", &bad.mappings).ok());
  ASSERT_TRUE(ParseMapping("L=beauty", &bad.mappings).ok());
  Status st = OpenError({dir / "custom.exr"}, bad);
  ASSERT_FALSE(st.ok());
  EXPECT_THAT(st.message(), HasSubstr("no channel 'objectid'"));
  EXPECT_THAT(st.message(), HasSubstr("objid"));
  EXPECT_THAT(st.message(), HasSubstr("albedo.R"));
  EXPECT_THAT(st.message(), HasSubstr("custom.exr"));

  // Syntax errors.
  std::vector<Mapping> m;
  EXPECT_FALSE(ParseMapping("noequals", &m).ok());
  EXPECT_FALSE(ParseMapping("colour=foo", &m).ok());
  EXPECT_FALSE(ParseMapping("L.R=a+", &m).ok());
  EXPECT_FALSE(ParseMapping("L=", &m).ok());
}

TEST(AovProvider, UintIdsAreReadAsIntegers) {
  ScratchDir dir;
  TestChannel id{"id", {}, {}, false};
  for (int i = 0; i < 64; ++i) id.ids.push_back(i % 2 ? 1000000u : 4000000000u);
  auto rgb = Fill("R", 8, 8, [](int, int) { return 0.5f; });
  WriteExr(dir / "uint.exr", 8, 8, {rgb, Fill("G", 8, 8, [](int, int) { return 0.5f; }),
                                    Fill("B", 8, 8, [](int, int) { return 0.5f; }), id});
  auto p = MustOpen({dir / "uint.exr"});
  ASSERT_TRUE(p);
  const GuideImage g = AllGuides(*p, {true, false, false});
  EXPECT_EQ(g.objectId[0], 4000000000u);  // would be normalised through a float buffer
  EXPECT_EQ(g.objectId[1], 1000000u);
}

TEST(AovProvider, NonIntegerIdsAreAnError) {
  ScratchDir dir;
  Scene sc{8, 8};
  auto ch = sc.GenericChannels(false);
  ch[1].values[size_t(3 * 8 + 5)] = 2.5f;  // shader channel
  WriteExr(dir / "frac.exr", 8, 8, ch);
  Status st = OpenError({dir / "frac.exr"});
  ASSERT_FALSE(st.ok());
  EXPECT_THAT(st.message(), HasSubstr("frac.exr"));
  EXPECT_THAT(st.message(), HasSubstr("'shader'"));
  EXPECT_THAT(st.message(), HasSubstr("non-integer"));
  EXPECT_THAT(st.message(), HasSubstr("(5, 3)"));
  // NaN is not an integer either; half storage holds small integers exactly.
  ch = sc.GenericChannels(false);
  ch[0].half = true;
  WriteExr(dir / "half.exr", 8, 8, ch);
  EXPECT_TRUE(OpenError({dir / "half.exr"}).ok());
  ch[0].values[0] = std::numeric_limits<float>::quiet_NaN();
  WriteExr(dir / "nan.exr", 8, 8, ch);
  st = OpenError({dir / "nan.exr"});
  EXPECT_THAT(st.message(), HasSubstr("'id'"));
}

float FromBits(uint32_t u) {
  float f;
  std::memcpy(&f, &u, 4);
  return f;
}

/// The rank-1 ID of AddCrypto's layers.
constexpr uint32_t kOtherHash = 0x3d0a11f3u;

/// A Cryptomatte layer like Blender writes it: rank-0 ID in 00.R, coverage in
/// 00.G, rank 1 in 00.B and 00.A, manifest in the metadata.
void AddCrypto(std::vector<TestChannel>* ch, Attributes* attrs, const std::string& name,
               const std::string& key, int w, int h, const std::function<uint32_t(int, int)>& hashAt,
               const std::vector<std::pair<std::string, uint32_t>>& manifest, bool half = false,
               const std::function<std::pair<float, float>(int, int)>& coverageAt = {}) {
  TestChannel r = Fill(name + "00.R", w, h, [&](int x, int y) { return FromBits(hashAt(x, y)); });
  r.half = half;
  ch->push_back(r);
  // Rank 0 covers the whole pixel unless `coverageAt` says (rank 0, rank 1).
  auto cover = [&](int x, int y) { return coverageAt ? coverageAt(x, y) : std::pair(1.f, 0.f); };
  ch->push_back(Fill(name + "00.G", w, h, [&](int x, int y) { return cover(x, y).first; }));
  ch->push_back(Fill(name + "00.B", w, h, [](int, int) { return FromBits(kOtherHash); }));
  ch->push_back(Fill(name + "00.A", w, h, [&](int x, int y) { return cover(x, y).second; }));
  std::string json = "{";
  for (size_t i = 0; i < manifest.size(); ++i) {
    char hex[16];
    std::snprintf(hex, sizeof hex, "%08x", manifest[i].second);
    // Appends, not "literal" + string: GCC 12 warns falsely (-Wrestrict) on those.
    if (i) json += ',';
    json += '"';
    json += manifest[i].first;
    json += "\":\"";
    json += hex;
    json += '"';
  }
  json += "}";
  attrs->push_back({"cryptomatte/" + key + "/name", name});
  attrs->push_back({"cryptomatte/" + key + "/hash", "MurmurHash3_32"});
  attrs->push_back({"cryptomatte/" + key + "/conversion", "uint32_to_float32"});
  attrs->push_back({"cryptomatte/" + key + "/manifest", json});
}

// Hash-like IDs (float bit patterns with a normal exponent, as Cryptomatte
// makes them) of two objects and two materials.
constexpr uint32_t kChair = 0x3f2a9c11u, kTable = 0x40c31b07u;
constexpr uint32_t kWood = 0x3e8d2f55u, kMetal = 0x41172ac3u;

TEST(AovProvider, CryptomatteIds) {
  ScratchDir dir;
  const int w = 16, h = 8;
  auto ch = BlenderChannels("ViewLayer", w, h, true);
  Attributes attrs;
  AddCrypto(&ch, &attrs, "ViewLayer.CryptoObject", "a1b2c3d", w, h,
            [](int x, int) { return x < 8 ? kChair : kTable; }, {{"Chair", kChair}, {"Table", kTable}});
  AddCrypto(&ch, &attrs, "ViewLayer.CryptoMaterial", "e4f5a6b", w, h,
            [](int, int y) { return y < 4 ? kWood : kMetal; }, {{"Wood", kWood}, {"Metal", kMetal}});
  WriteExr(dir / "crypto.exr", w, h, ch, attrs);
  AovOptions o;
  o.preset = Preset::kBlender;
  auto p = MustOpen({dir / "crypto.exr"}, o);
  ASSERT_TRUE(p);
  const GuideImage g = AllGuides(*p, {true, true, false});
  // The Blender preset prefers Cryptomatte over IndexOB/IndexMA; the IDs are
  // the float bit patterns.
  EXPECT_EQ(g.objectId[size_t(2 * w + 3)], kChair);
  EXPECT_EQ(g.objectId[size_t(2 * w + 12)], kTable);
  EXPECT_EQ(g.shaderId[size_t(1 * w + 3)], kWood);
  EXPECT_EQ(g.shaderId[size_t(6 * w + 3)], kMetal);
  bool said = false;
  for (const auto& n : p->Notes()) said |= n.find("Cryptomatte layer 'ViewLayer.CryptoObject'") != std::string::npos &&
                                           n.find("2 names") != std::string::npos;
  EXPECT_TRUE(said);

  // Generic preset with an explicit mapping by layer suffix.
  AovOptions g2;
  ASSERT_TRUE(ParseMapping("id=cryptomatte:CryptoMaterial", &g2.mappings).ok());
  ASSERT_TRUE(ParseMapping("L=ViewLayer.Combined", &g2.mappings).ok());
  auto q = MustOpen({dir / "crypto.exr"}, g2);
  ASSERT_TRUE(q);
  EXPECT_EQ(AllGuides(*q, {true, false, false}).objectId[size_t(6 * w)], kMetal);
  // An unknown layer lists the layers that exist.
  AovOptions g3;
  ASSERT_TRUE(ParseMapping("id=cryptomatte:CryptoAsset", &g3.mappings).ok());
  ASSERT_TRUE(ParseMapping("L=ViewLayer.Combined", &g3.mappings).ok());
  Status st = OpenError({dir / "crypto.exr"}, g3);
  EXPECT_THAT(st.message(), HasSubstr("no Cryptomatte layer 'CryptoAsset'"));
  EXPECT_THAT(st.message(), HasSubstr("ViewLayer.CryptoObject"));
}

// The sky through a window, where one of the pixel's samples hit the frame:
// Cryptomatte's rank 0 is then the frame with a tiny coverage, and the rest
// of the footprint saw nothing. Such pixels are background (ID 0), not the
// frame; a pixel shared by two objects keeps its rank 0.
TEST(AovProvider, CryptomattePixelsThatMostlySawNothingAreBackground) {
  ScratchDir dir;
  const int w = 12, h = 4;
  auto ch = BlenderChannels("ViewLayer", w, h, true);
  Attributes attrs;
  // x < 4: the chair alone; 4 <= x < 8: chair 0.4 and another object 0.3, so
  // 0.3 saw nothing; x >= 8: the chair with 1/1024 of the pixel, as Blender
  // writes the sky beside a frame.
  auto coverage = [](int x, int) {
    return x < 4 ? std::pair(1.f, 0.f) : x < 8 ? std::pair(0.4f, 0.3f) : std::pair(1.f / 1024, 0.f);
  };
  AddCrypto(&ch, &attrs, "ViewLayer.CryptoObject", "a1b2c3d", w, h, [](int, int) { return kChair; },
            {{"Chair", kChair}}, false, coverage);
  WriteExr(dir / "sky.exr", w, h, ch, attrs);
  AovOptions o;
  o.preset = Preset::kBlender;
  auto p = MustOpen({dir / "sky.exr"}, o);
  ASSERT_TRUE(p);
  const GuideImage g = AllGuides(*p, {true, false, false});
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      EXPECT_EQ(g.objectId[size_t(y * w + x)], x < 8 ? kChair : 0u) << "pixel " << x << "," << y;
}

TEST(AovProvider, CryptomatteInHalfIsAnError) {
  ScratchDir dir;
  auto ch = BlenderChannels("ViewLayer", 8, 8, true);
  Attributes attrs;
  AddCrypto(&ch, &attrs, "ViewLayer.CryptoObject", "a1b2c3d", 8, 8, [](int, int) { return kChair; },
            {{"Chair", kChair}}, /*half=*/true);
  WriteExr(dir / "halfcrypto.exr", 8, 8, ch, attrs);
  AovOptions o;
  o.preset = Preset::kBlender;
  Status st = OpenError({dir / "halfcrypto.exr"}, o);
  ASSERT_FALSE(st.ok());
  EXPECT_THAT(st.message(), HasSubstr("ViewLayer.CryptoObject00.R"));
  EXPECT_THAT(st.message(), HasSubstr("32-bit float"));
}

/// A 4x4 texture with distinct texel values.
void WriteTexture(const std::string& path) {
  std::vector<TestChannel> ch;
  const char* comp[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c)
    ch.push_back(Fill(comp[c], 4, 4, [c](int x, int y) { return 0.1f * float(x) + 0.02f * float(y) + 0.3f * float(c); }));
  WriteExr(path, 4, 4, ch);
}

TEST(AovProvider, TextureLookupFromUvAndShader) {
  ScratchDir dir;
  WriteTexture(dir / "tex.exr");
  // 8x8 pixels; shader 5 on the left half looks the texture up at texel
  // centres ((i + 0.5)/4); v runs up, so texel row ty is at v = 1 - (ty+0.5)/4.
  const int w = 8, h = 8;
  std::vector<TestChannel> ch;
  ch.push_back(Fill("shader", w, h, [](int x, int) { return x < 4 ? 5.f : 6.f; }));
  ch.push_back(Fill("u", w, h, [](int x, int) { return (float(x % 4) + 0.5f) / 4.f; }));
  ch.push_back(Fill("v", w, h, [](int, int y) { return 1.f - (float(y % 4) + 0.5f) / 4.f; }));
  for (const char* c : {"Li.R", "Li.G", "Li.B", "Lc.R", "Lc.G", "Lc.B"})
    ch.push_back(Fill(c, w, h, [](int x, int y) { return 0.1f * float(x + y); }));
  WriteExr(dir / "uv.exr", w, h, ch);
  AovOptions o;
  TextureBinding b;
  ASSERT_TRUE(ParseTextureBinding("5=" + (dir / "tex.exr"), &b).ok());
  o.textures.push_back(b);
  auto p = MustOpen({dir / "uv.exr"}, o);
  ASSERT_TRUE(p);
  EXPECT_TRUE(p->Capabilities().splitRadiance);
  const GuideImage g = AllGuides(*p, {false, false, true});
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const RGB t = g.texture[size_t(y * w + x)];
      if (x >= 4) {
        EXPECT_EQ(t, RGB::Gray(1.f)) << "untextured shader: tau = 1";
        continue;
      }
      // Bilinear interpolation at a texel centre returns the texel up to the
      // rounding of the interpolation weights (1e-6 is ~10 float ulp here).
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(t[c], 0.1f * float(x % 4) + 0.02f * float(y % 4) + 0.3f * float(c), 1e-6f) << x << "," << y;
    }
  }
  // L = L_i * tau + L_c with the looked-up tau.
  const ExactSample s = Sample(*p, 1, 2, true);
  EXPECT_EQ(s.L, s.Li * g.texture[size_t(2 * w + 1)] + s.Lc);

  // A missing texture file and an unknown shader name are errors.
  AovOptions bad;
  bad.textures.push_back({"5", dir / "nope.exr"});
  Status st = OpenError({dir / "uv.exr"}, bad);
  EXPECT_THAT(st.message(), HasSubstr("nope.exr"));
  bad.textures = {{"Wood", dir / "tex.exr"}};
  st = OpenError({dir / "uv.exr"}, bad);
  EXPECT_THAT(st.message(), HasSubstr("'Wood'"));
}

TEST(AovProvider, TextureByCryptomatteMaterialName) {
  ScratchDir dir;
  WriteTexture(dir / "tex.exr");
  const int w = 8, h = 4;
  std::vector<TestChannel> ch;
  Attributes attrs;
  AddCrypto(&ch, &attrs, "CryptoMaterial", "e4f5a6b", w, h, [](int x, int) { return x < 4 ? kWood : kMetal; },
            {{"Wood", kWood}, {"Metal", kMetal}});
  ch.push_back(Fill("u", w, h, [](int x, int) { return (float(x % 4) + 0.5f) / 4.f; }));
  ch.push_back(Fill("v", w, h, [](int, int y) { return 1.f - (float(y) + 0.5f) / 4.f; }));
  for (const char* c : {"Li.R", "Li.G", "Li.B", "R", "G", "B"})
    ch.push_back(Fill(c, w, h, [](int, int) { return 0.5f; }));
  WriteExr(dir / "crypto_uv.exr", w, h, ch, attrs);
  AovOptions o;
  ASSERT_TRUE(ParseMapping("shader=cryptomatte:CryptoMaterial", &o.mappings).ok());
  o.textures.push_back({"Wood", dir / "tex.exr"});
  auto p = MustOpen({dir / "crypto_uv.exr"}, o);
  ASSERT_TRUE(p);
  const GuideImage g = AllGuides(*p, {false, false, true});
  EXPECT_NEAR(g.texture[size_t(1 * w + 2)].g, 0.1f * 2 + 0.02f * 1 + 0.3f, 1e-6f);
  EXPECT_EQ(g.texture[size_t(1 * w + 6)], RGB::Gray(1.f));
}

TEST(AovProvider, SparseSamplesAndPending) {
  ScratchDir dir;
  Scene sc{16, 16};
  WriteExr(dir / "guides.exr", 16, 16, sc.GenericChannels(false, /*guidesOnly=*/true));
  AovOptions o;
  o.sparse = true;
  auto p = MustOpen({dir / "guides.exr"}, o);
  ASSERT_TRUE(p);
  EXPECT_FALSE(p->dense());
  EXPECT_EQ(p->SampleCount(), 0);
  EXPECT_EQ(p->SampleChannels(), (std::vector<std::string>{"R", "G", "B", "mask"}));
  Point2i px[2] = {{3, 4}, {10, 11}};
  ExactSample s[2];
  Status st = p->Evaluate(px, {}, s);
  EXPECT_TRUE(st.pending()) << st.message();

  // A samples file with pixel (3,4) only.
  auto all = sc.GenericChannels(false);
  std::vector<TestChannel> samples = {all[2], all[3], all[4],
                                      Fill("mask", 16, 16, [](int x, int y) { return x == 3 && y == 4 ? 1.f : 0.f; })};
  WriteExr(dir / "s0.exr", 16, 16, samples);
  o.samples = {dir / "s0.exr"};
  auto q = MustOpen({dir / "guides.exr"}, o);
  ASSERT_TRUE(q);
  EXPECT_EQ(q->SampleCount(), 1);
  EXPECT_TRUE(q->HasSample({3, 4}));
  EXPECT_FALSE(q->HasSample({10, 11}));
  EXPECT_TRUE(q->Evaluate(px, {}, s).pending());
  EXPECT_TRUE(q->Evaluate(std::span(px, 1), {}, std::span(s, 1)).ok());
  EXPECT_EQ(s[0].L, sc.L(3, 4));

  // Samples without a mask, or of another size, are errors naming the file.
  WriteExr(dir / "nomask.exr", 16, 16, {all[2], all[3], all[4]});
  o.samples = {dir / "nomask.exr"};
  st = OpenError({dir / "guides.exr"}, o);
  EXPECT_THAT(st.message(), HasSubstr("nomask.exr"));
  EXPECT_THAT(st.message(), HasSubstr("mask"));
  WriteExr(dir / "small.exr", 8, 8, {Fill("R", 8, 8, [](int, int) { return 0.f; })});
  o.samples = {dir / "small.exr"};
  st = OpenError({dir / "guides.exr"}, o);
  EXPECT_THAT(st.message(), HasSubstr("different resolutions"));
  EXPECT_THAT(st.message(), HasSubstr("small.exr"));
}

TEST(AovProvider, NonFiniteAndNegativeSamplesAreReported) {
  ScratchDir dir;
  Scene sc{16, 16};
  auto ch = sc.GenericChannels(false);
  ch[2].values[5] = std::numeric_limits<float>::quiet_NaN();     // R
  ch[3].values[6] = std::numeric_limits<float>::infinity();      // G
  ch[4].values[7] = -0.5f;                                       // B
  WriteExr(dir / "bad_values.exr", 16, 16, ch);
  auto p = MustOpen({dir / "bad_values.exr"});
  ASSERT_TRUE(p);
  std::string all;
  for (const auto& w : p->Warnings()) all += w + "\n";
  EXPECT_THAT(all, HasSubstr("bad_values.exr"));
  EXPECT_THAT(all, HasSubstr("channel 'R': 1 NaN/Inf"));
  EXPECT_THAT(all, HasSubstr("channel 'G': 1 NaN/Inf"));
  EXPECT_THAT(all, HasSubstr("channel 'B': 1 negative"));
  // The values are handed over as they are (the engine keeps them to their pixel).
  EXPECT_TRUE(std::isnan(Sample(*p, 5, 0).L.r));
}

TEST(AovProvider, BadFiles) {
  ScratchDir dir;
  Scene sc{16, 16};
  // Missing file.
  Status st = OpenError({dir / "missing.exr"});
  EXPECT_THAT(st.message(), HasSubstr("missing.exr': no such file"));
  // Not an EXR: a text file with an .exr name.
  { std::ofstream(dir / "text.exr") << "hello, not an image\n"; }
  st = OpenError({dir / "text.exr"});
  EXPECT_THAT(st.message(), HasSubstr("text.exr': not an OpenEXR file"));
  // Truncated EXR.
  WriteExr(dir / "full.exr", 64, 64, Scene{64, 64}.GenericChannels(false));
  const auto size = std::filesystem::file_size(dir / "full.exr");
  std::filesystem::copy_file(dir / "full.exr", dir / "cut.exr");
  std::filesystem::resize_file(dir / "cut.exr", size / 2);
  st = OpenError({dir / "cut.exr"});
  ASSERT_FALSE(st.ok());
  EXPECT_THAT(st.message(), HasSubstr("cut.exr"));
  // Different resolutions.
  WriteExr(dir / "a.exr", 16, 16, sc.GenericChannels(false));
  WriteExr(dir / "b.exr", 16, 8, {Fill("u", 16, 8, [](int, int) { return 0.f; })});
  st = OpenError({dir / "a.exr", dir / "b.exr"});
  EXPECT_THAT(st.message(), HasSubstr("different resolutions"));
  EXPECT_THAT(st.message(), HasSubstr("b.exr' is 16x8"));
  // Absurd dimensions: a valid header and offset table of 120000x120000
  // pixels; the memory guard refuses it before anything is allocated.
  MakeHugeExr(dir / "huge.exr", 120000);
  st = OpenError({dir / "huge.exr"});
  EXPECT_THAT(st.message(), HasSubstr("huge.exr': 120000x120000 pixels would need"));
  MakeHugeExr(dir / "wide.exr", 200000);
  st = OpenError({dir / "wide.exr"});
  EXPECT_THAT(st.message(), HasSubstr("absurd image dimensions 200000x200000"));
  // No beauty at all.
  WriteExr(dir / "ids_only.exr", 16, 16, sc.GenericChannels(false, true));
  st = OpenError({dir / "ids_only.exr"});
  EXPECT_THAT(st.message(), HasSubstr("no exact samples"));
  EXPECT_THAT(st.message(), HasSubstr("shader"));
}

}  // namespace
}  // namespace dcm::aov::test
