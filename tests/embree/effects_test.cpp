// "Simulate only the effects a scene calls for": rays of a kind are traced only
// when the scene has what needs them.
#include <gtest/gtest.h>

#include "test_scenes.h"

namespace dcm::embree {
namespace {

using testing::AllPixels;
using testing::EvaluateAll;
using testing::MakeProvider;
using testing::SceneJson;

const char* kDiffuse = R"({"floor": {"type": "diffuse"}, "ball": {"type": "diffuse"}, "block": {"type": "diffuse"}})";
const char* kRender = R"({"shadow_rays": 4, "glossy_rays": 4, "mirror_depth": 3})";

RayCounts RenderAll(EmbreeProvider& p) {
  p.ResetRayCounts();
  EvaluateAll(p, AllPixels(p), p.Capabilities().splitRadiance);
  return p.rayCounts();
}

TEST(Effects, DiffuseSceneTracesOnlyPrimaryAndShadowRays) {
  auto p = MakeProvider(SceneJson(kDiffuse, kRender));
  ASSERT_TRUE(p);
  RayCounts c = RenderAll(*p);
  EXPECT_EQ(c.primary, uint64_t(32 * 32));
  EXPECT_GT(c.shadow, 0u);
  EXPECT_EQ(c.glossy, 0u);
  EXPECT_EQ(c.mirror, 0u);
  EXPECT_EQ(c.indirect, 0u);
  ProviderCapabilities caps = p->Capabilities();
  EXPECT_FALSE(caps.texture);
  EXPECT_FALSE(caps.splitRadiance);
  EXPECT_TRUE(caps.objectId);
  EXPECT_TRUE(caps.shaderId);
  EXPECT_EQ(p->effects().Names(), std::vector<std::string>{"area_lights"});
}

TEST(Effects, GlossyMaterialTracesGlossyRays) {
  auto p = MakeProvider(SceneJson(
      R"({"floor": {"type": "diffuse"}, "ball": {"type": "plastic", "exponent": 20}, "block": {"type": "diffuse"}})",
      kRender));
  ASSERT_TRUE(p);
  RayCounts c = RenderAll(*p);
  EXPECT_GT(c.glossy, 0u);
  EXPECT_EQ(c.mirror, 0u);
  EXPECT_EQ(c.indirect, 0u);
  EXPECT_TRUE(p->effects().glossy);
}

TEST(Effects, UnusedGlossyMaterialTracesNoGlossyRays) {
  auto p = MakeProvider(SceneJson(
      R"({"floor": {"type": "diffuse"}, "ball": {"type": "diffuse"}, "block": {"type": "diffuse"},
          "unused": {"type": "plastic"}, "unused_mirror": {"type": "mirror"},
          "unused_tex": {"type": "diffuse", "texture": {"type": "checker"}}})",
      kRender));
  ASSERT_TRUE(p);
  RayCounts c = RenderAll(*p);
  EXPECT_EQ(c.glossy, 0u);
  EXPECT_EQ(c.mirror, 0u);
  EXPECT_FALSE(p->Capabilities().texture);
}

TEST(Effects, GlossyRaysZeroKeepsHighlightsFromLightSamples) {
  const char* mats = R"({"floor": {"type": "diffuse"}, "ball": {"type": "plastic", "specular": 0.5, "exponent": 10},
                         "block": {"type": "diffuse"}})";
  auto p = MakeProvider(SceneJson(mats, R"({"shadow_rays": 4, "glossy_rays": 0})"));
  ASSERT_TRUE(p);
  RayCounts c = RenderAll(*p);
  EXPECT_EQ(c.glossy, 0u);
  EXPECT_FALSE(p->effects().glossy);
  // The highlight is still there (light sampling): some pixel has Lc > 0.
  auto px = testing::AllPixels(*p);
  bool anyGlossy = false;
  for (const auto& pt : px) anyGlossy |= Luminance(p->EvaluatePixel(pt.x, pt.y).Lc) > 0.f;
  EXPECT_TRUE(anyGlossy);
}

