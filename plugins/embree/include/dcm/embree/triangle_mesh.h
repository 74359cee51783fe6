// Triangle meshes: what every object of the scene becomes before it enters the
// Embree BVH.
#pragma once

#include <cstdint>
#include <vector>

#include "dcm/embree/scene.h"
#include "dcm/embree/vec3.h"

namespace dcm::embree {

/// An indexed triangle mesh with optional per-vertex normals and texture
/// coordinates (empty when absent: flat shading, uv from the barycentrics).
struct TriangleMesh {
  std::vector<Vec3> positions;
  std::vector<Vec3> normals;
  std::vector<Vec2> uvs;
  std::vector<uint32_t> indices;  ///< three per triangle
  size_t triangleCount() const { return indices.size() / 3; }
};

/// Tessellates a built-in shape (quad, box, sphere, cylinder) in its own frame;
/// the object's transform is applied separately.
TriangleMesh TessellateShape(const ObjectDesc& object);

/// Applies scale, rotation and translation to positions and normals.
void ApplyTransform(const TransformDesc& transform, TriangleMesh* mesh);

/// A rectangle origin + s*edgeU + t*edgeV as two triangles with normal
/// cross(edgeU, edgeV) (used for the shapes of area lights).
TriangleMesh MakeParallelogram(Vec3 origin, Vec3 edgeU, Vec3 edgeV);

}  // namespace dcm::embree
