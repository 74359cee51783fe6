// Scene files: errors name the file, the key path, the line and column.
#include <gtest/gtest.h>

#include <string>

#include "dcm/embree/embree_provider.h"
#include "dcm/embree/scene_file.h"
#include "test_scenes.h"

namespace dcm::embree {
namespace {

using testing::Parse;
using testing::SceneJson;
using testing::TempDir;

const char* kMaterials = R"({"floor": {"type": "diffuse"}, "ball": {"type": "diffuse"}, "block": {"type": "diffuse"}})";

TEST(SceneFile, ValidSceneParses) {
  Scene s;
  Status st = Parse(SceneJson(kMaterials), &s);
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_EQ(s.objects.size(), 3u);
  EXPECT_EQ(s.materials.size(), 3u);
  EXPECT_EQ(s.materials[1].name, "ball");  // file order, not sorted
  EXPECT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.camera.width, 32);
}

TEST(SceneFile, SyntaxErrorReportsLineAndColumn) {
  const std::string line2 = R"(  "camera": {"position": [0, 0, 5] "look_at": [0, 0, 0]})";
  const std::string text = "{\n" + line2 + "\n}\n";
  Scene s;
  Status st = Parse(text, &s);
  ASSERT_FALSE(st.ok());
  // The parser stops on the last character of the unexpected token "look_at".
  const size_t column = line2.find("\"look_at\"") + 9;
  EXPECT_NE(st.message().find("test.json:2:" + std::to_string(column) + ": syntax error"), std::string::npos)
      << st.message();
}

TEST(SceneFile, SyntaxErrorOnLaterLine) {
  Scene s;
  Status st = Parse("{\n\n\n  \"camera\": [1, 2,,]\n}", &s);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("test.json:4:"), std::string::npos) << st.message();
}

TEST(SceneFile, UnknownKeyNamesItsPath) {
  std::string json = SceneJson(kMaterials, "{}", "",
                               R"({"type": "sphere", "material": "ball", "radius": 1, "radiuss": 2})");
  Scene s;
  Status st = Parse(json, &s);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("test.json: objects[3].radiuss: unknown key"), std::string::npos) << st.message();
}

TEST(SceneFile, UnknownKeyInRenderSettings) {
  Scene s;
  Status st = Parse(SceneJson(kMaterials, R"({"indirect": {"bounce": 1}})"), &s);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("render.indirect.bounce: unknown key"), std::string::npos) << st.message();
}

TEST(SceneFile, WrongTypeNamesKeyAndTypes) {
  Scene s;
  Status st = Parse(SceneJson(kMaterials, R"({"shadow_rays": "many"})"), &s);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("render.shadow_rays: expected an integer, found a string"), std::string::npos)
      << st.message();

  st = Parse(SceneJson(R"({"floor": {"type": "diffuse", "color": [1, 2]}, "ball": {"type": "diffuse"},
                          "block": {"type": "diffuse"}})"),
             &s);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("materials.floor.color: expected a colour"), std::string::npos) << st.message();
}

TEST(SceneFile, OutOfRangeValue) {
  Scene s;
  Status st = Parse(SceneJson(kMaterials, R"({"supersampling": 0})"), &s);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("render.supersampling: value 0 out of range"), std::string::npos) << st.message();
}

TEST(SceneFile, UnknownMaterialReference) {
  Scene s;
  Status st = Parse(SceneJson(R"({"floor": {"type": "diffuse"}, "ball": {"type": "diffuse"}})"), &s);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("objects[2].material: unknown material 'block'"), std::string::npos) << st.message();
}

TEST(SceneFile, MissingMeshFileNamesKeyAndFile) {
  TempDir dir;
  Scene s;
  Status st = Parse(SceneJson(kMaterials, "{}", "", R"({"type": "mesh", "material": "ball", "file": "nope.obj"})"),
                    &s, dir.path());
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("objects[3].file: file '"), std::string::npos) << st.message();
  EXPECT_NE(st.message().find("nope.obj' not found"), std::string::npos) << st.message();
}

