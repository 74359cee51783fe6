// The split L = L_i * tau + L_c of textured scenes (paper 3.3).
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <cstring>

#include "test_scenes.h"

namespace dcm::embree {
namespace {

using testing::AllPixels;
using testing::MakeProvider;
using testing::SceneJson;

const char* kRender = R"({"shadow_rays": 4, "glossy_rays": 4, "mirror_depth": 2})";

std::string Materials(const std::string& floorTexture) {
  return R"({"floor": {"type": "plastic", "color": [0.9, 0.8, 0.7], "specular": 0.3, "exponent": 40)" +
         (floorTexture.empty() ? std::string() : ", \"texture\": " + floorTexture) +
         R"(}, "ball": {"type": "mirror"}, "block": {"type": "diffuse", "texture": {"type": "checker", "scale": 5}}})";
}

TEST(Split, RadianceIsLiTimesGuideTauPlusLc) {
  auto p = MakeProvider(SceneJson(Materials(R"({"type": "planks", "scale": 2})"), kRender));
  ASSERT_TRUE(p);
  ASSERT_TRUE(p->Capabilities().splitRadiance);
  std::vector<Point2i> pixels = AllPixels(*p);
  auto s = testing::EvaluateAll(*p, pixels, true);
  GuideImage g;
  GuideRequest req;
  req.texture = true;
  ASSERT_TRUE(p->Guides({{0, 0}, {p->workWidth(), p->workHeight()}}, req, &g).ok());
  int textured = 0, withLc = 0;
  for (size_t i = 0; i < pixels.size(); ++i) {
    const RGB tau = g.texture[i];
    const RGB rebuilt = s[i].Li * tau + s[i].Lc;
    // Same float operations as the provider's own L: equal up to rounding of
    // one multiply-add (a few ulps), hence the relative 1e-6.
    for (int c = 0; c < 3; ++c) {
      ASSERT_NEAR(rebuilt[c], s[i].L[c], 1e-6f * std::max(1.f, s[i].L[c])) << i;
    }
    if (!(tau == RGB::Gray(1.f))) ++textured;
    if (Luminance(s[i].Lc) > 0.f && Luminance(s[i].Li) > 0.f) ++withLc;
  }
  EXPECT_GT(textured, int(pixels.size()) / 2);  // the floor fills most of the view
  EXPECT_GT(withLc, 0);                        // glossy floor: Lc carries the highlight
}

TEST(Split, LiIsTheRadianceBeforeTexturing) {
  // Li of the textured scene equals L_i of the same scene without the texture,
  // bit for bit: the texture multiplies the diffuse part only, after shading.
  // (Lc may differ: the mirror and the glossy lobe reflect the textured floor.)
  auto textured = MakeProvider(SceneJson(Materials(R"({"type": "checker", "scale": 7})"), kRender));
  auto plain = MakeProvider(SceneJson(Materials(""), kRender));
  ASSERT_TRUE(textured && plain);
  std::vector<Point2i> pixels = AllPixels(*textured);
  auto a = testing::EvaluateAll(*textured, pixels, true);
  auto b = testing::EvaluateAll(*plain, pixels, true);
  for (size_t i = 0; i < pixels.size(); ++i) {
    PixelRadiance pr = plain->EvaluatePixel(pixels[i].x, pixels[i].y);
    if (!(pr.tau == RGB::Gray(1.f))) continue;  // the block keeps its texture in both scenes
    ASSERT_EQ(std::memcmp(&a[i].Li, &b[i].Li, sizeof(RGB)), 0) << i;
  }
}

TEST(Split, MirrorPixelsCarryEverythingInLc) {
  auto p = MakeProvider(SceneJson(Materials(R"({"type": "planks"})"), kRender));
  ASSERT_TRUE(p);
  // The ball (a mirror) is at (-0.5, 0.4, 0); the pixel straight at its centre.
  GuideImage g;
  GuideRequest req;
  req.objectId = true;
  ASSERT_TRUE(p->Guides({{0, 0}, {32, 32}}, req, &g).ok());
  int mirrorPixels = 0;
  for (int y = 0; y < 32; ++y) {
    for (int x = 0; x < 32; ++x) {
      uint32_t id = g.objectId[size_t(g.region.offset({x, y}))];
      if ((id & 0x80000000u) == 0 || id == 0) continue;  // not seen through the mirror
      ++mirrorPixels;
      PixelRadiance r = p->EvaluatePixel(x, y);
      EXPECT_EQ(r.Li, RGB{});
      EXPECT_EQ(r.tau, RGB::Gray(1.f));
      EXPECT_EQ(r.L, r.Lc);
    }
  }
  EXPECT_GT(mirrorPixels, 10);
}

TEST(Split, ImageTextureIsDecodedFromSrgbAndFiltered) {
  testing::TempDir dir;
  // An 8x8 PNG of constant sRGB value 128: linear 0.2158 at any filter width.
  const std::string png = dir.path() + "/gray.png";
  {
    auto out = OIIO::ImageOutput::create(png);
    ASSERT_TRUE(out);
    OIIO::ImageSpec spec(8, 8, 3, OIIO::TypeDesc::UINT8);
    std::vector<uint8_t> px(8 * 8 * 3, 128);
    ASSERT_TRUE(out->open(png, spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, px.data()));
    out->close();
  }
  auto p = MakeProvider(SceneJson(Materials(R"({"type": "image", "file": "gray.png", "scale": 3})"), kRender),
                        dir.path());
  ASSERT_TRUE(p);
  GuideImage g;
  GuideRequest req;
  req.texture = true;
  req.objectId = true;
  ASSERT_TRUE(p->Guides({{0, 0}, {32, 32}}, req, &g).ok());
  int floorPixels = 0;
  const float expected = std::pow((128.f / 255.f + 0.055f) / 1.055f, 2.4f);
  for (size_t i = 0; i < g.objectId.size(); ++i) {
    if (g.objectId[i] != 1u) continue;
    ++floorPixels;
    // 8-bit input: the filtered value is exact up to float rounding.
    EXPECT_NEAR(g.texture[i].r, expected, 1e-4f);
    EXPECT_NEAR(g.texture[i].b, expected, 1e-4f);
  }
  EXPECT_GT(floorPixels, 100);
}

}  // namespace
}  // namespace dcm::embree
