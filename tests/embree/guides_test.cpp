// Guides: object and shader IDs and normals at known pixels, and through a
// planar mirror the IDs and normals of what the mirror shows.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "dcm/embree/integrator.h"
#include "test_scenes.h"

namespace dcm::embree {
namespace {

using testing::MakeProvider;

/// Camera at z=5 looking down -z at a quad in the plane z=0 (id 10), which
/// fills the view; 64x64 pixels, tan(fov/2) = 0.1763 (fov 20 degrees). Behind
/// the camera, out of its view, a large backdrop at z=10 (id 20) and a small
/// box around (0.5, 0.5, 7) (id 30). `wall` is the quad's material.
std::string MirrorScene(const std::string& wall) {
  return R"({
    "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 20, "resolution": [64, 64]},
    "render": {"mirror_depth": 2, "shadow_rays": 1},
    "materials": {"wall": )" + wall + R"(, "backdrop": {"type": "diffuse"}, "red": {"type": "diffuse", "color": [1, 0, 0]}},
    "objects": [
      {"type": "quad", "id": 10, "material": "wall", "origin": [-1.5, -1.5, 0], "edge_u": [3, 0, 0], "edge_v": [0, 3, 0]},
      {"type": "quad", "id": 20, "material": "backdrop", "origin": [-6, -6, 10], "edge_u": [12, 0, 0], "edge_v": [0, 12, 0]},
      {"type": "box", "id": 30, "material": "red", "min": [0.3, 0.3, 6.9], "max": [0.7, 0.7, 7.1]}
    ],
    "lights": [{"type": "point", "position": [0, 0, 8], "intensity": 5}]
  })";
}

/// The working pixel whose primary ray hits the plane z=0 at (x, y), camera as above.
Point2i PixelOf(float x, float y) {
  const float tanHalf = std::tan(10.f * 3.14159265f / 180.f);
  float sx = x / 5.f / tanHalf, sy = y / 5.f / tanHalf;
  return {int(std::floor((sx + 1.f) * 0.5f * 64.f)), int(std::floor((1.f - sy) * 0.5f * 64.f))};
}

GuideImage AllGuides(EmbreeProvider& p) {
  GuideImage g;
  GuideRequest req;
  req.objectId = req.shaderId = req.texture = req.normal = true;
  Status st = p.Guides({{0, 0}, {p.workWidth(), p.workHeight()}}, req, &g);
  EXPECT_TRUE(st.ok()) << st.message();
  return g;
}

TEST(Guides, DiffuseWallShowsItsOwnIds) {
  auto p = MakeProvider(MirrorScene(R"({"type": "diffuse"})"));
  ASSERT_TRUE(p);
  GuideImage g = AllGuides(*p);
  ASSERT_EQ(g.objectId.size(), 64u * 64u);
  for (size_t i = 0; i < g.objectId.size(); ++i) {
    ASSERT_EQ(g.objectId[i], 10u) << i;
    ASSERT_EQ(g.shaderId[i], 1u) << i;  // material index 0 + 1
    ASSERT_EQ(g.texture[i], RGB::Gray(1.f)) << i;  // untextured: tau = 1
  }
}

