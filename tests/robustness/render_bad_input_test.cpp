// Bad scene input through the `dcm render` binary (run as a subprocess, its
// path in DCM_BINARY): syntax and schema errors, missing and corrupt meshes
// and textures, degenerate and non-finite geometry, a camera inside an object,
// no lights. Each must give a clear message naming the file and the key, exit
// with a code != 0 (and not by a signal), create no output file, and leave an
// existing output file byte-for-byte as it was (atomic writes), with no
// temporary files left behind.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dcm_process.h"

namespace {

namespace fs = std::filesystem;

using namespace dcm::testing;

/// Whether `text` contains a match of `pattern`, where '*' stands for any
/// characters and '#' for one or more digits; everything else is literal.
bool MatchHere(const char* t, const char* p) {
  if (*p == '\0') return true;
  if (*p == '*') {
    for (const char* u = t;; ++u) {
      if (MatchHere(u, p + 1)) return true;
      if (*u == '\0') return false;
    }
  }
  if (*p == '#') {
    if (!std::isdigit(static_cast<unsigned char>(*t))) return false;
    for (const char* u = t; std::isdigit(static_cast<unsigned char>(*u)); ++u)
      if (MatchHere(u + 1, p + 1)) return true;
    return false;
  }
  return *t != '\0' && *t == *p && MatchHere(t + 1, p + 1);
}
bool Contains(const std::string& text, const std::string& pattern) {
  for (size_t i = 0; i <= text.size(); ++i)
    if (MatchHere(text.c_str() + i, pattern.c_str())) return true;
  return false;
}

const char* kPrecious = "an earlier render: must survive a failed run\n";

/// A 16x16 scene: one diffuse material "m", the given objects and lights.
std::string Scene(const std::string& objects,
                  const std::string& lights = R"([{"type": "point", "position": [0, 3, 2], "intensity": 10}])",
                  const std::string& camera = R"({"position": [0, 1, 4], "look_at": [0, 0.5, 0], "resolution": [16, 16]})",
                  const std::string& materials = R"({"m": {"type": "diffuse"}})") {
  return "{\n  \"camera\": " + camera + ",\n  \"render\": {\"shadow_rays\": 1},\n  \"materials\": " + materials +
         ",\n  \"objects\": " + objects + ",\n  \"lights\": " + lights + "\n}\n";
}

const std::string kBox = R"([{"type": "box", "material": "m", "min": [-1, 0, -1], "max": [1, 1, 1]}])";

/// Renders `scene.json` twice: once to a fresh output name (must not appear,
/// nor the stats/sample-map/preview outputs), once over an existing output
/// (must be unchanged). Checks the exit and that `expected` (a regex) matches
/// the message (a Contains() pattern). Returns the first run's result.
Result ExpectRejected(const TempDir& dir, const std::string& expected) {
  const std::set<std::string> before = dir.Files();
  Result r = RunDcm(dir.path(), {"render", "scene.json", "-o", "fresh.exr", "--stats", "fresh.json",
                                 "--sample-map", "fresh_map.png", "--preview", "fresh.png", "--quiet"});
  EXPECT_TRUE(r.exited) << r.Describe();
  EXPECT_NE(r.code, 0) << r.Describe();
  EXPECT_TRUE(Contains(r.output, expected)) << "expected '" << expected << "' in: " << r.Describe();
  EXPECT_EQ(dir.Files(), before) << "files appeared (outputs or temporaries); " << r.Describe();

  dir.Write("existing.exr", kPrecious);
  const std::set<std::string> before2 = dir.Files();
  Result r2 = RunDcm(dir.path(), {"render", "scene.json", "-o", "existing.exr", "--quiet"});
  EXPECT_TRUE(r2.exited && r2.code != 0) << r2.Describe();
  const std::string after = ReadAll(dir.path() / "existing.exr");
  EXPECT_TRUE(after == kPrecious) << "existing output replaced or truncated (now " << after.size() << " bytes, "
                                  << (after.rfind("v/1\x01", 0) == 0 ? "an EXR" : "not an EXR") << "); "
                                  << r2.Describe();
  EXPECT_EQ(dir.Files(), before2) << r2.Describe();
  fs::remove(dir.path() / "existing.exr");
  return r;
}

// The harness itself: a good scene renders, creates every output and replaces
// an existing output atomically. Without this the rejection tests could pass
// against a binary that never writes anything.
TEST(RenderBadInput, ControlGoodSceneWritesItsOutputs) {
  TempDir dir;
  dir.Write("scene.json", Scene(kBox));
  Result r = RunDcm(dir.path(), {"render", "scene.json", "-o", "fresh.exr", "--stats", "fresh.json", "--sample-map",
                                 "fresh_map.png", "--preview", "fresh.png", "--quiet"});
  ASSERT_TRUE(r.exited && r.code == 0) << r.Describe();
  for (const char* f : {"fresh.exr", "fresh.json", "fresh_map.png", "fresh.png"})
    EXPECT_TRUE(fs::is_regular_file(dir.path() / f)) << f;
  dir.Write("existing.exr", kPrecious);
  r = RunDcm(dir.path(), {"render", "scene.json", "-o", "existing.exr", "--quiet"});
  ASSERT_TRUE(r.exited && r.code == 0) << r.Describe();
  EXPECT_EQ(ReadAll(dir.path() / "existing.exr").substr(0, 4), std::string("\x76\x2f\x31\x01", 4))
      << "not replaced by an EXR";
  EXPECT_EQ(dir.Files(), (std::set<std::string>{"scene.json", "fresh.exr", "fresh.json", "fresh_map.png",
                                                "fresh.png", "existing.exr"}));
}

// With --with-reference the stats give what two processes, one per run, would
// take end to end (issue 21: the start-up counts): each at least its run and the
// start-up, neither more than the process took. Tolerance: the start is known
// to a clock tick (10 ms).
TEST(RenderCommand, WithReferenceReportsEndToEndTimes) {
  TempDir dir;
  dir.Write("scene.json", Scene(kBox));
  const auto t0 = std::chrono::steady_clock::now();
  Result r = RunDcm(dir.path(), {"render", "scene.json", "-o", "out.exr", "--with-reference", "--stats", "s.json",
                                 "--quiet"});
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(r.exited && r.code == 0) << r.Describe();
  const nlohmann::json j = nlohmann::json::parse(ReadAll(dir.path() / "s.json"));
  ASSERT_TRUE(j.contains("end_to_end")) << j.dump();
  const nlohmann::json& e = j["end_to_end"];
  const double tick = 0.011, startup = e["startup_s"], dcmS = e["dcm_s"], fullS = e["full_s"];
  EXPECT_GT(startup, 0);
  EXPECT_GE(dcmS, startup + j["time_wall_s"].get<double>() - tick) << e.dump();
  EXPECT_GE(fullS, startup + j["full"]["time_wall_s"].get<double>() - tick) << e.dump();
  EXPECT_LE(dcmS, wall + tick) << e.dump();
  EXPECT_LE(fullS, wall + tick) << e.dump();
  EXPECT_DOUBLE_EQ(e["speedup"].get<double>(), fullS / dcmS);
}

TEST(RenderBadInput, MissingSceneFile) {
  TempDir dir;
  ExpectRejected(dir, "scene.json");
}

TEST(RenderBadInput, EmptySceneFile) {
  TempDir dir;
  dir.Write("scene.json", "");
  ExpectRejected(dir, "scene.json:1:#: syntax error");
}

TEST(RenderBadInput, SyntaxErrorGivesLineAndColumn) {
  TempDir dir;
  std::string text = Scene(kBox);
  // Drop the comma after the camera (end of line 2): the unexpected token is
  // "render" on line 3, columns 3-10; the parser stops on its last character.
  const size_t comma = text.find("},\n  \"render\"");
  ASSERT_NE(comma, std::string::npos);
  text.erase(comma + 1, 1);
  dir.Write("scene.json", text);
  ExpectRejected(dir, "scene.json:3:10: syntax error");
}

TEST(RenderBadInput, TruncatedSceneFile) {
  TempDir dir;
  const std::string text = Scene(kBox);
  dir.Write("scene.json", text.substr(0, text.size() / 2));
  ExpectRejected(dir, "scene.json:#:#: syntax error");
}

// A number beyond double's range is a JSON syntax matter: the message must
// name the file (and ideally the line), like any other syntax error.
TEST(RenderBadInput, NumberOverflowNamesTheFile) {
  TempDir dir;
  dir.Write("scene.json", Scene(R"([{"type": "box", "material": "m", "min": [-1, 0, -1], "max": [1e400, 1, 1]}])"));
  ExpectRejected(dir, "scene.json*1e400");
}

TEST(RenderBadInput, SchemaErrorsNameTheKeyPath) {
  struct Case {
    std::string scene, expected;
  };
  const std::vector<Case> cases = {
      {Scene(R"([{"type": "sphere", "material": "m", "radius": 1, "radiuss": 2}])"),
       "scene.json: objects[0].radiuss: unknown key"},
      {Scene(kBox, R"([{"type": "point", "position": [0, 3, 2], "intensity": "bright"}])"),
       "scene.json: lights[0].intensity: "},
      {Scene(kBox, R"([{"type": "point", "position": [0, 3, 2], "intensity": 10}])",
             R"({"position": [0, 1, 4], "look_at": [0, 0.5, 0], "fov": "wide"})"),
       "scene.json: camera.fov: expected a number"},
      {Scene(kBox, R"([{"type": "point", "position": [0, 3, 2], "intensity": 10}])",
             R"({"position": [0, 1, 4], "look_at": [0, 0.5, 0], "resolution": [0, 16]})"),
       "scene.json: camera.resolution: "},
      {Scene(R"([{"type": "box", "material": "nope", "min": [-1, 0, -1], "max": [1, 1, 1]}])"),
       "scene.json: objects[0].material: unknown material 'nope'"},
      {Scene(kBox, R"([{"type": "point", "position": [0, 3, 2], "intensity": 10}])",
             R"({"position": [0, 1, 4], "look_at": [0, 0.5, 0]})",
             R"({"m": {"type": "diffuse", "texture": {"type": "checker", "color0": [1, -1, 0]}}})"),
       "scene.json: materials.m.texture.color0: "},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.expected);
    TempDir dir;
    dir.Write("scene.json", c.scene);
    ExpectRejected(dir, c.expected);
  }
}

