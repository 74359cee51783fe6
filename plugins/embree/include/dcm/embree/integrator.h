// Exact evaluation of one pixel: direct light with stratified shadow rays (soft
// shadows), glossy reflection by lobe sampling with multiple importance
// sampling, recursive perfect mirrors, optional indirect diffuse light; and the
// cheap guides of a pixel from its primary ray.
#pragma once

#include <cstdint>
#include <vector>

#include "dcm/color.h"
#include "dcm/embree/camera.h"
#include "dcm/embree/embree_scene.h"
#include "dcm/embree/lights.h"
#include "dcm/embree/materials.h"
#include "dcm/embree/sampling.h"
#include "dcm/embree/scene.h"

namespace dcm::embree {

/// Rays traced, by purpose.
struct RayCounts {
  uint64_t primary = 0;   ///< camera rays of exact samples
  uint64_t guide = 0;     ///< camera and mirror rays of the guides
  uint64_t shadow = 0;    ///< towards lights
  uint64_t glossy = 0;    ///< sampling glossy lobes
  uint64_t mirror = 0;    ///< perfect reflections
  uint64_t indirect = 0;  ///< indirect diffuse
  uint64_t total() const { return primary + guide + shadow + glossy + mirror + indirect; }
  RayCounts& operator+=(const RayCounts& o) {
    primary += o.primary; guide += o.guide; shadow += o.shadow;
    glossy += o.glossy; mirror += o.mirror; indirect += o.indirect;
    return *this;
  }
  /// The rays traced since `earlier`, a count of the same counters.
  RayCounts Since(const RayCounts& earlier) const {
    return {primary - earlier.primary, guide - earlier.guide,   shadow - earlier.shadow,
            glossy - earlier.glossy,   mirror - earlier.mirror, indirect - earlier.indirect};
  }
};

/// One exact pixel: L = Li * tau + Lc (exactly, in floats).
struct PixelRadiance {
  RGB L, Li, Lc;
  RGB tau{1.f, 1.f, 1.f};
  /// Variance of the estimate of L (of the mean of samplesPerPixel
  /// estimates); 0 with one estimate.
  RGB variance;
};

/// The guides of one pixel.
struct PixelGuide {
  uint32_t objectId = 0;  ///< 0: background
  uint32_t shaderId = 0;  ///< 0: background
  RGB tau{1.f, 1.f, 1.f};
  /// Shading normal of the surface shown (at the end of a mirror chain, as the
  /// IDs); zero for the background and lights.
  Vec3 normal{0.f, 0.f, 0.f};
};

/// What the integrator may trace; set from the scene (only the effects the
/// scene calls for).
struct IntegratorConfig {
  int shadowRays = 16;
  int secondaryShadowRays = 1;
  int glossyRays = 0;       ///< 0 when no material is glossy
  int mirrorDepth = 0;      ///< 0 when no material is a mirror
  int indirectBounces = 0;  ///< 0: off
  int indirectRays = 0;
  int samplesPerPixel = 1;  ///< independent estimates averaged per pixel
  uint32_t seed = 0;
  RGB background;
  bool shadowGuide = false;  ///< point-light visibility folded into the guides' IDs
  bool highlightGuide = false;  ///< highlights of plastic surfaces folded into the guides' IDs (InHighlight)
};

/// R + G + B of a plastic surface's direct glossy light above which a pixel
/// is in a highlight: the AOV path's default `--highlight-level`, as bright
/// as mid-grey on the display.
inline constexpr float kHighlightLevel = 1.5f;

/// Evaluates pixels of the working image. Thread safe: all state is const and
/// every call seeds its own random numbers from the pixel.
class Integrator {
 public:
  /// `materials` indexed like Scene::materials; `objectMaterial` and `objectId`
  /// per object; `lightId` per light (for visible rect lights).
  Integrator(const EmbreeScene& bvh, const Camera& camera, IntegratorConfig config,
             std::vector<Material> materials, std::vector<Light> lights,
             std::vector<int> objectMaterial, std::vector<uint32_t> objectId,
             std::vector<uint32_t> lightId);