TEST(Guides, MirrorShowsTheIdsOfWhatItReflects) {
  auto p = MakeProvider(MirrorScene(R"({"type": "mirror"})"));
  ASSERT_TRUE(p);
  GuideImage g = AllGuides(*p);
  const Bounds2i& r = g.region;
  // A reflected ray from mirror point (x, y, 0) reaches z=7 at (2.4x, 2.4y):
  // the box (0.3..0.7) is seen around mirror point (0.21, 0.21).
  const Point2i onBox = PixelOf(0.21f, 0.21f);
  const Point2i onBackdrop = PixelOf(-0.6f, -0.6f);
  const uint32_t boxChain[2] = {10u, 30u}, backdropChain[2] = {10u, 20u};
  const uint32_t boxShaders[2] = {1u, 3u}, backdropShaders[2] = {1u, 2u};
  EXPECT_EQ(g.objectId[size_t(r.offset(onBox))], ChainId(boxChain, 2));
  EXPECT_EQ(g.shaderId[size_t(r.offset(onBox))], ChainId(boxShaders, 2));
  EXPECT_EQ(g.objectId[size_t(r.offset(onBackdrop))], ChainId(backdropChain, 2));
  EXPECT_EQ(g.shaderId[size_t(r.offset(onBackdrop))], ChainId(backdropShaders, 2));
  // Mirrored IDs never collide with plain ones, and the two chains differ.
  EXPECT_NE(ChainId(boxChain, 2) & 0x80000000u, 0u);
  EXPECT_NE(ChainId(boxChain, 2), ChainId(backdropChain, 2));
  // The box is behind the camera: only the mirror chain shows it. Predict, per
  // pixel, whether the reflected centre ray hits the box: the camera ray is
  // (sx, sy, -1), it meets the mirror at 5*(sx, sy), the reflection is at
  // sx*(5+z), sy*(5+z) at depth z. Pixels within 0.003 of the box's outline
  // are left out (float rounding of the tessellated box).
  const float tanHalf = std::tan(10.f * 3.14159265f / 180.f);
  auto hitsBox = [&](int px, int py, float grow) {
    float sx = (2.f * (float(px) + 0.5f) / 64.f - 1.f) * tanHalf;
    float sy = (1.f - 2.f * (float(py) + 0.5f) / 64.f) * tanHalf;
    if (sx <= 0.f || sy <= 0.f) return false;
    float z0 = 6.9f - grow, z1 = 7.1f + grow;
    z0 = std::max({z0, (0.3f - grow) / sx - 5.f, (0.3f - grow) / sy - 5.f});
    z1 = std::min({z1, (0.7f + grow) / sx - 5.f, (0.7f + grow) / sy - 5.f});
    return z0 <= z1;
  };
  int boxPixels = 0;
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      bool surelyIn = hitsBox(x, y, -0.003f), possiblyIn = hitsBox(x, y, 0.003f);
      bool isBox = g.objectId[size_t(r.offset({x, y}))] == ChainId(boxChain, 2);
      boxPixels += isBox;
      if (surelyIn) {
        EXPECT_TRUE(isBox) << x << "," << y;
      }
      if (!possiblyIn) {
        EXPECT_FALSE(isBox) << x << "," << y;
      }
    }
  }
  EXPECT_GT(boxPixels, 25);  // about 0.17 units of mirror = 6 pixels per side
}

TEST(Guides, SubRegionMatchesFullImage) {
  auto p = MakeProvider(MirrorScene(R"({"type": "mirror"})"));
  ASSERT_TRUE(p);
  GuideImage full = AllGuides(*p);
  GuideImage part;
  GuideRequest req;
  req.objectId = true;
  const Bounds2i region{{30, 17}, {45, 40}};
  ASSERT_TRUE(p->Guides(region, req, &part).ok());
  EXPECT_TRUE(part.shaderId.empty());
  EXPECT_TRUE(part.texture.empty());
  EXPECT_TRUE(part.normal.empty());
  for (int y = region.min.y; y < region.max.y; ++y)
    for (int x = region.min.x; x < region.max.x; ++x)
      ASSERT_EQ(part.objectId[size_t(region.offset({x, y}))], full.objectId[size_t(full.region.offset({x, y}))]);
}

