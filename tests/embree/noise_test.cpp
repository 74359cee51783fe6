// Monte Carlo noise of the tracer: samples_per_pixel independent estimates,
// their mean as the sample and the variance of that mean; scene overrides.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "dcm/embree/scene_file.h"
#include "test_scenes.h"

namespace dcm::embree {
namespace {

using testing::AllPixels;
using testing::MakeProvider;
using testing::SceneJson;

const char* kDiffuse = R"({"floor": {"type": "diffuse"}, "ball": {"type": "diffuse"}, "block": {"type": "diffuse"}})";

std::vector<ExactSample> Evaluate(EmbreeProvider& p, bool variance) {
  const std::vector<Point2i> px = AllPixels(p);
  std::vector<ExactSample> s(px.size());
  SampleRequest req;
  req.variance = variance;
  EXPECT_TRUE(p.Evaluate(px, req, s).ok());
  return s;
}

TEST(TracerNoise, OneEstimateReportsNoVariance) {
  auto p = MakeProvider(SceneJson(kDiffuse, R"({"shadow_rays": 1})"));
  ASSERT_TRUE(p);
  EXPECT_FALSE(p->Capabilities().variance);
}

TEST(TracerNoise, ReportedVarianceMatchesTheSpreadAcrossSeeds) {
  // Soft shadows with one shadow ray per estimate, 16 estimates per pixel.
  // The reported variance of the mean must match the variance of the mean
  // across 24 independent renders (other seeds): summed over the pixels in
  // penumbrae, the two agree within 20 % (the seed-to-seed estimate over
  // ~24 x hundreds of pixel values is good to a few percent).
  const int kSeeds = 24;
  std::vector<std::vector<ExactSample>> runs;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    auto p = MakeProvider(SceneJson(kDiffuse, R"({"shadow_rays": 1, "samples_per_pixel": 16, "seed": )" +
                                                  std::to_string(seed) + "}"));
    ASSERT_TRUE(p);
    ASSERT_TRUE(p->Capabilities().variance);
    runs.push_back(Evaluate(*p, true));
  }
  double reported = 0, spread = 0;
  int noisy = 0;
  for (size_t i = 0; i < runs[0].size(); ++i) {
    double mean = 0, meanReported = 0;
    for (const auto& r : runs) mean += r[i].L.g, meanReported += r[i].variance.g;
    mean /= kSeeds;
    meanReported /= kSeeds;
    double var = 0;
    for (const auto& r : runs) var += (r[i].L.g - mean) * (r[i].L.g - mean);
    var /= kSeeds - 1;
    if (meanReported <= 0) {
      // Lit or shadowed for certain (or background): no noise at all.
      EXPECT_LT(var, 1e-12) << "pixel " << i;
      continue;
    }
    reported += meanReported;
    spread += var;
    ++noisy;
  }
  ASSERT_GT(noisy, 20) << "the scene has no penumbra";
  EXPECT_NEAR(reported / spread, 1.0, 0.2) << noisy << " noisy pixels";
}

TEST(TracerNoise, MeanOfMoreEstimatesIsCloser) {
  // The variance of the mean falls as 1/spp: 64 estimates report a quarter
  // of the variance of 16 (within 25 %, summed over the noisy pixels).
  auto p16 = MakeProvider(SceneJson(kDiffuse, R"({"shadow_rays": 1, "samples_per_pixel": 16})"));
  auto p64 = MakeProvider(SceneJson(kDiffuse, R"({"shadow_rays": 1, "samples_per_pixel": 64})"));
  ASSERT_TRUE(p16 && p64);
  double v16 = 0, v64 = 0;
  for (const auto& s : Evaluate(*p16, true)) v16 += s.variance.g;
  for (const auto& s : Evaluate(*p64, true)) v64 += s.variance.g;
  ASSERT_GT(v16, 0);
  EXPECT_NEAR(v64 / v16, 0.25, 0.25 * 0.25);
}

TEST(SceneOverrides, SetKeysBeforeValidation) {
  testing::TempDir dir;
  const std::string path = dir.Write("s.json", SceneJson(kDiffuse, R"({"shadow_rays": 4})"));
  Scene s;
  const std::vector<std::string> ok = {"render.samples_per_pixel=8", R"(render.indirect={"bounces": 1, "rays": 2})",
                                       "camera.fov=30"};
  ASSERT_TRUE(LoadSceneFile(path, &s, ok).ok());
  EXPECT_EQ(s.render.samplesPerPixel, 8);
  EXPECT_EQ(s.render.indirectBounces, 1);
  EXPECT_EQ(s.render.indirectRays, 2);
  EXPECT_EQ(s.render.shadowRays, 4);
  // Overridden values are validated like the file's own, naming the key.
  const std::vector<std::string> bad = {"render.samples_per_pixel=0"};
  Status st = LoadSceneFile(path, &s, bad);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("render.samples_per_pixel"), std::string::npos) << st.message();
  const std::vector<std::string> malformed = {"render.shadow_rays"};
  st = LoadSceneFile(path, &s, malformed);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("override 'render.shadow_rays': expected KEY.PATH=VALUE"), std::string::npos)
      << st.message();
}

}  // namespace
}  // namespace dcm::embree