TEST(RenderBadInput, ZeroLights) {
  TempDir dir;
  dir.Write("scene.json", Scene(kBox, "[]"));
  ExpectRejected(dir, "scene.json: lights: the scene has no lights");
}

TEST(RenderBadInput, CameraInsideAClosedObject) {
  // Inside a box, a sphere, a rotated and scaled box, a closed mesh:
  // rejected, naming the object. Inside a room built of quads or an open
  // mesh (open surfaces) is normal.
  const std::string camera = R"({"position": [0.2, 0.5, 0.1], "look_at": [0, 0.5, -3], "resolution": [16, 16]})";
  const std::string light = R"([{"type": "point", "position": [0, 3, 2], "intensity": 10}])";
  const std::pair<std::string, std::string> cases[] = {
      {kBox, "objects[0] (a box)"},
      {R"([{"type": "quad", "material": "m", "origin": [-3, 0, 3], "edge_u": [6, 0, 0], "edge_v": [0, 0, -6]},
           {"type": "sphere", "material": "m", "center": [0, 0.5, 0], "radius": 0.6}])",
       "objects[1] (a sphere)"},
      {R"([{"type": "box", "material": "m", "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5],
            "transform": {"scale": [1, 2, 1], "rotate": [0, 45, 0], "translate": [0, 0.5, 0]}}])",
       "objects[0] (a box)"},
  };
  for (const auto& [objects, what] : cases) {
    TempDir dir;
    dir.Write("scene.json", Scene(objects, light, camera));
    ExpectRejected(dir, "scene.json: camera.position (0.200000, 0.500000, 0.100000) is inside " + what +
                            ": every camera ray would start inside it");
  }
  // A closed OBJ cube around the camera; the same cube with one face
  // missing (open: being inside is fine).
  const std::string cube =
      "v -1 0 -1\nv 1 0 -1\nv 1 2 -1\nv -1 2 -1\nv -1 0 1\nv 1 0 1\nv 1 2 1\nv -1 2 1\n"
      "f 1 2 3\nf 1 3 4\nf 5 7 6\nf 5 8 7\nf 1 5 6\nf 1 6 2\nf 4 3 7\nf 4 7 8\nf 1 4 8\nf 1 8 5\n";
  {
    TempDir dir;
    dir.Write("cube.obj", cube + "f 2 6 7\nf 2 7 3\n");
    dir.Write("scene.json", Scene(R"([{"type": "mesh", "material": "m", "file": "cube.obj"}])", light, camera));
    ExpectRejected(dir, "is inside objects[0] (a closed mesh)");
    dir.Write("open.obj", cube);
    dir.Write("scene.json", Scene(R"([{"type": "mesh", "material": "m", "file": "open.obj"}])", light, camera));
    const Result open = RunDcm(dir.path(), {"render", "scene.json", "-o", "open.exr", "--quiet"});
    EXPECT_TRUE(open.exited && open.code == 0) << open.Describe();
  }
  TempDir room;
  room.Write("scene.json", Scene(R"([{"type": "quad", "material": "m", "origin": [-3, 0, 3], "edge_u": [6, 0, 0], "edge_v": [0, 0, -6]},
      {"type": "quad", "material": "m", "origin": [-3, 3, -3], "edge_u": [6, 0, 0], "edge_v": [0, 0, 6]}])",
                                 light, camera));
  const Result ok = RunDcm(room.path(), {"render", "scene.json", "-o", "room.exr", "--quiet"});
  EXPECT_TRUE(ok.exited && ok.code == 0) << ok.Describe();
}