TEST(Effects, MirrorMaterialTracesMirrorRays) {
  auto p = MakeProvider(SceneJson(
      R"({"floor": {"type": "diffuse"}, "ball": {"type": "mirror"}, "block": {"type": "diffuse"}})", kRender));
  ASSERT_TRUE(p);
  RayCounts c = RenderAll(*p);
  EXPECT_GT(c.mirror, 0u);
  EXPECT_EQ(c.glossy, 0u);
  EXPECT_EQ(c.indirect, 0u);
}

TEST(Effects, MirrorDepthZeroTracesNoMirrorRays) {
  auto p = MakeProvider(SceneJson(
      R"({"floor": {"type": "diffuse"}, "ball": {"type": "mirror"}, "block": {"type": "diffuse"}})",
      R"({"mirror_depth": 0})"));
  ASSERT_TRUE(p);
  EXPECT_EQ(RenderAll(*p).mirror, 0u);
}

TEST(Effects, IndirectOnlyWhenAsked) {
  auto off = MakeProvider(SceneJson(kDiffuse, R"({"shadow_rays": 1, "indirect": {"bounces": 0, "rays": 4}})"));
  auto on = MakeProvider(SceneJson(kDiffuse, R"({"shadow_rays": 1, "indirect": {"bounces": 2, "rays": 4}})"));
  ASSERT_TRUE(off && on);
  EXPECT_EQ(RenderAll(*off).indirect, 0u);
  RayCounts c = RenderAll(*on);
  EXPECT_GT(c.indirect, 0u);
  EXPECT_TRUE(on->effects().indirect);
  // Indirect light only adds: every pixel at least as bright as without.
  auto px = testing::AllPixels(*on);
  auto a = EvaluateAll(*off, px, false);
  auto b = EvaluateAll(*on, px, false);
  double sumA = 0, sumB = 0;
  for (size_t i = 0; i < px.size(); ++i) {
    EXPECT_GE(Luminance(b[i].L), Luminance(a[i].L) * (1.f - 1e-5f)) << px[i].x << "," << px[i].y;
    sumA += Luminance(a[i].L);
    sumB += Luminance(b[i].L);
  }
  EXPECT_GT(sumB, sumA * 1.01);  // a closed floor-and-objects scene: at least 1 % more light
}

TEST(Effects, TexturedMaterialEnablesSplit) {
  auto p = MakeProvider(SceneJson(
      R"({"floor": {"type": "diffuse", "texture": {"type": "checker", "scale": 4}}, "ball": {"type": "diffuse"},
          "block": {"type": "diffuse"}})",
      kRender));
  ASSERT_TRUE(p);
  EXPECT_TRUE(p->Capabilities().texture);
  EXPECT_TRUE(p->Capabilities().splitRadiance);
  EXPECT_TRUE(p->effects().textures);
}

TEST(Effects, PointLightsOnlyTraceOneShadowRayPerLight) {
  auto p = MakeProvider(SceneJson(kDiffuse, R"({"shadow_rays": 64})",
                                  R"({"type": "point", "position": [0, 4, 0], "intensity": 10})"));
  ASSERT_TRUE(p);
  RayCounts c = RenderAll(*p);
  EXPECT_LE(c.shadow, c.primary);  // one per lit pixel at most: shadow_rays applies to area lights
  EXPECT_GT(c.shadow, 0u);
  EXPECT_EQ(p->effects().Names(), std::vector<std::string>{"point_lights"});
}

