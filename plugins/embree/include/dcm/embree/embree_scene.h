// The scene's geometry in an Embree 3 BVH, and what a ray hits.
#pragma once

#include <embree3/rtcore.h>

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "dcm/status.h"
#include "dcm/embree/scene.h"
#include "dcm/embree/triangle_mesh.h"
#include "dcm/embree/vec3.h"

namespace dcm::embree {

/// The surface a ray hit, oriented towards the ray's origin.
struct SurfaceHit {
  float t = 0.f;
  Vec3 p;           ///< position
  Vec3 ng;          ///< geometric normal, unit, facing the incoming ray
  Vec3 ns;          ///< shading normal, unit, in the hemisphere of ng
  Vec2 uv;          ///< texture coordinates
  Vec3 dpdu, dpdv;  ///< position derivatives along u and v (for ray differentials)
  int object = -1;  ///< index into Scene::objects, or -1 for a light
  int light = -1;   ///< index into Scene::lights when a visible rect light was hit
  bool front = true;  ///< the ray hit the side the stored normal points to (emitting side of a light)
};

/// Geometry of objects and visible area lights in one Embree scene. Intersect()
/// and Occluded() are thread safe (each call has its own context).
class EmbreeScene {
 public:
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  /// Tessellates or loads every object, applies transforms and builds the BVH.
  /// Mesh files that cannot be read are reported with the object's key path.
  static Status Build(const Scene& scene, std::unique_ptr<EmbreeScene>* out);

  /// Closest hit along org + t*dir, t in [tnear, tfar]; false on a miss.
  bool Intersect(Vec3 org, Vec3 dir, float tnear, float tfar, SurfaceHit* hit) const;
  /// Closest hits of rays from one origin (a camera's primary rays), traced
  /// as one coherent stream (Embree packs them into packets): hits[i] is
  /// valid where found[i]. The same hits as Intersect() ray by ray.
  void IntersectCoherent(Vec3 org, std::span<const Vec3> dirs, std::span<SurfaceHit> hits,
                         std::span<uint8_t> found) const;
  /// True when something blocks org + t*dir for t in [tnear, tfar].
  bool Occluded(Vec3 org, Vec3 dir, float tnear, float tfar) const;

  /// A point just off the surface at `p` on the side of `n`, to start rays
  /// from without hitting the surface again.
  static Vec3 Offset(Vec3 p, Vec3 n);

  size_t triangleCount() const;

 private:
  EmbreeScene() = default;
  struct Geometry {
    TriangleMesh mesh;
    int object = -1;
    int light = -1;
  };
  Status AddMesh(TriangleMesh mesh, int object, int light);
  /// The surface at the hit Embree reported for a ray along `dir`.
  void Shade(const RTCRayHit& rh, Vec3 dir, SurfaceHit* hit) const;
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  std::vector<Geometry> geometries_;  // indexed by Embree geometry ID
  std::string deviceError_;           // first error reported while building
};

}  // namespace dcm::embree
