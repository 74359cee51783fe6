// `dcm render --target-psnr / --budget` judged by the tracer's preview
// (tools/dcm/render_preview.h), as a user runs it: which judge, what it
// delivers against the full render, what it costs, and when it is refused.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "../robustness/dcm_process.h"

namespace dcm::testing {
namespace {

// Two area lights of 64 shadow rays each over a checker floor, glossy spheres,
// a thin rod and a box (the held-out scene of quality_target_render_test.cpp
// with more shadow rays): a preview costs about 7 % of the full render.
const char* kAreaLights = R"({
  "camera": {"position": [0.4, 1.6, 3.0], "look_at": [0, 0.35, 0], "fov": 45, "resolution": [96, 96]},
  "render": {"shadow_rays": 64, "glossy_rays": 8, "supersampling": 1},
  "materials": {
    "floor": {"type": "diffuse", "color": 0.8, "texture": {"type": "checker", "scale": 8, "color0": 0.3, "color1": 0.9}},
    "shiny": {"type": "plastic", "color": [0.1, 0.5, 0.2], "specular": 0.4, "exponent": 60},
    "rod": {"type": "diffuse", "color": [0.9, 0.8, 0.2]},
    "box": {"type": "diffuse", "color": [0.6, 0.3, 0.5]}
  },
  "objects": [
    {"type": "quad", "material": "floor", "origin": [-3, 0, 3], "edge_u": [6, 0, 0], "edge_v": [0, 0, -6]},
    {"type": "sphere", "material": "shiny", "center": [-0.7, 0.25, 0.2], "radius": 0.25},
    {"type": "sphere", "material": "shiny", "center": [0.5, 0.3, -0.3], "radius": 0.3},
    {"type": "cylinder", "material": "rod", "from": [0.2, 0, 0.9], "to": [-0.4, 1.0, 0.5], "radius": 0.01},
    {"type": "box", "material": "box", "min": [0.6, 0, 0.3], "max": [1.1, 0.4, 0.8]}
  ],
  "lights": [
    {"type": "rect", "origin": [-1.5, 2.5, 0], "edge_u": [0.5, 0, 0], "edge_v": [0, 0, 0.5], "radiance": [9, 7, 5]},
    {"type": "rect", "origin": [1.5, 2.0, 1.0], "edge_u": [0.3, 0, 0], "edge_v": [0, 0, 0.3], "radiance": [3, 5, 9]}
  ]
})";

// Point lights: one shadow ray each, which a preview cannot divide.
const char* kPointLights = R"({
  "camera": {"position": [0.4, 1.6, 3.0], "look_at": [0, 0.35, 0], "fov": 45, "resolution": [64, 64]},
  "materials": {"floor": {"type": "diffuse", "color": 0.8}, "box": {"type": "diffuse", "color": [0.6, 0.3, 0.5]}},
  "objects": [
    {"type": "quad", "material": "floor", "origin": [-3, 0, 3], "edge_u": [6, 0, 0], "edge_v": [0, 0, -6]},
    {"type": "box", "material": "box", "min": [0.3, 0, -0.2], "max": [0.9, 0.5, 0.4]}
  ],
  "lights": [{"type": "point", "position": [-1, 2.5, 1], "intensity": 8}, {"type": "point", "position": [1, 2, 0], "intensity": 4}]
})";

nlohmann::json Stats(const TempDir& dir, const std::string& name) {
  return nlohmann::json::parse(ReadAll(dir.path() / name));
}