// Guides() traces each row's primary rays as one coherent stream (Embree
// packets); the result is that of tracing every pixel's ray alone, to the
// bit: IDs through a mirror chain, and tau of an image-free procedural
// texture filtered with the ray differentials.
TEST(Guides, CoherentRowsEqualRayByRay) {
  const std::string textured = R"({
    "camera": {"position": [0, 2.2, 3.2], "look_at": [0, 0.3, 0], "fov": 40, "resolution": [48, 40]},
    "render": {"shadow_rays": 1, "mirror_depth": 2},
    "materials": {
      "floor": {"type": "diffuse", "texture": {"type": "planks", "plank_length": 0.5, "plank_width": 0.1}},
      "mirror": {"type": "mirror"},
      "ball": {"type": "diffuse", "texture": {"type": "checker", "scale": 8}}
    },
    "objects": [
      {"type": "quad", "material": "floor", "origin": [-3, 0, 3], "edge_u": [6, 0, 0], "edge_v": [0, 0, -6]},
      {"type": "quad", "material": "mirror", "origin": [-1, 0, -1], "edge_u": [2, 0, 0], "edge_v": [0, 1.5, 0]},
      {"type": "sphere", "material": "ball", "center": [0.3, 0.4, 0.2], "radius": 0.4}
    ],
    "lights": [{"type": "point", "position": [0, 3, 1], "intensity": 5}]
  })";
  for (const std::string& scene : {MirrorScene(R"({"type": "mirror"})"), textured}) {
    auto p = MakeProvider(scene);
    ASSERT_TRUE(p);
    const GuideImage g = AllGuides(*p);
    int hits = 0;
    for (int y = 0; y < p->workHeight(); ++y)
      for (int x = 0; x < p->workWidth(); ++x) {
        const size_t i = size_t(g.region.offset({x, y}));
        const PixelGuide one = p->GuidePixel(x, y, /*wantTau=*/true);
        ASSERT_EQ(g.objectId[i], one.objectId) << x << "," << y;
        ASSERT_EQ(g.shaderId[i], one.shaderId) << x << "," << y;
        for (int c = 0; c < 3; ++c) ASSERT_EQ(g.texture[i][c], one.tau[c]) << x << "," << y;
        ASSERT_EQ(g.normal[i].x, one.normal.x) << x << "," << y;
        ASSERT_EQ(g.normal[i].y, one.normal.y) << x << "," << y;
        ASSERT_EQ(g.normal[i].z, one.normal.z) << x << "," << y;
        hits += one.objectId != 0;
      }
    EXPECT_GT(hits, p->workWidth() * p->workHeight() / 2);
  }
}

TEST(Guides, ObjectsAndBackgroundAtKnownPixels) {
  // Looking straight down at a floor quad (id 5) spanning x,z in [-1, 1] with
  // a box (id 6) in the middle; the corners of the view miss the floor.
  auto p = MakeProvider(R"({
    "camera": {"position": [0, 5, 0], "look_at": [0, 0, 0], "up": [0, 0, -1], "fov": 30, "resolution": [40, 40]},
    "materials": {"a": {"type": "diffuse"}, "b": {"type": "diffuse"}},
    "objects": [
      {"type": "quad", "id": 5, "material": "a", "origin": [-1, 0, 1], "edge_u": [2, 0, 0], "edge_v": [0, 0, -2]},
      {"type": "box", "id": 6, "material": "b", "min": [-0.2, 0, -0.2], "max": [0.2, 0.3, 0.2]}
    ],
    "lights": [{"type": "point", "position": [0, 3, 0], "intensity": 1}]
  })");
  ASSERT_TRUE(p);
  GuideImage g = AllGuides(*p);
  auto at = [&](int x, int y) { return size_t(g.region.offset({x, y})); };
  // View half-width at the floor: 5 * tan(15 deg) = 1.34 > 1: corners see nothing.
  EXPECT_EQ(g.objectId[at(0, 0)], 0u);
  EXPECT_EQ(g.shaderId[at(0, 0)], 0u);
  EXPECT_EQ(g.objectId[at(20, 20)], 6u);
  EXPECT_EQ(g.shaderId[at(20, 20)], 2u);
  // x = 0.7 on the floor: pixel (0.7/1.34 + 1) * 20 = 30.4.
  EXPECT_EQ(g.objectId[at(30, 20)], 5u);
  EXPECT_EQ(g.shaderId[at(30, 20)], 1u);
}

