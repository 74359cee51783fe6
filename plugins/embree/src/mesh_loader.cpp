#include "dcm/embree/mesh_loader.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <charconv>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "dcm/memory_budget.h"

namespace dcm::embree {
namespace {

/// Bytes of a binary PLY scalar type (0: unknown).
int PlyTypeBytes(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

/// Memory one PLY element costs once loaded, at least: Assimp's copy and
/// ours (TriangleMesh), each a position, a normal and a uv (32 bytes) for a
/// vertex or three indices for a face.
constexpr double kBytesPerPlyElement = 64.0;

}  // namespace

Status CheckDeclaredMeshSize(const std::string& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Ok();  // missing or unreadable: Assimp's message says so
  // Assimp reads a .ply file as PLY whatever it holds (and 5.2.5 reads on
  // forever in one whose first line is not "ply"), and a file of another
  // extension when it starts with the line "ply".
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  std::string first;
  std::getline(in, first);
  if (!first.empty() && first.back() == '\r') first.pop_back();
  if (first != "ply") {
    if (ext != ".ply") return Status::Ok();  // not PLY: no declared counts to check
    return Status::Error(what + ": mesh '" + path + "' is no PLY file (its first line is not 'ply')");
  }
  std::error_code ec;
  const auto fileBytes = std::filesystem::file_size(path, ec);
  if (ec) return Status::Ok();

  struct Element {
    std::string name;
    uint64_t count = 0;
    double minBytes = 0.0;  ///< the least one element can take in the file
  };
  std::vector<Element> elements;
  bool binary = false, ended = false;
  std::string line;
  // The header is text; one of more than 64 KiB is taken as having no end.
  while (in.tellg() >= 0 && in.tellg() < (1 << 16) && std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream ls(line);
    std::string key;
    ls >> key;
    if (key == "end_header") {
      ended = true;
      break;
    }
    if (key == "format") {
      // Assimp 5.2.5 reads on forever after a malformed format line (fuzz_mesh).
      std::string f, version;
      ls >> f >> version;
      if ((f != "ascii" && f != "binary_little_endian" && f != "binary_big_endian") || version != "1.0")
        return Status::Error(what + ": mesh '" + path + "': PLY format line '" + line +
                             "' is not 'format ascii|binary_little_endian|binary_big_endian 1.0'");
      binary = f != "ascii";
    } else if (key == "element") {
      Element e;
      std::string count;
      ls >> e.name >> count;
      const auto [p, err] = std::from_chars(count.data(), count.data() + count.size(), e.count);
      if (err == std::errc::result_out_of_range)
        return Status::Error(what + ": mesh '" + path + "' declares " + count + " " + e.name +
                             " elements, more than any file holds");
      if (err != std::errc() || p != count.data() + count.size())
        return Status::Error(what + ": mesh '" + path + "': PLY element '" + e.name + "' has no count");
      elements.push_back(e);
    } else if (key == "property") {
      if (elements.empty())
        return Status::Error(what + ": mesh '" + path + "': PLY property before any element ('" + line + "')");
      std::string type;
      ls >> type;
      // A list takes at least its count (it may be empty); a scalar its size
      // in binary, and in ASCII a digit and a separator.
      if (type == "list") ls >> type;
      const int bytes = PlyTypeBytes(type);
      elements.back().minBytes += binary ? double(std::max(bytes, 1)) : 2.0;
    }
  }
  // Assimp 5.2.5 reads past the end of a header without one (SIGSEGV).
  if (!ended) return Status::Error(what + ": mesh '" + path + "' is a PLY file without 'end_header'");
  // An element without properties takes no bytes in a binary file, yet
  // Assimp builds an instance of it for each: count a byte (ASCII's newline).
  for (Element& e : elements) e.minBytes = std::max(e.minBytes, 1.0);
  const double available = double(fileBytes) - double(std::max<std::streamoff>(in.tellg(), 0));
  double needed = 0.0, memory = 0.0;
  std::string declared;  // "200000000 vertex, 1 face"
  for (const Element& e : elements) {
    needed += double(e.count) * e.minBytes;
    memory += double(e.count) * kBytesPerPlyElement;
    declared += (declared.empty() ? "" : ", ") + std::to_string(e.count) + " " + e.name;
  }
  const std::string prefix = what + ": mesh '" + path + "' declares " + declared + " elements";
  if (needed > available)
    return Status::Error(prefix + ", which need at least " + ByteText(needed) + " of data, but the file holds " +
                         ByteText(double(fileBytes)) + " (truncated or corrupt)");
  return CheckMemoryBudget(prefix + ", which", memory);
}

Status LoadMeshFile(const std::string& path, const std::string& what, TriangleMesh* mesh) {
  // Assimp allocates what a header declares before it reads the data.
  DCM_RETURN_IF_ERROR(CheckDeclaredMeshSize(path, what));
  Assimp::Importer importer;
  // Points and lines are of no use to a ray tracer: drop them.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* s = importer.ReadFile(path, aiProcess_ValidateDataStructure);
  if (!s || (s->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || !s->mRootNode) {
    return Status::Error(what + ": cannot load mesh '" + path + "': " + importer.GetErrorString());
  }
  // Assimp's post-processing asserts (aborts) on faces its validation lets
  // through: a face without vertices, or of a kind the mesh does not declare.
  for (unsigned i = 0; i < s->mNumMeshes; ++i) {
    const aiMesh* am = s->mMeshes[i];
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const unsigned n = am->mFaces[f].mNumIndices;
      const unsigned kind = n == 1   ? aiPrimitiveType_POINT
                            : n == 2 ? aiPrimitiveType_LINE
                            : n == 3 ? aiPrimitiveType_TRIANGLE
                                     : aiPrimitiveType_POLYGON;
      if (n == 0 || !(am->mPrimitiveTypes & kind))
        return Status::Error(what + ": mesh '" + path + "' has a face of " + std::to_string(n) +
                             " vertices (face " + std::to_string(f) + " of mesh " + std::to_string(i) +
                             "): corrupt file");
    }
  }
  s = importer.ApplyPostProcessing(aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                   aiProcess_GenSmoothNormals | aiProcess_PreTransformVertices |
                                   aiProcess_SortByPType);
  if (!s || !s->mRootNode)
    return Status::Error(what + ": cannot load mesh '" + path + "': " + importer.GetErrorString());
  TriangleMesh m;
  bool allHaveUv = true;
  for (unsigned i = 0; i < s->mNumMeshes; ++i) {
    // Every mesh the loop below takes (any with triangles) must have uvs.
    if ((s->mMeshes[i]->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) && !s->mMeshes[i]->HasTextureCoords(0)) {
      allHaveUv = false;
    }
  }
  for (unsigned i = 0; i < s->mNumMeshes; ++i) {
    const aiMesh* am = s->mMeshes[i];
    if (!(am->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
    uint32_t base = uint32_t(m.positions.size());
    for (unsigned v = 0; v < am->mNumVertices; ++v) {
      const aiVector3D& p = am->mVertices[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        return Status::Error(what + ": mesh '" + path + "' has a non-finite vertex " + std::to_string(v));
      m.positions.push_back({p.x, p.y, p.z});
      if (am->HasNormals()) {
        const aiVector3D& n = am->mNormals[v];
        m.normals.push_back(Normalize(Vec3{n.x, n.y, n.z}));
      }
      if (allHaveUv) {
        const aiVector3D& t = am->mTextureCoords[0][v];
        m.uvs.push_back({t.x, t.y});
      }
    }
    for (unsigned f = 0; f < am->mNumFaces; ++f) {
      const aiFace& face = am->mFaces[f];
      if (face.mNumIndices != 3) continue;
      m.indices.insert(m.indices.end(), {base + face.mIndices[0], base + face.mIndices[1], base + face.mIndices[2]});
    }
  }
  if (m.normals.size() != m.positions.size()) m.normals.clear();
  if (m.indices.empty()) return Status::Error(what + ": mesh '" + path + "' has no triangles");
  bool anyArea = false;
  for (size_t k = 0; k + 2 < m.indices.size() && !anyArea; k += 3) {
    const Vec3 a = m.positions[m.indices[k]], b = m.positions[m.indices[k + 1]], c = m.positions[m.indices[k + 2]];
    anyArea = Length(Cross(b - a, c - a)) > 0.f;
  }
  if (!anyArea) return Status::Error(what + ": mesh '" + path + "' has no triangle of non-zero area");
  *mesh = std::move(m);
  return Status::Ok();
}

}  // namespace dcm::embree