TEST(RenderGoal, JudgedByThePreviewItMeetsTheTargetWithFewerExactPixels) {
  TempDir dir("dcm_render_goal");
  dir.Write("scene.json", kAreaLights);
  Result full = RunDcm(dir.path(), {"render", "scene.json", "--full", "-o", "full.exr", "--stats", "full.json", "-q"});
  ASSERT_TRUE(full.exited && full.code == 0) << full.Describe();
  Result r = RunDcm(dir.path(), {"render", "scene.json", "--target-psnr", "40", "-o", "p.exr", "--stats", "p.json",
                                 "--compare", "full.exr", "-v"});
  ASSERT_TRUE(r.exited && r.code == 0) << r.Describe();
  EXPECT_NE(r.output.find("--target-psnr judged by the preview's estimate"), std::string::npos) << r.output;
  const nlohmann::json p = Stats(dir, "p.json");
  ASSERT_EQ(p["estimated_psnr_from"], "preview");
  EXPECT_TRUE(p["quality"]["target_reached"].get<bool>());
  const double truth = p["reference"]["psnr"], estimate = p["estimated_psnr"];
  // Issue 22's tolerances: the truth at most 0.5 dB below the target, the
  // estimate within 1.5 dB of the truth.
  EXPECT_GE(truth, 39.5);
  EXPECT_NEAR(estimate, truth, 1.5);
  // The preview's rays are the run's and are reported apart.
  const double previewRays = p["quality"]["preview"]["rays"]["total"];
  EXPECT_GT(previewRays, 0);
  EXPECT_GT(p["rays"]["total"].get<double>(), previewRays);
  EXPECT_LT(p["quality"]["preview"]["cost_share"].get<double>(), 0.1);
  EXPECT_EQ(p["quality"]["validation_pixels"], 0);

  // The same goal judged by validation pixels spends more exact pixels: the
  // validation's own and a search that starts at the default threshold.
  Result v = RunDcm(dir.path(), {"render", "scene.json", "--target-psnr", "40", "-o", "v.exr", "--stats", "v.json",
                                 "--compare", "full.exr", "--estimate-from", "validation", "-q"});
  ASSERT_TRUE(v.exited && v.code == 0) << v.Describe();
  const nlohmann::json val = Stats(dir, "v.json");
  EXPECT_EQ(val["estimated_psnr_from"], "validation");
  EXPECT_GT(val["exact_fraction"].get<double>(), p["exact_fraction"].get<double>());

  // A budget judged by the preview never exceeds it.
  Result b = RunDcm(dir.path(), {"render", "scene.json", "--budget", "0.12", "-o", "b.exr", "--stats", "b.json", "-q"});
  ASSERT_TRUE(b.exited && b.code == 0) << b.Describe();
  const nlohmann::json bs = Stats(dir, "b.json");
  EXPECT_EQ(bs["estimated_psnr_from"], "preview");
  EXPECT_LE(bs["exact_fraction"].get<double>(), 0.12);
}

TEST(RenderGoal, WhereThePreviewCostsMoreThanItSparesValidationPixelsJudge) {
  TempDir dir("dcm_render_goal");
  dir.Write("scene.json", kPointLights);
  Result r = RunDcm(dir.path(), {"render", "scene.json", "--target-psnr", "40", "-o", "a.exr", "--stats", "a.json", "-v"});
  ASSERT_TRUE(r.exited && r.code == 0) << r.Describe();
  EXPECT_NE(r.output.find("judged by validation pixels: a preview would cost"), std::string::npos) << r.output;
  const nlohmann::json a = Stats(dir, "a.json");
  EXPECT_EQ(a["estimated_psnr_from"], "validation");
  EXPECT_NE(a["quality"]["validation_because"].get<std::string>().find("would cost"), std::string::npos);
  // Asked for, the preview judges all the same.
  Result f = RunDcm(dir.path(), {"render", "scene.json", "--target-psnr", "40", "-o", "f.exr", "--stats", "f.json",
                                 "--estimate-from", "preview", "-q"});
  ASSERT_TRUE(f.exited && f.code == 0) << f.Describe();
  EXPECT_EQ(Stats(dir, "f.json")["estimated_psnr_from"], "preview");
}

TEST(RenderGoal, ThePreviewAskedForWhereItCannotJudgeIsAUsageError) {
  TempDir dir("dcm_render_goal");
  dir.Write("scene.json", kAreaLights);
  for (const std::vector<std::string>& extra :
       {std::vector<std::string>{"--target-psnr", "40", "--supersampling", "2"},
        std::vector<std::string>{"--target-psnr", "40", "--spp", "4"},
        std::vector<std::string>{"--threshold", "0.1"}}) {
    std::vector<std::string> args{"render", "scene.json", "-o", "out.exr", "--estimate-from", "preview", "-q"};
    args.insert(args.end(), extra.begin(), extra.end());
    Result r = RunDcm(dir.path(), args);
    EXPECT_TRUE(r.exited && r.code == 2) << r.Describe();
    EXPECT_NE(r.output.find("--estimate-from preview"), std::string::npos) << r.output;
    EXPECT_EQ(dir.Files(), std::set<std::string>{"scene.json"});  // nothing written
  }
}

}  // namespace
}  // namespace dcm::testing
