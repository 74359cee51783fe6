// A small DCM render with the engine against the full render of the same scene.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

#include "common/metrics.h"
#include "dcm/reconstructor.h"
#include "test_scenes.h"

namespace dcm::embree {
namespace {

using testing::MakeProvider;

// A floor with a parquet texture, a glossy sphere, a box and a thin post under
// a soft area light: 64x64 output, 2x2 supersampling (128x128 working pixels).
const char* kScene = R"({
  "camera": {"position": [0, 2.2, 3.2], "look_at": [0, 0.3, 0], "fov": 40, "resolution": [64, 64]},
  "render": {"shadow_rays": 16, "glossy_rays": 8, "supersampling": 2},
  "materials": {
    "floor": {"type": "diffuse", "color": 0.9, "texture": {"type": "planks", "plank_length": 0.5, "plank_width": 0.1}},
    "ball": {"type": "plastic", "color": [0.6, 0.1, 0.1], "specular": 0.3, "exponent": 40},
    "block": {"type": "diffuse", "color": [0.2, 0.4, 0.7]},
    "post": {"type": "diffuse", "color": 0.8}
  },
  "objects": [
    {"type": "quad", "material": "floor", "origin": [-3, 0, 3], "edge_u": [6, 0, 0], "edge_v": [0, 0, -6]},
    {"type": "sphere", "material": "ball", "center": [-0.6, 0.4, 0], "radius": 0.4},
    {"type": "box", "material": "block", "min": [0.2, 0, -0.4], "max": [0.9, 0.7, 0.3]},
    {"type": "cylinder", "material": "post", "from": [0.0, 0, 0.8], "to": [0.0, 1.2, 0.8], "radius": 0.012}
  ],
  "lights": [{"type": "rect", "origin": [-0.6, 3, -0.6], "edge_u": [1.2, 0, 0], "edge_v": [0, 0, 1.2], "radiance": 6}]
})";

ReconstructionOptions Options(EmbreeProvider& p) {
  ReconstructionOptions o;
  o.downsample = p.scene().render.supersampling;
  o.threads = 2;
  return o;
}

TEST(DcmRender, ReachesHighPsnrWithAFractionOfThePixels) {
  auto p = MakeProvider(kScene);
  ASSERT_TRUE(p);
  ReconstructionOptions o = Options(*p);
  Reconstruction dcm, full;
  Status st = Reconstruct(*p, o, &dcm);
  ASSERT_TRUE(st.ok()) << st.message();
  o.fullEvaluation = true;
  st = Reconstruct(*p, o, &full);
  ASSERT_TRUE(st.ok()) << st.message();
  ASSERT_EQ(dcm.width, 64);
  ASSERT_EQ(full.width, 64);
  EXPECT_TRUE(dcm.stats.usedSplit);  // the textured floor is reconstructed with the split
  toolkit::ImageError e = toolkit::Compare(dcm.image, full.image, 64, 64);
  RecordProperty("psnr", std::to_string(e.psnr));
  RecordProperty("exact_fraction", std::to_string(dcm.stats.exactFraction()));
  std::printf("DCM: %.2f dB at %.1f %% exact pixels\n", e.psnr, 100.0 * dcm.stats.exactFraction());
  // Thresholds from measurement with margin: this scene (2x supersampled,
  // the display-weighted contrast at 0.15) gives 44.7 dB at 5.7 % exact
  // pixels (Mitchell's contrast at 0.12: 45.3 dB at 11.1 %). 40 dB leaves
  // room for engine tuning while a wrong split, tau or guide costs far more.
  EXPECT_GT(e.psnr, 40.0);
  EXPECT_LT(dcm.stats.exactFraction(), 0.4);
  EXPECT_EQ(full.stats.exactFraction(), 1.0);
  EXPECT_EQ(e.nonFinite, 0);
}

