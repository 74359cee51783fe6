// A sample provider whose exact value at every pixel is closed-form, so ground
// truth is free: the engine's tests and benchmarks run on it.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "dcm/sample_provider.h"

namespace dcm::testing {

/// Everything a renderer knows about one pixel.
struct PixelTruth {
  uint32_t objectId = 1;
  uint32_t shaderId = 1;
  RGB tau = RGB::Gray(1.f);  ///< texture value; L = Li * tau + Lc
  RGB Li;
  RGB Lc;
  /// L as a renderer measured it, when it is not exactly Li * tau + Lc (a
  /// renderer that divides L_t by a tiny tau, or leaves garbage in L_i).
  std::optional<RGB> renderedL;
  Vec3f normal{0.f, 0.f, 1.f};  ///< surface normal (a guide with AnalyticChannels::normals)
  RGB L() const { return renderedL.value_or(Li * tau + Lc); }
};

using SceneFunction = std::function<PixelTruth(int x, int y)>;

/// Which channels the provider advertises.
struct AnalyticChannels {
  bool ids = true;
  bool shaders = true;
  bool texture = true;
  bool normals = false;  ///< advertise the normal guide
  bool hardShadowsGuided = false;  ///< ProviderCapabilities::hardShadowsGuided
};

/// Serves a SceneFunction; counts how often each pixel is evaluated.
class AnalyticProvider : public SampleProvider {
 public:
  AnalyticProvider(int width, int height, SceneFunction scene, AnalyticChannels channels = {});

  ProviderCapabilities Capabilities() const override;
  Status Guides(const Bounds2i& region, const GuideRequest& what, GuideImage* out) override;
  Status Evaluate(std::span<const Point2i> pixels, const SampleRequest& what,
                  std::span<ExactSample> out) override;

  /// L at every pixel (the baseline render).
  std::vector<RGB> FullRender() const;
  /// Guides of every pixel.
  PixelTruth Truth(int x, int y) const { return scene_(x, y); }
  /// Largest number of evaluations of any one pixel.
  int MaxEvaluationsOfOnePixel() const;
  int64_t TotalEvaluations() const;
  /// How many times pixel (x, y) was evaluated.
  int EvaluationsOf(int x, int y) const { return count_[size_t(y) * size_t(width_) + size_t(x)].load(); }

 private:
  int width_, height_;
  SceneFunction scene_;
  AnalyticChannels channels_;
  std::unique_ptr<std::atomic<int>[]> count_;
};

/// Options of the furnished test scene.
struct FurnishedOptions {
  bool softShadow = true;  ///< a penumbra 6 px wide across the background
  bool disc = true;        ///< a shaded disc (object 2)
  bool thinLine = true;    ///< a bright 1-px line at 34 degrees (object 3)
  bool texture = true;     ///< a checker/plank-textured floor (object 4) with a glossy highlight
  bool hdr = true;         ///< a small light source of radiance 1000 (object 5)
};

/// A scene with soft shadow edges, a thin line at an angle, a textured floor,
/// flat regions and high dynamic range; all closed-form.
SceneFunction FurnishedScene(int width, int height, FurnishedOptions o = {});

/// True when pixel (x, y) of FurnishedScene(width, height) lies on the thin line.
bool OnThinLine(int width, int height, int x, int y);

/// L = a + b*x + c*y (one surface).
SceneFunction LinearRamp(RGB a, RGB bx, RGB cy);

/// A constant colour.
SceneFunction Constant(RGB c);

/// Uniform white noise in [0,1) per pixel and channel, with a fixed seed.
SceneFunction Noise(uint32_t seed);

/// One object made of many triangle-shaped primitives (each its own object ID)
/// sharing one shader, smoothly lit (the situation of paper 3.2).
SceneFunction ManyPrimitivesOneShader(int primitiveSize);

/// PSNR in dB of sRGB-encoded values clipped to [0,1] (display-referred).
double DisplayPsnr(const std::vector<RGB>& image, const std::vector<RGB>& reference);

}  // namespace dcm::testing
