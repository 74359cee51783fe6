// Tiny files that declare huge sizes, through the `dcm` binary (its path in
// DCM_BINARY): a PLY header declaring 2e8 or 2e9 vertices, an image texture
// declaring 100000x100000 pixels, an AOV EXR declaring 9400x9400. Each must be
// refused from its header, before the allocation, with a message that names
// the file and the size it declares, and exit 1. dcm runs with its address
// space limited (kAddressSpace), so that a regression fails here instead of
// swapping the machine; a control input shows that the limit alone refuses
// nothing that should work. At the end, meshes that crashed the mesh loader
// (found by fuzz_mesh).
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <OpenImageIO/imageio.h>

#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <regex>
#include <string>
#include <tuple>
#include <vector>

#include "../support/exr_declared_size.h"
#include "dcm_process.h"

#if defined(__SANITIZE_ADDRESS__)
#define DCM_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define DCM_TEST_ASAN 1
#endif
#endif

namespace {

namespace fs = std::filesystem;
using namespace dcm::testing;

/// The address space dcm may use here: 1 GiB. The control scene below
/// renders within it with one thread and two malloc arenas (it needs between
/// 512 and 768 MiB, mostly the mapped libraries: docs/PROMISES.md), while
/// the allocations the lying files used to cause are 2.4 GB (2e8 PLY
/// vertices) and 5.9 GB (the 9400^2 EXR), so a guard that lets them through
/// fails the test.
/// AddressSanitizer reserves terabytes of shadow memory: no limit under it.
constexpr rlim_t kAddressSpace = rlim_t(1) << 30;

/// Runs `dcm args...` in `cwd` with the address space limited to
/// kAddressSpace and `env` ("NAME=value") added to the environment.
Result RunLimited(const fs::path& cwd, const std::vector<std::string>& args, const std::vector<std::string>& env = {}) {
  return RunDcm(cwd, args, [&env] {
    // glibc reserves 64 MiB of address space per malloc arena (one per thread).
    ::setenv("MALLOC_ARENA_MAX", "2", 1);
    for (const std::string& e : env) ::putenv(const_cast<char*>(e.c_str()));
#ifndef DCM_TEST_ASAN
    const rlimit limit{kAddressSpace, kAddressSpace};
    if (::setrlimit(RLIMIT_AS, &limit) != 0) _exit(126);
#endif
  });
}

/// The failure every lying file must give: exit 1 (not a signal, not a
/// std::bad_alloc), a message with each of `needles`, no output file.
void ExpectRefused(const Result& r, const TempDir& dir, const std::vector<std::string>& needles) {
  EXPECT_TRUE(r.exited) << r.Describe();
  EXPECT_EQ(r.code, 1) << r.Describe();
  for (const std::string& n : needles) EXPECT_NE(r.output.find(n), std::string::npos) << "no '" << n << "' in " << r.Describe();
  EXPECT_EQ(r.output.find("bad_alloc"), std::string::npos) << r.Describe();
  EXPECT_EQ(r.output.find("out of memory"), std::string::npos) << "refused late: " << r.Describe();
  EXPECT_FALSE(fs::exists(dir.path() / "out.exr"));
}

/// A 16x16 scene: a mesh object from `mesh` (or a box when empty) with the
/// material "m", optionally textured by the image `texture`.
std::string Scene(const std::string& mesh, const std::string& texture = "") {
  const std::string material = texture.empty()
                                   ? R"({"m": {"type": "diffuse"}})"
                                   : R"({"m": {"type": "diffuse", "texture": {"type": "image", "file": ")" + texture +
                                         R"("}}})";
  const std::string object = mesh.empty()
                                 ? R"({"type": "box", "material": "m", "min": [-1, 0, -1], "max": [1, 1, 1]})"
                                 : R"({"type": "mesh", "material": "m", "file": ")" + mesh + R"("})";
  return R"({"camera": {"position": [0, 1, 4], "look_at": [0, 0.5, 0], "resolution": [16, 16]},
  "render": {"shadow_rays": 1}, "materials": )" +
         material + R"(, "objects": [)" + object + R"(],
  "lights": [{"type": "point", "position": [0, 3, 2], "intensity": 10}]})";
}

Result Render(const TempDir& dir, const std::vector<std::string>& env = {}) {
  return RunLimited(dir.path(), {"render", "scene.json", "-o", "out.exr", "--threads", "1", "--quiet"}, env);
}

/// A binary little-endian PLY header: `vertices` xyz floats, `faces` lists.
std::string PlyHeader(const std::string& format, uint64_t vertices, uint64_t faces) {
  return "ply\nformat " + format + " 1.0\ncomment a tiny file with a big claim\nelement vertex " +
         std::to_string(vertices) + "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
         std::to_string(faces) + "\nproperty list uchar int vertex_indices\nend_header\n";
}