// Small balls out of view cast 2-pixel shadow dots on a point-lit floor. No
// ID marks them, and most fall between the lattice's corners, so the
// lattice misses them; with the point-light visibility guide
// (render.shadow_guide) their pixels differ from their neighbours' like a
// thin object's, and are evaluated exactly.
TEST(DcmRender, ShadowGuideFindsShadowsSmallerThanTheLattice) {
  auto scene = [](bool guide) {
    std::string balls;
    for (double x : {1.35, 1.6, 1.85, 2.1, 2.35})
      for (double z : {-0.8, -0.4, 0.0, 0.4, 0.8})
        balls += R"(, {"type": "sphere", "material": "ball", "radius": 0.03, "center": [)" + std::to_string(x) +
                 ", 1.5, " + std::to_string(z) + "]}";
    return std::string(R"({
      "camera": {"position": [0, 5, 0], "look_at": [0, 0, 0], "up": [0, 0, -1], "fov": 40, "resolution": [64, 64]},
      "render": {"shadow_guide": )") + (guide ? "true" : "false") + R"(},
      "materials": {"floor": {"type": "diffuse", "color": 0.8}, "ball": {"type": "diffuse"}},
      "objects": [
        {"type": "quad", "material": "floor", "origin": [-3, 0, 3], "edge_u": [6, 0, 0], "edge_v": [0, 0, -6]})" +
           balls + R"(
      ],
      "lights": [{"type": "point", "position": [3, 3, 0], "intensity": 20}]
    })";
  };
  double psnr[2] = {0, 0};
  for (bool guide : {false, true}) {
    auto p = MakeProvider(scene(guide));
    ASSERT_TRUE(p);
    ASSERT_EQ(p->effects().shadowGuide, guide);
    // A point light: its hard shadows show in the guides only with the guide.
    EXPECT_EQ(p->Capabilities().hardShadowsGuided, guide);
    ReconstructionOptions o = Options(*p);
    Reconstruction dcm, full;
    ASSERT_TRUE(Reconstruct(*p, o, &dcm).ok());
    o.fullEvaluation = true;
    ASSERT_TRUE(Reconstruct(*p, o, &full).ok());
    // The shadows are there: dark floor pixels, a few per ball.
    int dark = 0;
    for (const RGB& c : full.image) dark += c.g < 0.05f;
    ASSERT_GT(dark, 25) << "no shadow dots in the full render";
    psnr[guide] = toolkit::Compare(dcm.image, full.image, 64, 64).psnr;
    std::printf("shadow guide %s: %.2f dB at %.1f %% exact pixels\n", guide ? "on" : "off", psnr[guide],
                100.0 * dcm.stats.exactFraction());
  }
  // Measured: most dots are interpolated over without the guide, exact with
  // it (the image is otherwise a smooth gradient). 10 dB is a fraction of
  // the gap.
  EXPECT_GT(psnr[1], psnr[0] + 10.0);
}

