// The tracer's preview (EmbreeProvider::RenderPreview), which judges dcm
// render's goals: an unbiased estimate of the same pixels as the exact ones,
// with the variance of its own noise, for a share of the rays.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "test_scenes.h"

namespace dcm::embree {
namespace {

using testing::AllPixels;
using testing::EvaluateAll;
using testing::MakeProvider;

// Two area lights of 64 shadow rays each over a textured floor, a sphere and
// a box: the rays a preview divides. Diffuse only: a glossy lobe lit by a small
// bright light has heavy tails, and one image's squared error then swings
// (2.3-2.45 times the summed variance with this sphere glossy, while the mean
// of 32 previews lay within its noise of the exact render).
const char* kAreaLights = R"({
  "camera": {"position": [0.4, 1.6, 3.0], "look_at": [0, 0.35, 0], "fov": 45, "resolution": [64, 64]},
  "render": {"shadow_rays": 64, "glossy_rays": 8, "supersampling": 1},
  "materials": {
    "floor": {"type": "diffuse", "color": 0.8, "texture": {"type": "checker", "scale": 8, "color0": 0.3, "color1": 0.9}},
    "ball": {"type": "diffuse", "color": [0.1, 0.5, 0.2]},
    "box": {"type": "diffuse", "color": [0.6, 0.3, 0.5]}
  },
  "objects": [
    {"type": "quad", "material": "floor", "origin": [-3, 0, 3], "edge_u": [6, 0, 0], "edge_v": [0, 0, -6]},
    {"type": "sphere", "material": "ball", "center": [-0.5, 0.3, 0.2], "radius": 0.3},
    {"type": "box", "material": "box", "min": [0.3, 0, -0.2], "max": [0.9, 0.5, 0.4]}
  ],
  "lights": [
    {"type": "rect", "origin": [-1.5, 2.5, 0], "edge_u": [0.5, 0, 0], "edge_v": [0, 0, 0.5], "radiance": [9, 7, 5]},
    {"type": "rect", "origin": [1.5, 2.0, 1.0], "edge_u": [0.3, 0, 0], "edge_v": [0, 0, 0.3], "radiance": [3, 5, 9]}
  ]
})";

TEST(TracerPreview, IsUnbiasedAndItsVarianceIsItsNoise) {
  auto p = MakeProvider(kAreaLights);
  ASSERT_TRUE(p);
  const std::vector<ExactSample> exact = EvaluateAll(*p, AllPixels(*p), true);
  const RayCounts before = p->rayCounts();
  std::vector<ExactSample> preview;
  ASSERT_TRUE(p->RenderPreview(32, &preview).ok());
  ASSERT_EQ(preview.size(), exact.size());
  const RayCounts after = p->rayCounts();
  // Its rays count in the provider's: 2 + 2 shadow rays a lit pixel instead of 128.
  EXPECT_GT(after.shadow, before.shadow);
  EXPECT_LT(double(after.shadow - before.shadow), 0.1 * double(before.shadow));
  double squared = 0, variance = 0, difference = 0;
  for (size_t i = 0; i < exact.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double d = double(preview[i].L[c]) - double(exact[i].L[c]);
      squared += d * d;
      difference += d;
      variance += preview[i].variance[c];
      EXPECT_GE(preview[i].variance[c], 0.f);
    }
  ASSERT_GT(variance, 0);
  // The squared difference from the exact render (64 shadow rays a light, a
  // sixteenth of the preview's variance besides) over the preview's variance:
  // 1.06 expected (0.93 here); 12288 values of one degree of freedom each keep
  // the sum's ratio within a third of it.
  EXPECT_NEAR(squared / variance, 1.06, 0.35) << "squared " << squared << ", variance " << variance;
  // Unbiased: the summed difference within 4 of its standard deviations.
  EXPECT_LT(std::abs(difference), 4 * std::sqrt(variance)) << difference;
}

}  // namespace
}  // namespace dcm::embree
