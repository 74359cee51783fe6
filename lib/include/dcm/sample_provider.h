// The protocol between the engine and any renderer: cheap guides for a region,
// expensive exact samples for a batch of pixels.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "dcm/color.h"
#include "dcm/geometry.h"
#include "dcm/status.h"

namespace dcm {

/// What a provider can deliver for the scene it serves. A provider reports what
/// the *scene* calls for: a scene without textures reports `texture = false`
/// even if the renderer could compute a texture value.
struct ProviderCapabilities {
  int width = 0;   ///< working resolution (the supersampled image), pixels
  int height = 0;
  bool objectId = false;       ///< guides carry an object ID per pixel
  bool shaderId = false;       ///< guides carry a shader (material) ID per pixel
  bool texture = false;        ///< guides carry the texture value tau per pixel
  bool normal = false;         ///< guides carry the surface normal per pixel (creases inside one object)
  bool splitRadiance = false;  ///< samples carry (L_i, L_c) with L = L_i*tau + L_c
  bool variance = false;       ///< samples carry the variance of their estimate of L
  /// Every hard shadow of the scene shows in the guides: the scene has no
  /// point or directional light, or the guides mark where such a light's
  /// visibility changes (a shadow guide folded into the IDs); and so does
  /// every highlight where the provider knows the scene has any (the
  /// tracer's highlight guide). Then a smooth block of samples that are not
  /// noisy needs no centre probe (SmoothRefinement::kCentreProbe,
  /// ResolvedSettings::smoothRefinement): what the probe finds between a
  /// block's corners is a shadow or a highlight smaller than the block, and
  /// the guides show those.
  bool hardShadowsGuided = false;
  /// Evaluate() may be called concurrently from several threads on disjoint
  /// batches. Providers that are not thread safe are called from one thread.
  bool threadSafe = true;
  std::string name;  ///< for statistics and messages
};

/// Which guides to fill.
struct GuideRequest {
  bool objectId = false;
  bool shaderId = false;
  bool texture = false;
  bool normal = false;
};

/// Guides for a region, row-major over `region`; arrays not requested stay empty.
struct GuideImage {
  Bounds2i region;
  std::vector<uint32_t> objectId;
  std::vector<uint32_t> shaderId;
  std::vector<RGB> texture;  ///< tau
  std::vector<Vec3f> normal; ///< surface normal (need not be unit length; zero: none)
};

/// Which parts of an exact sample to compute.
struct SampleRequest {
  bool split = false;     ///< fill L_i and L_c
  bool variance = false;  ///< fill variance
};

/// The largest magnitude of a sample value (L, L_i, L_c) the engine takes;
/// finite values beyond it are clamped to it as they arrive. Far above any
/// radiance (the sun's disc is about 1.6e9 cd/m^2), and small enough that the
/// engine's sums and squares of samples stay finite in float (1e30 per square).
inline constexpr float kMaxSampleMagnitude = 1e15f;

/// One exact (expensive) sample of a pixel.
struct ExactSample {
  RGB L;         ///< radiance; always filled
  RGB Li;        ///< radiance before texturing (L_t / tau); with `split`
  RGB Lc;        ///< radiance not modulated by the texture; with `split`
  RGB variance;  ///< variance of the estimate of L; with `variance`
};

/// A source of guides and exact samples: the internal ray tracer, EXR AOVs of
/// another renderer, a callback of a host application, or a child process.
///
/// Contract: exact samples are deterministic per pixel (the same pixel gives
/// the same bits whatever the batch, its order or the thread), so that the
/// engine's result does not depend on thread count or tiling.
class SampleProvider {
 public:
  virtual ~SampleProvider() = default;

  /// What this provider can deliver; constant for the provider's lifetime.
  virtual ProviderCapabilities Capabilities() const = 0;

  /// Fills the requested guides for `region` (inside the working image).
  virtual Status Guides(const Bounds2i& region, const GuideRequest& what, GuideImage* out) = 0;

  /// Evaluates `pixels` exactly; `out` has the same size as `pixels`. May
  /// return Status::Pending when the samples must come from another process
  /// (the engine then reports the requested pixels and stops).
  virtual Status Evaluate(std::span<const Point2i> pixels, const SampleRequest& what,
                          std::span<ExactSample> out) = 0;

  /// Called once before the engine asks for `pixels` in several Evaluate()
  /// calls, which may run concurrently: a provider that bounds what it
  /// evaluates (a budget) accepts or refuses them together, so that what it
  /// evaluated does not depend on which call came first. Default: accepted.
  virtual Status Admit(std::span<const Point2i> pixels, const SampleRequest& what) {
    (void)pixels;
    (void)what;
    return Status::Ok();
  }

  /// Moves into `pixels` and `samples` the pixels that the last Evaluate()
  /// computed exactly besides those asked for, as asked for (a renderer whose
  /// call traces every ray of some other pixels too: Cycles with a wide pixel
  /// filter). The same values as Evaluate() would give them. Default: none.
  virtual void TakeExtraSamples(std::vector<Point2i>* pixels, std::vector<ExactSample>* samples) {
    pixels->clear();
    samples->clear();
  }
};

}  // namespace dcm