TEST(RenderBadInput, MissingMesh) {
  TempDir dir;
  dir.Write("scene.json", Scene(R"([{"type": "mesh", "material": "m", "file": "gone.obj"}])"));
  ExpectRejected(dir, "scene.json: objects[0].file: file '*gone.obj' not found");
}

const std::string kObj = "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nv 0 1 0\n"
                         "f 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\nf 1 3 2\nf 1 4 3\n";

/// A mesh file written by the test: each must be rejected with a message that
/// names the object's key and the file.
void ExpectMeshRejected(const std::string& name, const std::string& bytes) {
  SCOPED_TRACE(name);
  TempDir dir;
  dir.Write(name, bytes);
  dir.Write("scene.json", Scene(R"([{"type": "mesh", "material": "m", "file": ")" + name + R"("}])"));
  ExpectRejected(dir, "scene.json: objects[0].file: *" + name);
}

TEST(RenderBadInput, TruncatedObj) {
  // Cut inside the face list: the last face refers to vertices the file no
  // longer has, or no faces remain.
  ExpectMeshRejected("cut.obj", kObj.substr(0, kObj.find("f 1 2 5") + 5));
  ExpectMeshRejected("cut_vertices.obj", "v -1 0 -1\nv 1 0\n");
  ExpectMeshRejected("badindex.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
}

TEST(RenderBadInput, CorruptObj) {
  static const char kGarbage[] = "\x7f" "ELF\x02\x01\x01\x00\x00\xff\xfe this is no mesh\n";
  ExpectMeshRejected("garbage.obj", std::string(kGarbage, sizeof kGarbage - 1));
}

TEST(RenderBadInput, TruncatedPly) {
  const std::string header =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  // Three vertices need 36 bytes and the face 13: give 20.
  ExpectMeshRejected("cut.ply", header + std::string(20, '\0'));
  ExpectMeshRejected("cut_ascii.ply",
                     "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                     "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0\n");
}

TEST(RenderBadInput, TruncatedGltf) {
  const std::string gltf =
      R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
          "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
          "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                         "min": [0, 0, 0], "max": [1, 1, 0]}],
          "bufferViews": [{"buffer": 0, "byteLength": 36}],
          "buffers": [{"byteLength": 36, "uri": "tri.bin"}]})";
  // The JSON cut in half.
  ExpectMeshRejected("cut.gltf", gltf.substr(0, gltf.size() / 2));
  // Complete JSON, but its buffer file holds 12 of the 36 bytes it declares.
  {
    SCOPED_TRACE("short buffer");
    TempDir dir;
    dir.Write("tri.gltf", gltf);
    dir.Write("tri.bin", std::string(12, '\0'));
    dir.Write("scene.json", Scene(R"([{"type": "mesh", "material": "m", "file": "tri.gltf"}])"));
    ExpectRejected(dir, "scene.json: objects[0].file: *tri.gltf");
  }
  // Complete JSON whose buffer file is missing.
  {
    SCOPED_TRACE("missing buffer");
    TempDir dir;
    dir.Write("tri.gltf", gltf);
    dir.Write("scene.json", Scene(R"([{"type": "mesh", "material": "m", "file": "tri.gltf"}])"));
    ExpectRejected(dir, "scene.json: objects[0].file: *tri.gltf");
  }
}