/// A tetrahedron as a binary PLY.
std::string TetrahedronPly() {
  std::string ply = PlyHeader("binary_little_endian", 4, 4);
  const float v[12] = {-1, 0, -1, 1, 0, -1, 0, 0, 1, 0, 1, 0};
  ply.append(reinterpret_cast<const char*>(v), sizeof v);
  const int32_t f[4][3] = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
  for (const auto& tri : f) {
    ply += char(3);
    ply.append(reinterpret_cast<const char*>(tri), sizeof tri);
  }
  return ply;
}

uint32_t Crc32(const std::string& bytes) {
  uint32_t c = 0xffffffffu;
  for (unsigned char b : bytes) {
    c ^= b;
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return ~c;
}

std::string BigEndian32(uint32_t v) {
  return {char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
}

/// A PNG chunk: length, type, data, CRC of type and data.
std::string PngChunk(const std::string& type, const std::string& data) {
  return BigEndian32(uint32_t(data.size())) + type + data + BigEndian32(Crc32(type + data));
}

/// A 3.7 kB PNG whose IHDR declares side x side RGB pixels of 8 bits; its
/// IDAT holds zeros, far fewer than the image needs.
std::string LyingPng(uint32_t side) {
  std::string png("\x89PNG\r\n\x1a\n", 8);
  png += PngChunk("IHDR", BigEndian32(side) + BigEndian32(side) + std::string("\x08\x02\x00\x00\x00", 5));
  png += PngChunk("IDAT", std::string(3650, '\0'));
  png += PngChunk("IEND", "");
  return png;
}

TEST(MemoryBounds, ControlRendersUnderTheLimit) {
  // A true PLY and a true texture render within kAddressSpace: the limit
  // does not decide the other tests.
  TempDir dir;
  dir.Write("tetra.ply", TetrahedronPly());
  dir.Write("wood.ppm", "P6\n2 2\n255\n" + std::string(12, '\x80'));
  dir.Write("scene.json", Scene("tetra.ply", "wood.ppm"));
  const Result r = Render(dir);
  EXPECT_TRUE(r.exited && r.code == 0) << r.Describe();
  EXPECT_TRUE(fs::exists(dir.path() / "out.exr"));
}

TEST(MemoryBounds, PlyHeaderDeclaring2e8Vertices) {
  for (const char* format : {"binary_little_endian", "ascii"}) {
    SCOPED_TRACE(format);
    TempDir dir;
    const std::string ply = PlyHeader(format, 200000000, 1) + std::string(16, '\0');
    ASSERT_LT(ply.size(), 260u);
    dir.Write("big.ply", ply);
    dir.Write("scene.json", Scene("big.ply"));
    ExpectRefused(Render(dir), dir, {"scene.json: objects[0].file", "big.ply", "declares 200000000 vertex"});
  }
}

TEST(MemoryBounds, PlyHeaderDeclaring2e9Vertices) {
  TempDir dir;
  dir.Write("big.ply", PlyHeader("binary_little_endian", 2000000000, 1) + std::string(16, '\0'));
  dir.Write("scene.json", Scene("big.ply"));
  ExpectRefused(Render(dir), dir, {"big.ply", "declares 2000000000 vertex", "truncated or corrupt"});
}

TEST(MemoryBounds, PlyBeyondDcmMemoryLimit) {
  // A true mesh of 40000 vertices (480 kB) is refused by a budget of 1 MiB
  // (64 bytes per element in memory), and renders without one.
  TempDir dir;
  const int n = 40000;
  std::string ply = PlyHeader("binary_little_endian", n, 1);
  std::vector<float> v(size_t(n) * 3, 0.f);
  v[3] = 1.f;
  v[7] = 1.f;
  ply.append(reinterpret_cast<const char*>(v.data()), v.size() * 4);
  const int32_t tri[3] = {0, 1, 2};
  ply += char(3);
  ply.append(reinterpret_cast<const char*>(tri), sizeof tri);
  dir.Write("many.ply", ply);
  dir.Write("scene.json", Scene("many.ply"));
  ExpectRefused(Render(dir, {"DCM_MEMORY_LIMIT=1M"}), dir, {"many.ply", "declares 40000 vertex", "memory limit of 1.0 MiB"});
  const Result ok = Render(dir);
  EXPECT_TRUE(ok.exited && ok.code == 0) << ok.Describe();
}

TEST(MemoryBounds, PngTextureDeclaring100000Squared) {
  TempDir dir;
  const std::string png = LyingPng(100000);
  ASSERT_LT(png.size(), 4000u);
  dir.Write("huge.png", png);
  dir.Write("scene.json", Scene("", "huge.png"));
  ExpectRefused(Render(dir), dir,
                {"scene.json: materials.m.texture", "huge.png", "declares 100000x100000 pixels", "any compression"});
}

TEST(MemoryBounds, UncompressedTextureDeclaring100000Squared) {
  // A binary PPM stores its samples raw: 30 GB cannot be in 3.7 kB.
  TempDir dir;
  dir.Write("huge.ppm", "P6\n100000 100000\n255\n" + std::string(3700, '\x80'));
  dir.Write("scene.json", Scene("", "huge.ppm"));
  ExpectRefused(Render(dir), dir, {"huge.ppm", "declares 100000x100000 pixels", "stored raw"});
}

TEST(MeshLoaderFindings, MalformedPlyFormatLineIsRefused) {
  // fuzz_mesh's finding: after 'format ascii ,.0' Assimp read on for more
  // than a minute. The format line, and a property before any element, are refused.
  TempDir dir;
  const std::string body = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                           "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                           "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  dir.Write("badformat.ply", "ply\nformat ascii ,.0\n" + body);
  dir.Write("scene.json", Scene("badformat.ply"));
  Result r = Render(dir);
  EXPECT_TRUE(r.exited && r.code == 1) << r.Describe();
  EXPECT_NE(r.output.find("badformat.ply': PLY format line 'format ascii ,.0'"), std::string::npos) << r.Describe();
  dir.Write("early.ply", "ply\nformat ascii 1.0\nproperty list uchar int vertex_indices\n" + body);
  dir.Write("scene.json", Scene("early.ply"));
  r = Render(dir);
  EXPECT_TRUE(r.exited && r.code == 1) << r.Describe();
  EXPECT_NE(r.output.find("PLY property before any element"), std::string::npos) << r.Describe();
  // The same mesh with a well-formed header renders.
  dir.Write("good.ply", "ply\nformat ascii 1.0\n" + body);
  dir.Write("scene.json", Scene("good.ply"));
  r = Render(dir);
  EXPECT_TRUE(r.exited && r.code == 0) << r.Describe();
}

TEST(MeshLoaderFindings, TextureOfZeroColumnsIsRefused) {
  // fuzz_texture's finding: a TGA declaring 0x8 pixels reached OpenImageIO's
  // bicubic lookup, which divides by the width (SIGFPE).
  TempDir dir;
  std::string tga(18, '\0');
  tga[2] = 3;   // uncompressed grey
  tga[14] = 8;  // height 8; width (bytes 12-13) 0
  tga[16] = 8;  // bits per pixel
  dir.Write("empty.tga", tga);
  dir.Write("scene.json", Scene("", "empty.tga"));
  const Result r = Render(dir);
  EXPECT_TRUE(r.exited && r.code == 1) << r.Describe();
  EXPECT_NE(r.output.find("empty.tga' declares an empty image (0x8"), std::string::npos) << r.Describe();
}

/// A small generic AOV EXR (id, shader, R, G, B; 32x32 half, PIZ: one chunk
/// of 32 scanlines) whose data and display windows are then patched to
/// declare side x side pixels, with an offset table of one entry per 32
/// scanlines that all point at the one real chunk: OpenEXR opens it.
std::string LyingExr(const fs::path& dir, int side) {
  const int n = 32;
  const std::string small = (dir / "small.exr").string();
  OIIO::ImageSpec spec(n, n, 5, OIIO::TypeDesc::HALF);
  spec.channelnames = {"id", "shader", "R", "G", "B"};
  spec.attribute("compression", "piz");
  std::vector<float> px(size_t(n) * n * 5);
  for (size_t i = 0; i < size_t(n) * n; ++i) {
    px[5 * i] = float(1 + (i % n) / 8);  // four objects in columns
    px[5 * i + 1] = 1.f;
    for (int c = 0; c < 3; ++c) px[5 * i + 2 + size_t(c)] = float((i * 2654435761u + size_t(c)) % 97) / 97.f;
  }
  auto out = OIIO::ImageOutput::create(small);
  if (!out || !out->open(small, spec) || !out->write_image(OIIO::TypeDesc::FLOAT, px.data()) || !out->close())
    throw std::runtime_error("cannot write " + small);
  std::ifstream in(small, std::ios::binary);
  std::string d((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  fs::remove(small);
  return DeclareExrSize(d, side, n);  // PIZ: 32 scanlines a chunk
}

TEST(MemoryBounds, AovExrDeclaring9400Squared) {
  TempDir dir;
  const std::string exr = LyingExr(dir.path(), 9400);
  ASSERT_LT(exr.size(), 16000u);
  dir.Write("tiny.exr", exr);
  const Result r = RunLimited(dir.path(), {"reconstruct", "tiny.exr", "-o", "out.exr", "--threads", "1", "--quiet"});
  ExpectRefused(r, dir, {"tiny.exr", "declares 9400x9400 pixels", "truncated or corrupt"});
}

TEST(MemoryBounds, AovExrControl) {
  // The same file unpatched reconstructs under the limit.
  TempDir dir;
  dir.Write("small.exr", LyingExr(dir.path(), 32));
  const Result r = RunLimited(dir.path(), {"reconstruct", "small.exr", "-o", "out.exr", "--threads", "1", "--quiet"});
  EXPECT_TRUE(r.exited && r.code == 0) << r.Describe();
}

TEST(MemoryBounds, BadAllocBecomesAMessage) {
#ifdef DCM_TEST_ASAN
  GTEST_SKIP() << "needs RLIMIT_AS, which AddressSanitizer's shadow memory rules out";
#else
  // A true scene at 16384x16384 needs several GiB of working images; with the
  // budget raised past the address space, the allocation itself fails, and
  // dcm says so instead of terminating on std::bad_alloc.
  TempDir dir;
  dir.Write("scene.json", Scene(""));
  const Result r = RunLimited(dir.path(),
                              {"render", "scene.json", "-o", "out.exr", "--threads", "1", "--quiet", "--size",
                               "16384x16384"},
                              {"DCM_MEMORY_LIMIT=1T"});
  EXPECT_TRUE(r.exited) << r.Describe();
  EXPECT_EQ(r.code, 1) << r.Describe();
  EXPECT_NE(r.output.find("out of memory while running 'dcm render'"), std::string::npos) << r.Describe();
  EXPECT_FALSE(fs::exists(dir.path() / "out.exr"));
#endif
}

}  // namespace

// Found by fuzz_mesh (docs/FUZZING.md): inputs that crashed `dcm render`
// inside the mesh loader.

TEST(MeshLoaderFindings, QuadObjWithoutUvsRenders) {
  // A polygon face and no texture coordinates: the loader read the uvs of a
  // mesh that has none (SIGSEGV).
  TempDir dir;
  dir.Write("quad.obj", "o quad\nv -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nf 1 2 3 4\n");
  dir.Write("scene.json", Scene("quad.obj"));
  const Result r = Render(dir);
  EXPECT_TRUE(r.exited && r.code == 0) << r.Describe();
}

TEST(MeshLoaderFindings, PlyWithEmptyFacesIsRefused) {
  // A misspelt property line: the faces are read from the wrong bytes and
  // have no vertices; Assimp's triangulation asserted on them (SIGABRT).
  std::string ply =
      "ply\nformat binary_big_endian 1.0\nelement vertex 4\nproperty float x\npropErty float y\n"
      "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n";
  const float v[12] = {-1, 0, -1, 1, 0, -1, 0, 0, 1, 0, 1, 0};
  auto big = [&](const void* p) {
    const auto* b = static_cast<const unsigned char*>(p);
    ply += {char(b[3]), char(b[2]), char(b[1]), char(b[0])};
  };
  for (const float& x : v) big(&x);
  const int32_t f[4][3] = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
  for (const auto& tri : f) {
    ply += char(3);
    for (const int32_t& i : tri) big(&i);
  }
  TempDir dir;
  dir.Write("typo.ply", ply);
  dir.Write("scene.json", Scene("typo.ply"));
  ExpectRefused(Render(dir), dir, {"scene.json: objects[0].file", "typo.ply", "has a face of 0 vertices"});
}

TEST(MeshLoaderFindings, PlyWithoutEndHeaderOrPlyLineIsRefused) {
  // No end_header, or a .ply whose first line is not "ply": Assimp 5.2.5
  // reads on past the end of the file (both hung `dcm render`; with other
  // bytes after the header, SIGSEGV).
  for (const auto& [name, bytes, message] :
       {std::tuple<std::string, std::string, std::string>{
            "noend.ply", std::regex_replace(PlyHeader("binary_big_endian", 4, 4), std::regex("end_header"), "0eader"),
            "without 'end_header'"},
        {"noply.ply", "ply)\nformat binary_big_endian 1.0\nelement vertex 4\nproperty float x\n", "is no PLY file"}}) {
    SCOPED_TRACE(name);
    TempDir dir;
    dir.Write(name, bytes);
    dir.Write("scene.json", Scene(name));
    ExpectRefused(Render(dir), dir, {"scene.json: objects[0].file", name, message});
  }
}
