// The internal Embree 3 ray tracer as a dcm::SampleProvider.
#pragma once

#include <array>
#include <atomic>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "dcm/sample_provider.h"
#include "dcm/embree/camera.h"
#include "dcm/embree/embree_scene.h"
#include "dcm/embree/integrator.h"
#include "dcm/embree/scene.h"
#include "dcm/embree/textures.h"

namespace dcm::embree {

/// The effects a scene calls for; the provider simulates only these.
struct Effects {
  bool pointLights = false;   ///< hard shadows from point lights
  bool areaLights = false;    ///< soft shadows from rectangular lights
  bool glossy = false;        ///< glossy reflection rays (a plastic material and glossy_rays > 0)
  bool mirror = false;        ///< mirror paths (a mirror material and mirror_depth > 0)
  bool textures = false;      ///< a textured material: tau guides and split radiance
  bool indirect = false;      ///< indirect diffuse (render.indirect.bounces > 0)
  bool shadowGuide = false;   ///< point-light visibility in the guides (render.shadow_guide)
  bool plastic = false;       ///< a plastic material with a specular lobe: highlights of direct light
  bool highlightGuide = false; ///< highlights in the guides (render.highlight_guide)
  /// Names of the active effects ("point_lights", "area_lights", "glossy",
  /// "mirror", "textures", "indirect", "shadow_guide", "highlight_guide").
  std::vector<std::string> Names() const;
};

/// Provides guides and exact samples of a scene by ray tracing with Embree.
/// The working image is the camera resolution times render.supersampling per
/// axis. Evaluate() and Guides() are thread safe.
class EmbreeProvider final : public SampleProvider {
 public:
  /// Builds the BVH, textures and lights of `scene`. Errors (unreadable mesh
  /// or texture) name the file and the key path.
  static Status Create(const Scene& scene, std::unique_ptr<EmbreeProvider>* out);
  /// Loads the scene file at `path` and creates the provider for it.
  static Status FromFile(const std::string& path, std::unique_ptr<EmbreeProvider>* out);

  ProviderCapabilities Capabilities() const override;
  Status Guides(const Bounds2i& region, const GuideRequest& what, GuideImage* out) override;
  Status Evaluate(std::span<const Point2i> pixels, const SampleRequest& what,
                  std::span<ExactSample> out) override;

  /// A preview of every working pixel, row-major, for a goal judged by its
  /// estimate (tools/dcm/render_preview.h): each secondary ray count of the
  /// scene (shadow, glossy, secondary shadow, indirect) divided by `divisor`,
  /// at least 1, and two independent estimates per pixel on random numbers of
  /// their own (not the exact samples'): L, L_i and L_c and the variance of
  /// their mean. Its rays count in rayCounts().
  Status RenderPreview(int divisor, std::vector<ExactSample>* out);
  /// One exact pixel with its tau (for tests and tools; same bits as Evaluate()).
  PixelRadiance EvaluatePixel(int x, int y);
  /// The guides of one pixel, its primary ray traced alone (for tests: the
  /// same as Guides(), which traces each row as one coherent stream).
  PixelGuide GuidePixel(int x, int y, bool wantTau);

  /// The effects this scene calls for.
  const Effects& effects() const { return effects_; }
  /// Rays traced so far, by kind.
  RayCounts rayCounts() const;
  /// Sets all ray counters to zero.
  void ResetRayCounts();

  const Scene& scene() const { return scene_; }
  int workWidth() const { return workWidth_; }
  int workHeight() const { return workHeight_; }
  size_t triangleCount() const { return bvh_->triangleCount(); }

 private:
  EmbreeProvider() = default;
  void AddCounts(const RayCounts& c);
  /// The integrator's config with each secondary ray count over `divisor`
  /// (at least 1), two estimates a pixel, a seed of its own.
  IntegratorConfig PreviewConfig(int divisor) const;

  Scene scene_;
  int workWidth_ = 0, workHeight_ = 0;
  Effects effects_;
  std::unique_ptr<EmbreeScene> bvh_;
  std::unique_ptr<Camera> camera_;
  TextureCache textureCache_;
  std::vector<std::unique_ptr<Texture>> textures_;
  std::unique_ptr<Integrator> integrator_;
  std::array<std::atomic<uint64_t>, 6> counters_{};
};

}  // namespace dcm::embree