TEST(SceneFile, UnreadableMeshIsReportedAtCreation) {
  TempDir dir;
  dir.Write("broken.obj", "this is not a mesh\n\x01\x02\x03");
  Scene s;
  Status st = Parse(SceneJson(kMaterials, "{}", "", R"({"type": "mesh", "material": "ball", "file": "broken.obj"})"),
                    &s, dir.path());
  ASSERT_TRUE(st.ok()) << st.message();
  std::unique_ptr<EmbreeProvider> p;
  st = EmbreeProvider::Create(s, &p);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("objects[3].file"), std::string::npos) << st.message();
  EXPECT_NE(st.message().find("broken.obj"), std::string::npos) << st.message();
}

TEST(SceneFile, MissingTextureFileNamesKeyAndFile) {
  TempDir dir;
  Scene s;
  Status st = Parse(SceneJson(R"({"floor": {"type": "diffuse", "texture": {"type": "image", "file": "wood.png"}},
                                  "ball": {"type": "diffuse"}, "block": {"type": "diffuse"}})"),
                    &s, dir.path());
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("materials.floor.texture.file: file '"), std::string::npos) << st.message();
  EXPECT_NE(st.message().find("wood.png' not found"), std::string::npos) << st.message();
}

TEST(SceneFile, UnreadableTextureIsReportedAtCreation) {
  TempDir dir;
  dir.Write("wood.png", "not an image");
  Scene s;
  Status st = Parse(SceneJson(R"({"floor": {"type": "diffuse", "texture": {"type": "image", "file": "wood.png"}},
                                  "ball": {"type": "diffuse"}, "block": {"type": "diffuse"}})"),
                    &s, dir.path());
  ASSERT_TRUE(st.ok()) << st.message();
  std::unique_ptr<EmbreeProvider> p;
  st = EmbreeProvider::Create(s, &p);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("materials.floor.texture: cannot read texture"), std::string::npos) << st.message();
}

TEST(SceneFile, ZeroLightsIsAnError) {
  std::string json = SceneJson(kMaterials);
  json = json.substr(0, json.find("\"lights\"")) + "\"lights\": []\n}";
  Scene s;
  Status st = Parse(json, &s);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("test.json: lights: the scene has no lights"), std::string::npos) << st.message();
}

TEST(SceneFile, MissingCameraIsAnError) {
  Scene s;
  Status st = Parse(R"({"materials": {}, "objects": [], "lights": []})", &s);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("camera: missing"), std::string::npos) << st.message();
}

TEST(SceneFile, LoadSceneFileReportsMissingFile) {
  Scene s;
  Status st = LoadSceneFile("/nonexistent/dir/scene.json", &s);
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("/nonexistent/dir/scene.json"), std::string::npos) << st.message();
}

TEST(SceneFile, MeshFromObjLoads) {
  TempDir dir;
  dir.Write("tri.obj", "v -1 0 -1\nv 1 0 -1\nv 0 0 1\nvt 0 0\nvt 1 0\nvt 0.5 1\nf 1/1 2/2 3/3\n");
  std::string path = dir.Write("scene.json", SceneJson(kMaterials, "{}", "",
                                                       R"({"type": "mesh", "material": "ball", "file": "tri.obj",
                                                          "transform": {"translate": [0, 0.05, 0]}})"));
  std::unique_ptr<EmbreeProvider> p;
  Status st = EmbreeProvider::FromFile(path, &p);
  ASSERT_TRUE(st.ok()) << st.message();
  EXPECT_EQ(p->scene().objects[3].shape, ShapeKind::kMesh);
  // 2 (quad) + 12 (box) + the sphere's triangles + 1 (the OBJ triangle).
  Scene plain;
  ASSERT_TRUE(Parse(SceneJson(kMaterials), &plain).ok());
  std::unique_ptr<EmbreeProvider> q;
  ASSERT_TRUE(EmbreeProvider::Create(plain, &q).ok());
  EXPECT_EQ(p->triangleCount(), q->triangleCount() + 1);
}

}  // namespace
}  // namespace dcm::embree
