// libFuzzer target: the mesh loader of the internal ray tracer
// (plugins/embree/src/mesh_loader.cpp: the PLY header check, then Assimp). The
// first byte picks the extension (.ply or .obj: Assimp chooses its reader by
// it, then by the content); the rest is written to a file and loaded.
//
// The contract checked besides crashes and sanitizer reports: no allocation
// beyond libFuzzer's -malloc_limit_mb (a header declaring more than the file
// holds is refused before Assimp allocates it); a mesh accepted has
// triangles, finite positions, indices inside it and normals and uvs either
// absent or one per vertex; an error names the object and the file.
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "dcm/embree/mesh_loader.h"

namespace {

/// The input file, per extension; never destroyed (see fuzz_exr.cpp).
const std::string& InputPath(bool ply) {
  static const std::string* base = [] {
    std::error_code ec;
    std::filesystem::path dir = std::filesystem::temp_directory_path(ec);
    if (ec) dir = "/tmp";
    return new std::string((dir / ("dcm_fuzz_mesh_" + std::to_string(::getpid()))).string());
  }();
  static const std::string* plyPath = new std::string(*base + ".ply");
  static const std::string* objPath = new std::string(*base + ".obj");
  return ply ? *plyPath : *objPath;
}

[[noreturn]] void Violation(const std::string& what) {
  std::fprintf(stderr, "fuzz_mesh: %s\n", what.c_str());
  std::abort();
}

}  // namespace

// Assimp 5.2.5's PLY reader leaks its partial element lists on some malformed
// headers (docs/FUZZING.md); not dcm's memory.
extern "C" const char* __lsan_default_suppressions() { return "leak:libassimp.so\n"; }

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  std::atexit([] {
    std::error_code ec;
    std::filesystem::remove(InputPath(true), ec);
    std::filesystem::remove(InputPath(false), ec);
  });
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1 || size > (1u << 20)) return 0;
  const std::string& path = InputPath((data[0] & 1) == 0);
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data + 1), std::streamsize(size - 1));
    if (!out) Violation("cannot write the input file " + path);
  }
  dcm::embree::TriangleMesh mesh;
  const dcm::Status st = dcm::embree::LoadMeshFile(path, "fuzz.json: objects[0].file", &mesh);
  if (!st.ok()) {
    if (st.message().rfind("fuzz.json: objects[0].file: ", 0) != 0 || st.message().find(path) == std::string::npos)
      Violation("error does not name the object and the file: " + st.message());
    return 0;
  }
  const size_t n = mesh.positions.size();
  if (mesh.indices.empty() || mesh.indices.size() % 3 != 0) Violation("a mesh without whole triangles accepted");
  for (uint32_t i : mesh.indices)
    if (i >= n) Violation("index " + std::to_string(i) + " of " + std::to_string(n) + " vertices accepted");
  for (const auto& p : mesh.positions)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) Violation("non-finite vertex accepted");
  if (!mesh.normals.empty() && mesh.normals.size() != n) Violation("normals not one per vertex");
  if (!mesh.uvs.empty() && mesh.uvs.size() != n) Violation("uvs not one per vertex");
  return 0;
}