// Shiny balls under a small light: each shows a highlight a few pixels
// across, inside blocks whose corners see only the balls' smooth shading.
// Without the highlight guide and without probes (what the tracer did when
// it claimed every small feature guided) the lattice interpolates over them;
// with it (render.highlight_guide) a highlight is a surface of its own and is
// refined like a thin object, with no probe.
TEST(DcmRender, HighlightGuideFindsHighlightsSmallerThanTheLattice) {
  auto scene = [](bool guide) {
    std::string balls;
    for (double x : {-1.2, -0.4, 0.4, 1.2})
      for (double z : {-0.8, 0.0, 0.8})
        balls += R"(, {"type": "sphere", "material": "shiny", "radius": 0.3, "center": [)" + std::to_string(x) +
                 ", 0.3, " + std::to_string(z) + "]}";
    return std::string(R"({
      "camera": {"position": [0, 4, 2.5], "look_at": [0, 0, 0], "fov": 45, "resolution": [96, 96]},
      "render": {"shadow_rays": 16, "highlight_guide": )") + (guide ? "true" : "false") + R"(},
      "materials": {"floor": {"type": "diffuse", "color": 0.5},
                    "shiny": {"type": "plastic", "color": [0.1, 0.3, 0.6], "specular": 0.5, "exponent": 300}},
      "objects": [
        {"type": "quad", "material": "floor", "origin": [-3, 0, 3], "edge_u": [6, 0, 0], "edge_v": [0, 0, -6]})" +
           balls + R"(
      ],
      "lights": [{"type": "rect", "origin": [-0.1, 4, 1.0], "edge_u": [0.2, 0, 0], "edge_v": [0, 0, 0.2], "radiance": 300}]
    })";
  };
  int highlights[2] = {0, 0}, kept[2] = {0, 0};
  for (bool guide : {false, true}) {
    auto p = MakeProvider(scene(guide));
    ASSERT_TRUE(p);
    ASSERT_EQ(p->effects().highlightGuide, guide);
    // No point light: with the guide nothing small is left for a probe.
    EXPECT_EQ(p->Capabilities().hardShadowsGuided, guide);
    ReconstructionOptions o = Options(*p);
    o.smoothRefinement = SmoothRefinement::kNever;
    Reconstruction dcm, full;
    ASSERT_TRUE(Reconstruct(*p, o, &dcm).ok());
    o.fullEvaluation = true;
    ASSERT_TRUE(Reconstruct(*p, o, &full).ok());
    // A highlight pixel: brighter than the light's diffuse share gives any
    // pixel here; kept: within 10 % of the full render (a pixel interpolated
    // over its highlight loses most of it).
    for (size_t i = 0; i < full.image.size(); ++i) {
      const float f = full.image[i].r + full.image[i].g + full.image[i].b;
      const float d = dcm.image[i].r + dcm.image[i].g + dcm.image[i].b;
      if (f <= 3.f) continue;
      ++highlights[guide];
      kept[guide] += std::abs(d - f) < 0.1f * f;
    }
    ASSERT_GT(highlights[guide], 12) << "no highlights in the full render";
    std::printf("highlight guide %s: %d of %d highlight pixels kept, %.1f %% exact pixels\n", guide ? "on" : "off",
                kept[guide], highlights[guide], 100.0 * dcm.stats.exactFraction());
  }
  ASSERT_LT(kept[0], highlights[0]) << "the lattice kept every highlight without the guide: the scene tests nothing";
  EXPECT_EQ(kept[1], highlights[1]);
}

TEST(DcmRender, TextureSplitSavesExactSamples) {
  // Paper 3.3: interpolating (L_i, L_c) instead of the textured L keeps the
  // parquet from forcing exact samples all over the floor.
  auto p = MakeProvider(kScene);
  ASSERT_TRUE(p);
  ReconstructionOptions o = Options(*p);
  Reconstruction split, plain;
  ASSERT_TRUE(Reconstruct(*p, o, &split).ok());
  o.textureSplit = false;
  ASSERT_TRUE(Reconstruct(*p, o, &plain).ok());
  std::printf("exact pixels: %.1f %% with the split, %.1f %% without\n", 100.0 * split.stats.exactFraction(),
              100.0 * plain.stats.exactFraction());
  EXPECT_FALSE(plain.stats.usedSplit);
  // Measured 24 % against 41 %; require at least a fifth fewer.
  EXPECT_LT(split.stats.exactFraction(), 0.8 * plain.stats.exactFraction());
}

TEST(DcmRender, ResultDoesNotDependOnThreadCount) {
  auto p = MakeProvider(kScene);
  ASSERT_TRUE(p);
  ReconstructionOptions o = Options(*p);
  Reconstruction a, b;
  o.threads = 1;
  ASSERT_TRUE(Reconstruct(*p, o, &a).ok());
  o.threads = 2;
  o.batchSize = 97;
  ASSERT_TRUE(Reconstruct(*p, o, &b).ok());
  ASSERT_EQ(a.image.size(), b.image.size());
  EXPECT_EQ(std::memcmp(a.image.data(), b.image.data(), a.image.size() * sizeof(RGB)), 0);
}

}  // namespace
}  // namespace dcm::embree
