#include "test_scenes.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "dcm/embree/scene_file.h"

namespace dcm::embree::testing {

namespace fs = std::filesystem;

TempDir::TempDir() {
  std::random_device rd;
  fs::path p = fs::temp_directory_path() / ("dcm_embree_test_" + std::to_string(rd()) + std::to_string(rd()));
  fs::create_directories(p);
  path_ = p.string();
}

TempDir::~TempDir() {
  std::error_code ec;
  fs::remove_all(path_, ec);
}

std::string TempDir::Write(const std::string& name, const std::string& text) const {
  std::string p = (fs::path(path_) / name).string();
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

Status Parse(const std::string& json, Scene* scene, const std::string& baseDir) {
  return ParseScene(json, "test.json", baseDir, scene);
}

std::unique_ptr<EmbreeProvider> MakeProvider(const std::string& json, const std::string& baseDir) {
  Scene scene;
  Status st = Parse(json, &scene, baseDir);
  EXPECT_TRUE(st.ok()) << st.message();
  std::unique_ptr<EmbreeProvider> p;
  if (st.ok()) {
    st = EmbreeProvider::Create(scene, &p);
    EXPECT_TRUE(st.ok()) << st.message();
  }
  return p;
}

std::vector<Point2i> AllPixels(const EmbreeProvider& p) {
  std::vector<Point2i> px;
  for (int y = 0; y < p.workHeight(); ++y)
    for (int x = 0; x < p.workWidth(); ++x) px.push_back({x, y});
  return px;
}

std::vector<ExactSample> EvaluateAll(EmbreeProvider& p, const std::vector<Point2i>& pixels, bool split) {
  std::vector<ExactSample> out(pixels.size());
  SampleRequest req;
  req.split = split;
  Status st = p.Evaluate(pixels, req, out);
  EXPECT_TRUE(st.ok()) << st.message();
  return out;
}

std::string SceneJson(const std::string& materials, const std::string& render, const std::string& lights,
                      const std::string& extraObjects) {
  std::string l = lights.empty()
                      ? R"({"type": "rect", "origin": [-0.5, 4, -0.5], "edge_u": [1, 0, 0], "edge_v": [0, 0, 1], "radiance": 10})"
                      : lights;
  return R"({
  "camera": {"position": [0, 3, 3], "look_at": [0, 0, 0], "fov": 40, "resolution": [32, 32]},
  "render": )" + render + R"(,
  "materials": )" + materials + R"(,
  "objects": [
    {"type": "quad", "id": 1, "material": "floor", "origin": [-3, 0, 3], "edge_u": [6, 0, 0], "edge_v": [0, 0, -6]},
    {"type": "sphere", "id": 2, "material": "ball", "center": [-0.5, 0.4, 0], "radius": 0.4},
    {"type": "box", "id": 3, "material": "block", "min": [0.2, 0, -0.3], "max": [0.8, 0.6, 0.3]})" +
         (extraObjects.empty() ? "" : ",\n    " + extraObjects) + R"(
  ],
  "lights": [)" + l + R"(]
})";
}

}  // namespace dcm::embree::testing