  /// The same scene traced with another `config` (a preview's ray counts and seed).
  Integrator(const Integrator& base, IntegratorConfig config) : Integrator(base) { cfg_ = config; }

  const IntegratorConfig& config() const { return cfg_; }

  /// The exact radiance of working pixel (x, y), split at the first hit.
  PixelRadiance Evaluate(int x, int y, RayCounts* counts) const;

  /// Object ID, shader ID (through mirror chains: IDs of the whole chain) and
  /// tau of working pixel (x, y); `tau` only when `wantTau`.
  PixelGuide Guide(int x, int y, bool wantTau, RayCounts* counts) const;
  /// Guide() of the pixels [x0, x1) of row y into out[0 .. x1-x0), the
  /// primary rays traced as one coherent stream: the same guides, faster.
  void GuideRow(int y, int x0, int x1, bool wantTau, RayCounts* counts, PixelGuide* out) const;

 private:
  struct Quality;
  struct Differentials;
  struct Shading {
    RGB diffuse;   ///< (1/pi) * incident light * cos: multiplied by the albedo
    RGB constant;  ///< glossy, mirror: not multiplied by the albedo
  };

  /// The guides of a primary ray `cr` that hit `h` (mirror chains followed).
  PixelGuide GuideFromHit(const CameraRay& cr, SurfaceHit h, bool wantTau, RayCounts* counts) const;
  /// Bit l set when point light l (of the first 32) lights `h`: the same
  /// shadow ray as DirectLight's (counted as a guide ray).
  uint32_t PointLightVisibility(const SurfaceHit& h, RayCounts* counts) const;
  /// True when the direct glossy light that `h` (a plastic surface seen
  /// along `dir`) reflects towards the eye exceeds kHighlightLevel in
  /// R + G + B, every light unshadowed (point lights, and rect lights as 4 x 4
  /// points): a highlight's footprint without a ray or a random number.
  bool InHighlight(const SurfaceHit& h, Vec3 dir) const;
  /// The shadow ray from `org` (just above `h`) to a point light.
  struct PointLightRay {
    Vec3 wi;           ///< unit, towards the light
    float dist = 0.f;  ///< to the light
    float cosS = 0.f;  ///< at the shading normal
  };
  /// Fills `r`; false when `h` faces away from the light (no ray to trace).
  /// DirectLight and PointLightVisibility share it, so the guide tests the
  /// very ray the illumination traces.
  bool FacesPointLight(const SurfaceHit& h, Vec3 org, const Light& light, PointLightRay* r) const;
  bool Unoccluded(Vec3 org, const PointLightRay& r) const;
  Shading Shade(const SurfaceHit& h, Vec3 wo, const Material& m, const Quality& q,
                const Differentials* diff, Pcg32& rng, RayCounts* counts) const;
  /// Radiance leaving `h` towards -dir, emission excluded.
  RGB Reflected(const SurfaceHit& h, Vec3 dir, const Quality& q, const Differentials* diff,
                Pcg32& rng, RayCounts* counts) const;
  /// Radiance arriving along a mirror-reflected ray (emission included).
  RGB TraceMirror(Vec3 org, Vec3 dir, const Quality& q, const Differentials* diff, Pcg32& rng,
                  RayCounts* counts) const;
  void DirectLight(const SurfaceHit& h, Vec3 wo, const Material& m, int samples, int glossyRays,
                   Pcg32& rng, RayCounts* counts, Shading* out) const;
  RGB TauAt(const SurfaceHit& h, const Material& m, const Differentials* diff) const;
  RGB Emission(const SurfaceHit& h) const;

  const EmbreeScene& bvh_;
  const Camera& camera_;
  IntegratorConfig cfg_;
  std::vector<Material> materials_;
  std::vector<Light> lights_;
  std::vector<int> objectMaterial_;
  std::vector<uint32_t> objectId_;
  std::vector<uint32_t> lightId_;
};

/// The ID of a chain of surfaces seen through mirrors: the plain ID for a
/// chain of one, else a hash of the chain with the top bit set.
uint32_t ChainId(const uint32_t* ids, int count);

}  // namespace dcm::embree