// The point-light visibility guide (render.shadow_guide): one shadow ray per
// point light and pixel in the guides, traced only where the scene has point
// lights, and by default ("auto") only where an exact pixel is a Monte Carlo
// estimate that costs far more.
TEST(Effects, ShadowGuideOnlyWithPointLightsAndByDefaultOnlyForMonteCarloPixels) {
  const char* point = R"({"type": "point", "position": [0, 4, 0], "intensity": 10})";
  auto guideRays = [](EmbreeProvider& p) {
    p.ResetRayCounts();
    GuideImage g;
    GuideRequest req;
    req.objectId = req.shaderId = true;
    EXPECT_TRUE(p.Guides({{0, 0}, {p.workWidth(), p.workHeight()}}, req, &g).ok());
    return p.rayCounts().guide;
  };
  const uint64_t pixels = 32 * 32;
  struct Case {
    const char* render;
    const char* lights;
    bool on;
  } cases[] = {
      {R"({"shadow_rays": 4})", point, false},                                   // one estimate: auto is off
      {R"({"shadow_rays": 4, "samples_per_pixel": 4})", point, true},            // Monte Carlo: auto is on
      {R"({"shadow_rays": 4, "indirect": {"bounces": 1, "rays": 1}})", point, true},
      {R"({"shadow_rays": 4, "samples_per_pixel": 4, "shadow_guide": false})", point, false},
      {R"({"shadow_rays": 4, "shadow_guide": true})", point, true},
      {R"({"shadow_rays": 4, "samples_per_pixel": 4, "shadow_guide": true})", "", false},  // area light only
  };
  for (const Case& c : cases) {
    auto p = MakeProvider(SceneJson(kDiffuse, c.render, c.lights));
    ASSERT_TRUE(p) << c.render;
    EXPECT_EQ(p->effects().shadowGuide, c.on) << c.render;
    const uint64_t rays = guideRays(*p);
    // One camera ray per pixel (no mirrors), plus one shadow ray per point
    // light at each pixel whose surface faces it.
    if (c.on) {
      EXPECT_GT(rays, pixels) << c.render;
      EXPECT_LE(rays, 2 * pixels) << c.render;
    } else {
      EXPECT_EQ(rays, pixels) << c.render;
    }
  }
}

// The highlight guide (render.highlight_guide): on wherever a used material
// is plastic, off with false or without one; it traces no ray, and only with
// it does the tracer tell the engine that its guides show every small feature.
TEST(Effects, HighlightGuideOnlyWithPlasticAndTracesNoRay) {
  const char* plastic =
      R"({"floor": {"type": "diffuse"}, "ball": {"type": "plastic", "exponent": 20}, "block": {"type": "diffuse"}})";
  const char* unused = R"({"floor": {"type": "diffuse"}, "ball": {"type": "diffuse"}, "block": {"type": "diffuse"},
                          "unused": {"type": "plastic"}})";
  struct Case {
    const char* materials;
    const char* render;
    bool on;
  } cases[] = {
      {plastic, R"({"shadow_rays": 4})", true},
      {plastic, R"({"shadow_rays": 4, "glossy_rays": 0})", true},  // highlights of light samples alone
      {plastic, R"({"shadow_rays": 4, "highlight_guide": false})", false},
      {unused, R"({"shadow_rays": 4})", false},
      {kDiffuse, R"({"shadow_rays": 4, "highlight_guide": true})", false},
  };
  for (const Case& c : cases) {
    auto p = MakeProvider(SceneJson(c.materials, c.render));
    ASSERT_TRUE(p) << c.render;
    EXPECT_EQ(p->effects().highlightGuide, c.on) << c.materials << c.render;
    const bool plasticUsed = c.materials == plastic;
    EXPECT_EQ(p->Capabilities().hardShadowsGuided, !plasticUsed || c.on) << c.materials << c.render;
    p->ResetRayCounts();
    GuideImage g;
    GuideRequest req;
    req.objectId = req.shaderId = true;
    ASSERT_TRUE(p->Guides({{0, 0}, {p->workWidth(), p->workHeight()}}, req, &g).ok());
    EXPECT_EQ(p->rayCounts().guide, uint64_t(32 * 32)) << c.render;  // the camera rays alone
  }
  Scene scene;
  const Status st = testing::Parse(SceneJson(kDiffuse, R"({"highlight_guide": "auto"})"), &scene);
  EXPECT_FALSE(st.ok());
  EXPECT_NE(st.message().find("render.highlight_guide"), std::string::npos) << st.message();
}

TEST(Effects, ShadowGuideRejectsOtherValues) {
  Scene scene;
  const Status st = testing::Parse(SceneJson(kDiffuse, R"({"shadow_guide": "yes"})"), &scene);
  EXPECT_FALSE(st.ok());
  EXPECT_NE(st.message().find("render.shadow_guide"), std::string::npos) << st.message();
}

}  // namespace
}  // namespace dcm::embree
