// dcm render's goal judged by a preview of the tracer (render_preview.h).
#include "render_preview.h"

#include <chrono>
#include <memory>
#include <vector>

#include "common/elapsed.h"
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
  GuideImage ids;
  DCM_RETURN_IF_ERROR(
      provider.Guides(Bounds2i{{0, 0}, {caps.width, caps.height}}, {true, true, false, false}, &ids));
  PreviewScheduleOptions so;
  const std::unique_ptr<SampleProvider> preview =
      PreviewFromSamples(s, caps.width, caps.height, caps.splitRadiance, true, ids,
                         VariancePoolRadius(options, caps), &so.previewOwnVariance);
  ApplyRoundFlags(RoundFlags{}, &so);  // the renderers' defaults (docs/TUNING.md), not chosen on the tracer
  so.maxRounds = kTracerMaxRounds;
  so.minRoundShare = 0;
  run->previewPsnr = PreviewNoisePsnr(*preview, so.previewOwnVariance);
  run->previewRays = provider.rayCounts().Since(before);
  run->previewS = toolkit::SecondsSince(t0);
  if (!CanTargetFromPreview(*preview, so, why)) return Status::Ok();
  *judged = true;
  return ReconstructToTargetFromPreview(provider, *preview, options, goal, so, out, report, &run->ladder);
}

}  // namespace dcm::cli
