// Meshes from files (OBJ, PLY, glTF and whatever else Assimp reads).
#pragma once

#include <string>

#include "dcm/status.h"
#include "embree/triangle_mesh.h"

namespace dcm::embree {

/// Loads every mesh of the file at `path` into one triangle mesh with the
/// file's node transforms applied (normals generated where the file has none,
/// texture coordinates of the first channel where present). `what` names the
/// object in messages ("scene.json: objects[2].file").
Status LoadMeshFile(const std::string& path, const std::string& what, TriangleMesh* mesh);

}  // namespace dcm::embree
