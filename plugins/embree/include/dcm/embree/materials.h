// Materials at render time: the BRDFs of the integrator.
#pragma once

#include <cmath>

#include "dcm/color.h"
#include "dcm/embree/scene.h"
#include "dcm/embree/textures.h"
#include "dcm/embree/vec3.h"

namespace dcm::embree {

/// A material ready for shading; `texture` (may be null) multiplies `color`.
struct Material {
  MaterialKind kind = MaterialKind::kDiffuse;
  RGB color;                        ///< diffuse albedo (before the texture)
  const Texture* texture = nullptr; ///< tau, owned by the provider
  RGB specular;                     ///< Phong lobe (plastic) or mirror reflectance
  float exponent = 0.f;             ///< Phong exponent
  bool glossy() const { return kind == MaterialKind::kPlastic && Luminance(specular) > 0.f; }
  bool diffuse() const { return kind != MaterialKind::kMirror; }
};

/// The normalised Phong lobe (e+2)/(2 pi) cos^e(alpha), alpha the angle between
/// the mirror direction `wr` and `wi`; zero outside the lobe. Multiplied by
/// the specular colour it is the glossy BRDF of plastic.
inline float PhongLobe(Vec3 wr, Vec3 wi, float e) {
  float c = Dot(wr, wi);
  return c > 0.f ? (e + 2.f) / (2.f * kPi) * std::pow(c, e) : 0.f;
}

/// Density (solid angle) of SamplePhongLobe() around `wr`.
inline float PhongPdf(Vec3 wr, Vec3 wi, float e) {
  float c = Dot(wr, wi);
  return c > 0.f ? (e + 1.f) / (2.f * kPi) * std::pow(c, e) : 0.f;
}

}  // namespace dcm::embree