// A mesh whose every triangle has zero area cannot be rendered: nothing of it
// would be visible. (A few degenerate triangles in a good mesh are harmless
// and may be dropped silently; this is the all-degenerate case.)
TEST(RenderBadInput, AllTrianglesDegenerate) {
  ExpectMeshRejected("flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 4 4 1\n");
}

// Non-finite vertex coordinates reach Embree as NaN/Inf geometry.
TEST(RenderBadInput, NaNCoordinatesInMesh) {
  ExpectMeshRejected("nan.obj", "v nan 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n");
  ExpectMeshRejected("inf.obj", "v 0 0 0\nv inf 0 0\nv 0 1 0\nf 1 2 3\n");
}

// Coordinates finite as JSON doubles but beyond float's range become +-Inf
// after conversion (and Embree aborts on a non-finite ray); scale and rotation
// likewise make the geometry non-finite.
TEST(RenderBadInput, CoordinatesBeyondFloatRange) {
  struct Case {
    std::string scene, expected;
  };
  const std::vector<Case> cases = {
      {Scene(kBox, R"([{"type": "point", "position": [0, 3, 2], "intensity": 10}])",
             R"({"position": [1e300, 1, 4], "look_at": [0, 0.5, 0], "resolution": [16, 16]})"),
       "scene.json: camera.position"},
      {Scene(R"([{"type": "box", "material": "m", "min": [-1, 0, -1], "max": [1, 1, 1],
                  "transform": {"scale": 1e300}}])"),
       "scene.json: objects[0].transform.scale"},
      {Scene(R"([{"type": "box", "material": "m", "min": [-1, 0, -1], "max": [1, 1, 1],
                  "transform": {"rotate": [1e39, 0, 0]}}])"),
       "scene.json: objects[0].transform.rotate"},
      {Scene(R"([{"type": "sphere", "material": "m", "center": [0, -4e38, 0], "radius": 1}])"),
       "scene.json: objects[0].center"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.expected);
    TempDir dir;
    dir.Write("scene.json", c.scene);
    ExpectRejected(dir, c.expected);
  }
}

