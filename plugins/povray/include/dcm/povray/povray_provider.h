// POV-Ray 3.7 as a sample provider: the passes of one scene file written with
// the pass convention of docs/POVRAY.md (`Declare=Pass=N`, a mesh camera under
// `Declare=Sparse=1`), each rendered by a POV-Ray process. The guide passes
// are rendered once in full; exact samples are rendered for just the pixels
// asked, through the mesh camera, the beauty and illumination passes side by
// side in two processes.
#pragma once

#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "dcm/round_schedule.h"
#include "dcm/sample_provider.h"
#include "dcm/status.h"

namespace dcm::pipe {
class ScratchFolder;
}  // namespace dcm::pipe

namespace dcm::povray {

/// The passes of the convention, by their `Declare=Pass=N` number.
enum class Pass : int {
  kBeauty = 0,        ///< L: the scene as it is
  kObjectId = 1,      ///< every channel the object's ID, emission only
  kShaderId = 2,      ///< every channel the material's ID, emission only
  kTexture = 3,       ///< tau: the diffuse pigment, emission only
  kIllumination = 4,  ///< L_i: every pigment white, diffuse and ambient only
  kNormal = 5,        ///< slope patterns along x, y, z in R, G, B
  /// 1 where the texture has highlights or reflection (L_c may be non-zero),
  /// else 0, emission only. Optional: without it every exact pixel's L_i is
  /// rendered; with it only those marked (elsewhere L_i = L/tau).
  kHighlight = 6,
};

/// The least tau (every channel) that L_i = L/tau is derived from on a matte
/// surface: below it the half-float L holds too few bits of L_i.
inline constexpr float kMinDivisibleTau = 0.01f;

/// "beauty", "object ID", ... for messages.
std::string_view PassName(Pass pass);

struct PovrayEnv;  // src/povray_process.h
struct PovrayJob;

struct PovrayOptions {
  std::string scene;              ///< the .pov file
  std::string povray = "povray";  ///< the executable: a path, or a name looked up on PATH
  int width = 0, height = 0;      ///< the frame
  /// POV-Ray processes run at the same time. POV-Ray spends about 0.6 s of
  /// each process waiting (start-up, its frontend's polling), so two short
  /// processes on two cores cost about the wall time of one.
  int concurrency = 2;
};

/// What the POV-Ray processes cost, by phase.
struct PovrayRunStats {
  int invocations = 0;          ///< POV-Ray processes, all passes
  int litInvocations = 0;       ///< of which the beauty and illumination passes
  std::vector<double> roundS;   ///< wall time of each Evaluate() call
  std::vector<int64_t> roundPixels;  ///< pixels asked in each Evaluate() call
  int64_t illuminationPixels = 0;    ///< of those, rendered in the illumination pass too
};

/// The provider. Not thread safe (Capabilities().threadSafe is false): the
/// engine calls it from one thread.
class PovrayProvider final : public SampleProvider {
 public:
  /// Checks that the scene is readable and mentions the convention's names
  /// (Pass, Sparse, NPix, PixX, PixY), finds POV-Ray and makes the private scratch folder
  /// for the renders and the pixel lists (removed by the destructor and, on
  /// SIGINT, SIGTERM or SIGHUP, by SignalCleanup()).
  static Status Open(const PovrayOptions& options, std::unique_ptr<PovrayProvider>* out);
  ~PovrayProvider() override;
  PovrayProvider(const PovrayProvider&) = delete;
  PovrayProvider& operator=(const PovrayProvider&) = delete;

  /// Renders the guide passes (object and shader IDs, tau, normal, the
  /// highlight mask) in full,
  /// `concurrency` processes at a time, and checks that the ID passes hold
  /// one integer per pixel (a scene that ignores `Pass` does not). In the
  /// same batch of processes, first (they take longest), it renders `also`
  /// densely at `alsoWidth` x `alsoHeight` into `alsoOut` (a preview).
  Status RenderGuides(std::span<const Pass> also = {}, int alsoWidth = 0, int alsoHeight = 0,
                      std::vector<std::vector<RGB>>* alsoOut = nullptr);

  /// Renders `passes` densely (the perspective camera) at `width` x `height`,
  /// side by side: the full render (--full) and low-resolution previews.
  /// `out` gets one RGB image per pass, row-major.
  Status RenderDense(std::span<const Pass> passes, int width, int height, std::vector<std::vector<RGB>>* out);

  ProviderCapabilities Capabilities() const override;
  /// The guides of RenderGuides() (which must have run) for `region`.
  Status Guides(const Bounds2i& region, const GuideRequest& what, GuideImage* out) override;
  /// Renders the beauty and illumination passes for `pixels` through the
  /// mesh camera, in two processes at the same time: one round. The
  /// illumination pass renders only the pixels the highlight mask marks (or
  /// whose tau is below kMinDivisibleTau), from its own pixel list.
  Status Evaluate(std::span<const Point2i> pixels, const SampleRequest& what,
                  std::span<ExactSample> out) override;

  /// What a round costs: a POV-Ray process spends about 0.65 s starting and
  /// stopping however small its image (measured with POV-Ray 3.7.0.10: its
  /// frontend and renderer exchange messages in 50 ms waits); the cost of a
  /// pixel depends on the scene (unknown: 0).
  RoundCost Cost() const { return RoundCost{0.65, 0}; }

  const PovrayRunStats& runStats() const { return stats_; }
  /// Per working pixel: 1 where Evaluate() rendered it.
  const std::vector<uint8_t>& rendered() const { return rendered_; }
  /// Per working pixel: the rendered sample (where rendered() is 1).
  const std::vector<ExactSample>& samples() const { return samples_; }
  /// The guides of RenderGuides(), whole frame.
  const std::vector<uint32_t>& objectIds() const { return objectId_; }
  const std::vector<uint32_t>& shaderIds() const { return shaderId_; }
  const std::vector<RGB>& texture() const { return tau_; }
  /// Whether the scene rendered the highlight mask (pass 6).
  bool haveHighlightMask() const { return haveHighlightMask_; }
  /// The scratch folder (for messages and tests).
  const std::string& scratch() const { return scratch_; }

 private:
  explicit PovrayProvider(PovrayOptions options) : options_(std::move(options)) {}
  /// Where and how the processes run.
  PovrayEnv Env() const;
  /// The job rendering `pass` for a list of `n` pixels (pixels.inc).
  PovrayJob SparseJob(Pass pass, size_t n) const;

  PovrayOptions options_;
  std::string povrayPath_;  ///< the executable found
  std::shared_ptr<pipe::ScratchFolder> scratchFolder_;  ///< removed with the provider
  std::string scratch_;     ///< its path
  PovrayRunStats stats_;
  bool haveGuides_ = false;
  std::vector<uint32_t> objectId_, shaderId_;
  std::vector<RGB> tau_;
  std::vector<Vec3f> normal_;
  bool haveHighlightMask_ = false;
  std::vector<uint8_t> highlight_;  ///< per pixel, with the mask
  std::vector<uint8_t> rendered_;
  std::vector<ExactSample> samples_;
};

/// For the SIGINT/SIGTERM/SIGHUP handlers (toolkit::SetSignalHook): kills
/// every POV-Ray process (the scratch folder's guardian removes the folder once
/// dcm is gone). Async-signal-safe.
void SignalCleanup();

}  // namespace dcm::povray
