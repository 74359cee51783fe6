#include "embree/mesh_loader.h"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cmath>

namespace dcm::embree {

Status LoadMeshFile(const std::string& path, const std::string& what, TriangleMesh* mesh) {
  Assimp::Importer importer;
  // Points and lines are of no use to a ray tracer: drop them.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* s = importer.ReadFile(
      path, aiProcess_ValidateDataStructure | aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                aiProcess_GenSmoothNormals | aiProcess_PreTransformVertices | aiProcess_SortByPType);
  if (!s || (s->mFlags & AI_SCENE_FLAGS_INCOMPLETE) || !s->mRootNode) {
    return Status::Error(what + ": cannot load mesh '" + path + "': " + importer.GetErrorString());
  }
  TriangleMesh m;
  bool allHaveUv = true;
  for (unsigned i = 0; i < s->mNumMeshes; ++i) {
    if (s->mMeshes[i]->mPrimitiveTypes == aiPrimitiveType_TRIANGLE && !s->mMeshes[i]->HasTextureCoords(0)) {
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