TEST(RenderBadInput, MissingTexture) {
  TempDir dir;
  dir.Write("scene.json", Scene(kBox, R"([{"type": "point", "position": [0, 3, 2], "intensity": 10}])",
                                R"({"position": [0, 1, 4], "look_at": [0, 0.5, 0], "resolution": [16, 16]})",
                                R"({"m": {"type": "diffuse", "texture": {"type": "image", "file": "wood.png"}}})"));
  ExpectRejected(dir, "scene.json: materials.m.texture.file: file '*wood.png' not found");
}

TEST(RenderBadInput, CorruptAndTruncatedTexture) {
  // A PNG signature and the start of an IHDR chunk, then nothing.
  const std::string truncatedPng("\x89PNG\r\n\x1a\n\x00\x00\x00\x0dIHDR\x00\x00\x00\x10", 20);
  for (const auto& [name, bytes] : {std::pair<std::string, std::string>{"wood.png", "not an image at all"},
                                    {"cut.png", truncatedPng}, {"cut.exr", std::string("\x76\x2f\x31\x01\x02\x00", 6)}}) {
    SCOPED_TRACE(name);
    TempDir dir;
    dir.Write(name, bytes);
    dir.Write("scene.json",
              Scene(kBox, R"([{"type": "point", "position": [0, 3, 2], "intensity": 10}])",
                    R"({"position": [0, 1, 4], "look_at": [0, 0.5, 0], "resolution": [16, 16]})",
                    R"({"m": {"type": "diffuse", "texture": {"type": "image", "file": ")" + name + R"("}}})"));
    ExpectRejected(dir, "scene.json: materials.m.texture");
  }
}
}  // namespace
