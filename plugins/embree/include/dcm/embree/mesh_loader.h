// Meshes from files (OBJ, PLY, glTF and whatever else Assimp reads).
#pragma once

#include <string>

#include "dcm/status.h"
#include "dcm/embree/triangle_mesh.h"

namespace dcm::embree {

/// Checks the element counts a PLY header declares against what the file
/// can hold (each element takes at least its binary size, or two characters
/// per number in ASCII) and against MemoryBudget(), before anything is
/// allocated; a .ply whose first line is not "ply", a header without
/// end_header and an element without a count are refused too. Other formats
/// (OBJ: no declared counts) pass. The message names the file and the
/// declared count.
Status CheckDeclaredMeshSize(const std::string& path, const std::string& what);

/// Loads every mesh of the file at `path` into one triangle mesh with the
/// file's node transforms applied (normals generated where the file has none,
/// texture coordinates of the first channel where present). `what` names the
/// object in messages ("scene.json: objects[2].file").
Status LoadMeshFile(const std::string& path, const std::string& what, TriangleMesh* mesh);

}  // namespace dcm::embree
