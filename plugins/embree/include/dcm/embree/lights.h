// Lights at render time: point lights and one-sided rectangular area lights.
#pragma once

#include "dcm/color.h"
#include "dcm/embree/scene.h"
#include "dcm/embree/vec3.h"

namespace dcm::embree {

/// A light ready for sampling.
struct Light {
  LightKind kind = LightKind::kPoint;
  Vec3 position;            ///< point light
  RGB intensity;            ///< point light, W/sr
  Vec3 origin, edgeU, edgeV;///< rect light: origin + s*edgeU + t*edgeV
  Vec3 normal;              ///< rect light: unit, the emitting side
  float area = 0.f;
  RGB radiance;             ///< rect light
  bool visible = true;      ///< rect light is in the BVH (seen by reflection rays)

  static Light From(const LightDesc& d) {
    Light l;
    l.kind = d.kind;
    l.position = d.position;
    l.intensity = d.intensity;
    l.origin = d.origin;
    l.edgeU = d.edgeU;
    l.edgeV = d.edgeV;
    Vec3 c = Cross(d.edgeU, d.edgeV);
    l.area = Length(c);
    l.normal = l.area > 0.f ? c / l.area : Vec3{0.f, 1.f, 0.f};
    l.radiance = d.radiance;
    l.visible = d.visible;
    return l;
  }
  /// The point of a rect light at (s, t) in [0,1]^2 (uniform in area).
  Vec3 PointAt(Vec2 st) const { return origin + edgeU * st.x + edgeV * st.y; }
  /// Solid-angle density of sampling the rect uniformly by area, seen from a
  /// point at distance `dist` where the light's cosine is `cosLight`.
  float PdfSolidAngle(float dist, float cosLight) const {
    return cosLight > 0.f ? dist * dist / (cosLight * area) : 0.f;
  }
};

}  // namespace dcm::embree