// The normal guide is the shading normal of the surface a pixel shows, which
// the crease test of the engine reads (docs/ENGINE.md): on a sphere the
// sphere's own normal at the hit, through a mirror the normal of what it
// reflects, zero where nothing is hit.
TEST(Guides, NormalsAreThoseOfTheSurfaceShown) {
  // A sphere of radius 0.8 at the origin (64 segments) in front of a backdrop
  // that does not fill the view; camera and pixels as MirrorScene's.
  auto p = MakeProvider(R"({
    "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 20, "resolution": [64, 64]},
    "materials": {"a": {"type": "diffuse"}},
    "objects": [
      {"type": "sphere", "material": "a", "center": [0, 0, 0], "radius": 0.8},
      {"type": "quad", "material": "a", "origin": [-1.2, -1.2, -2], "edge_u": [1.0, 0, 0], "edge_v": [0, 1.0, 0]}
    ],
    "lights": [{"type": "point", "position": [0, 0, 8], "intensity": 5}]
  })");
  ASSERT_TRUE(p);
  EXPECT_TRUE(p->Capabilities().normal);
  const GuideImage g = AllGuides(*p);
  ASSERT_EQ(g.normal.size(), 64u * 64u);
  const float tanHalf = std::tan(10.f * 3.14159265f / 180.f);
  int onSphere = 0, onNothing = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const Vec3f n = g.normal[size_t(g.region.offset({x, y}))];
      // The centre ray o + t d, o = (0, 0, 5), against |p| = 0.8.
      const float sx = (2.f * (float(x) + 0.5f) / 64.f - 1.f) * tanHalf;
      const float sy = (1.f - 2.f * (float(y) + 0.5f) / 64.f) * tanHalf;
      const float len = std::sqrt(sx * sx + sy * sy + 1.f);
      const float dx = sx / len, dy = sy / len, dz = -1.f / len;
      const float b = 5.f * dz, disc = b * b - (25.f - 0.64f);
      if (disc > 0.02f) {  // clear of the outline, where facets and circle differ
        const float t = -b - std::sqrt(disc);
        const float hx = t * dx / 0.8f, hy = t * dy / 0.8f, hz = (5.f + t * dz) / 0.8f;
        // Facets 5.6 degrees apart: the interpolated normal lies within half a
        // step of the sphere's at the hit; cos(3 degrees) = 0.9986.
        EXPECT_GT(n.x * hx + n.y * hy + n.z * hz, 0.9986f) << x << "," << y;
        ++onSphere;
      } else if (disc < -0.02f && x > 40 && y > 40) {  // right of and below the backdrop, clear of the sphere
        EXPECT_EQ(n.x * n.x + n.y * n.y + n.z * n.z, 0.f) << x << "," << y;
        ++onNothing;
      }
    }
  EXPECT_GT(onSphere, 500);
  EXPECT_GT(onNothing, 50);

  // Through the planar mirror of MirrorScene the box's face at z = 6.9 is
  // seen from below: its normal (0, 0, -1), not the mirror's (0, 0, 1).
  auto m = MakeProvider(MirrorScene(R"({"type": "mirror"})"));
  ASSERT_TRUE(m);
  const GuideImage mg = AllGuides(*m);
  const Vec3f onBox = mg.normal[size_t(mg.region.offset(PixelOf(0.21f, 0.21f)))];
  EXPECT_NEAR(onBox.z, -1.f, 1e-5f);
}

TEST(Guides, RegionOutsideTheImageIsAnError) {
  auto p = MakeProvider(MirrorScene(R"({"type": "diffuse"})"));
  ASSERT_TRUE(p);
  GuideImage g;
  GuideRequest req;
  req.objectId = true;
  EXPECT_FALSE(p->Guides({{60, 60}, {70, 70}}, req, &g).ok());
}

}  // namespace
}  // namespace dcm::embree
