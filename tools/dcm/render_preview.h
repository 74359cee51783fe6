// dcm render's --target-psnr and --budget judged by a preview of the tracer:
// every pixel traced with a few of the scene's rays, whose estimate of the
// result's error costs no exact pixel (docs/QUALITY.md, "The tracer's preview").
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
  double costShare = 0;               ///< its rays over the full render's, as measured before it
  double previewS = 0;                ///< measuring, tracing the preview and pooling its variance
  double previewPsnr = 0;             ///< its own noise against the converged image (display-referred)
  embree::RayCounts previewRays;      ///< the rays it took: the cost measured, the preview, its IDs
  PreviewTargetStats ladder;          ///< the runs its estimate judged
};

/// Whether the preview may judge the goal of `flags` (a --target-psnr in dB
/// or a --budget) with `options` on `provider`'s scene; where not, `why` says
/// what keeps it from it and validation pixels judge instead: `--estimate-from
/// validation`, a method other than dcm, --downsample (the scene's
/// supersampling: the preview estimates at final resolution), samples that
/// carry their variance (--spp above 1: the exact pixels are themselves
/// noisy, and validation pixels judge them against the converged image),
/// --progressive (its levels are estimated on validation pixels).
bool TracerPreviewApplies(const embree::EmbreeProvider& provider, const ReconstructionOptions& options,
                          const EngineFlags& flags, const std::string& estimateFrom, std::string* why);

/// With `estimateFrom` auto, measures what the preview would cost
/// (EmbreeProvider::PreviewCostShare) and goes no further where that is more
/// than a tenth of the full render's rays (point lights, few shadow rays: the
/// exact pixels it spares cost less than it does). Then traces the preview
/// (RenderPreview at kTracerPreviewDivisor), and where its own noise lets it
/// judge (CanTargetFromPreview) reconstructs `provider` to `goal` by
/// ReconstructToTargetFromPreview (`*judged` true). Where not, `*judged` is
/// false, `why` says why and validation pixels are to judge (the rays spent
/// so far count in the provider's).
Status ReconstructFromTracerPreview(embree::EmbreeProvider& provider, const ReconstructionOptions& options,
                                    const QualityGoal& goal, const std::string& estimateFrom, Reconstruction* out,
                                    QualityReport* report, TracerPreviewRun* run, bool* judged, std::string* why);

}  // namespace dcm::cli
