// dcm render's --target-psnr and --budget judged by a preview of the tracer:
// every pixel traced with a few of the scene's rays, whose estimate of the
// result's error costs no exact pixel (docs/QUALITY.md, "A goal judged by the
// tracer's preview").
#pragma once

#include <string>

#include "dcm/embree/embree_provider.h"
#include "dcm/preview_target.h"
#include "dcm/quality_target.h"
#include "engine_flags.h"

namespace dcm::cli {

/// The preview's rays: each secondary ray count of the scene over this, two
/// estimates a pixel: about a sixteenth of the full render's secondary rays,
/// as `dcm blender`'s preview is a sixteenth of the samples (not tuned).
inline constexpr int kTracerPreviewDivisor = 32;

/// What the preview did.
struct TracerPreviewRun {
  double previewS = 0;                ///< tracing the preview and pooling its variance
  double previewPsnr = 0;             ///< its own noise against the converged image (display-referred)
  embree::RayCounts previewRays;      ///< the rays it took: the preview and the IDs that pool its variance
  PreviewTargetStats ladder;          ///< the runs its estimate judged
};

/// Whether the preview can judge a goal of `flags` (--target-psnr in dB or
/// --budget) with `options` on `provider`'s scene; where not, `why` says what
/// keeps it from it: no goal, a method other than dcm, the scene's
/// supersampling (the preview estimates at final resolution), samples that
/// carry their variance (--spp above 1: the exact pixels are themselves
/// noisy, and validation pixels judge them against the converged image),
/// --progressive (its levels are estimated on validation pixels).
bool TracerPreviewApplies(const embree::EmbreeProvider& provider, const ReconstructionOptions& options,
                          const EngineFlags& flags, std::string* why);

/// Traces the preview (RenderPreview at kTracerPreviewDivisor) and, where its
/// own noise lets it judge (CanTargetFromPreview: `*judged` true),
/// reconstructs `provider` to `goal` by ReconstructToTargetFromPreview, with
/// the renderers' round flags' defaults and up to 16 rounds (they cost no
/// latency here). Where not, `*judged` is false and `why` says why (the
/// preview's rays are spent and counted in the provider's).
Status ReconstructFromTracerPreview(embree::EmbreeProvider& provider, const ReconstructionOptions& options,
                                    const QualityGoal& goal, Reconstruction* out, QualityReport* report,
                                    TracerPreviewRun* run, bool* judged, std::string* why);

}  // namespace dcm::cli
