// dcm render's goal judged by a preview of the tracer (render_preview.h).
#include "render_preview.h"

#include <chrono>
#include <utility>
#include <vector>

#include "common/elapsed.h"
#include "dcm/noise_estimate.h"
#include "dcm/preview_correction.h"
#include "dcm/reconstructor.h"
#include "dcm/round_schedule.h"

namespace dcm::cli {

namespace {

/// The tracer's exact pixels cost no latency: a run renders round after round
/// until its plan asks for nothing new, and no pixel keeps its preview value.
constexpr int kTracerMaxRounds = 16;

}  // namespace

bool TracerPreviewApplies(const embree::EmbreeProvider& provider, const ReconstructionOptions& options,
                          const EngineFlags& flags, std::string* why) {
  if (!flags.targetPsnr && !flags.budget) *why = "it judges --target-psnr or --budget, and neither is given";
  else if (flags.method != "dcm") *why = "--method " + flags.method + ": the preview plans dcm's runs";
  else if (options.downsample != 1)
    *why = "supersampling " + std::to_string(options.downsample) + ": the preview estimates at final resolution only";
  else if (provider.scene().render.samplesPerPixel > 1)
    *why = "--spp " + std::to_string(provider.scene().render.samplesPerPixel) +
           ": the exact samples are noisy, and validation pixels judge them against the converged image";
  else if (!flags.progressive.empty()) *why = "--progressive: validation pixels estimate each level";
  else if (flags.TargetsRender()) *why = "--target-psnr render: the exact samples carry no noise to pass";
  else return true;
  return false;
}

Status ReconstructFromTracerPreview(embree::EmbreeProvider& provider, const ReconstructionOptions& options,
                                    const QualityGoal& goal, Reconstruction* out, QualityReport* report,
                                    TracerPreviewRun* run, bool* judged, std::string* why) {
  *judged = false;
  const auto t0 = std::chrono::steady_clock::now();
  const embree::RayCounts before = provider.rayCounts();
  std::vector<ExactSample> s;
  DCM_RETURN_IF_ERROR(provider.RenderPreview(kTracerPreviewDivisor, &s));

  const ProviderCapabilities caps = provider.Capabilities();
  const int W = caps.width, H = caps.height;
  std::vector<RGB> L(s.size()), Li, Lc, own(s.size());
  if (caps.splitRadiance) {
    Li.resize(s.size());
    Lc.resize(s.size());
  }
  for (size_t i = 0; i < s.size(); ++i) {
    L[i] = s[i].L;
    own[i] = s[i].variance;
    if (caps.splitRadiance) {
      Li[i] = s[i].Li;
      Lc[i] = s[i].Lc;
    }
  }
  // Two estimates give each pixel's variance one degree of freedom: pooled
  // over its surface within the noisy regime's elementary block, as dcm
  // blender's preview is.
  ProviderCapabilities noisy = caps;
  noisy.variance = true;
  const int poolRadius = ResolveSettings(options, noisy).elementaryBlock;
  GuideImage ids;
  DCM_RETURN_IF_ERROR(provider.Guides(Bounds2i{{0, 0}, {W, H}}, {true, true, false, false}, &ids));
  std::vector<RGB> pooled = SurfaceWindowRelativeMean(own, L, W, H, ids.objectId, ids.shaderId, poolRadius);
  ImagePreviewProvider preview(W, H, W, H, std::move(L), std::move(Li), std::move(Lc), std::move(pooled));

  PreviewScheduleOptions so;
  ApplyRoundFlags(RoundFlags{}, &so);  // the renderers' defaults (docs/TUNING.md), not chosen on the tracer
  so.maxRounds = kTracerMaxRounds;
  so.minRoundShare = 0;
  so.previewOwnVariance = std::move(own);
  run->previewPsnr = PreviewNoisePsnr(preview, so.previewOwnVariance);
  run->previewRays = provider.rayCounts().Since(before);
  run->previewS = toolkit::SecondsSince(t0);
  if (!CanTargetFromPreview(preview, so, why)) return Status::Ok();
  *judged = true;
  return ReconstructToTargetFromPreview(provider, preview, options, goal, so, out, report, &run->ladder);
}

}  // namespace dcm::cli
