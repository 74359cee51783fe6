// A PSNR target judged by the preview's estimate: a ladder of preview-planned
// runs over one planner, so that each renders only what is new.
#include "dcm/preview_target.h"

#include <cmath>
#include <cstdio>
#include <new>
#include <string>
#include <utility>

#include "planning_provider.h"

namespace dcm {

namespace {

/// The ladder: from kStartFactor times the default threshold down by kStep
/// per run, at most kMaxRuns runs (chosen on the tuning set, docs/TUNING.md:
/// coarser starts save few pixels, as the lattice's corners remain; a finer
/// step costs a render call per run).
constexpr double kStartFactor = 3, kStep = 0.5;
constexpr int kMaxRuns = 7;
/// Two runs in a row that each raise the estimate by less than this have
/// reached what the threshold can give (the exact samples' noise, stand-ins).
constexpr double kPlateauDb = 0.1;

/// The full render's PSNR from the preview's own (`previewPsnr`): each exact
/// pixel keeps ExactVarianceShare(schedule) of the preview's noise.
double RenderPsnr(double previewPsnr, const PreviewScheduleOptions& schedule) {
  const double share = ExactVarianceShare(schedule);
  return share > 0 ? previewPsnr - 10 * std::log10(share) : HUGE_VAL;
}

std::string Db(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f dB", v);
  return buf;
}

}  // namespace

bool CanTargetFromPreview(SampleProvider& preview, const PreviewScheduleOptions& schedule, std::string* why) {
  const double own = PreviewNoisePsnr(preview, schedule.previewOwnVariance);
  if (std::isfinite(own) && own >= kMinPreviewPsnrForEstimate) return true;
  if (why)
    *why = std::isfinite(own) ? "the preview's own noise costs " + Db(own) + ", below " +
                                    Db(kMinPreviewPsnrForEstimate) + ": too noisy to estimate from"
                              : "the preview carries no variance";
  return false;
}

double RenderPsnrFromPreview(SampleProvider& preview, const PreviewScheduleOptions& schedule) {
  return RenderPsnr(PreviewNoisePsnr(preview, schedule.previewOwnVariance), schedule);
}

Status ReconstructToTargetFromPreview(SampleProvider& exact, SampleProvider& preview,
                                      const ReconstructionOptions& options, double targetPsnr,
                                      const PreviewScheduleOptions& schedule, Reconstruction* out,
                                      QualityReport* report, PreviewTargetStats* stats) {
  if (!(targetPsnr > 0 && targetPsnr <= 99))
    return Status::Error("--target-psnr: " + std::to_string(targetPsnr) + " dB is outside (0, 99]");
  DCM_RETURN_IF_ERROR(CheckPreviewSchedule(exact, preview, options, schedule));
  if (schedule.correctionRadius < 1)
    return Status::Error("target from the preview: the preview correction is off, and it makes the estimate");
  if (options.downsample != 1)
    return Status::Error("target from the preview: the preview estimates at final resolution only (downsample 1)");
  const ProviderCapabilities caps = exact.Capabilities();
  if (!preview.Capabilities().variance)
    return Status::Error("target from the preview: the preview carries no variance");

  PreviewTargetStats local;
  PreviewTargetStats& s = stats ? *stats : local;
  s = PreviewTargetStats{};
  try {
    // The preview's own noise, once: only the exact share changes over the runs.
    const double previewPsnr = PreviewNoisePsnr(preview, schedule.previewOwnVariance);
    s.renderPsnrAtStart = RenderPsnr(previewPsnr, schedule);
    s.beyondRender = !(targetPsnr <= s.renderPsnrAtStart - kRenderNoiseMarginDb);
    PlanningProvider planning(exact, preview);
    ReconstructionOptions o = options;
    const double defaultThreshold = double(ResolveSettings(options, caps).contrastThreshold);
    double threshold = s.beyondRender ? defaultThreshold : kStartFactor * defaultThreshold;
    const int maxRuns = s.beyondRender ? 1 : kMaxRuns;
    Reconstruction best;
    bool reached = false;
    int flat = 0;
    for (int run = 0; run < maxRuns && !reached; ++run, threshold *= kStep) {
      o.contrastThreshold = float(threshold);
      PreviewScheduleStats runStats;
      Reconstruction rec;
      DCM_RETURN_IF_ERROR(PlanAndRender(planning, o, schedule, s.rounds, &rec, &runStats));
      DCM_RETURN_IF_ERROR(FinishPreviewRun(planning, preview, o, schedule, &rec, &runStats));
      const PsnrEstimate& e = runStats.correction.estimate;
      if (std::isnan(e.psnr))
        return Status::Error("target from the preview: the preview made no estimate (its own PSNR " +
                             Db(runStats.correction.previewPsnr) + ")");
      flat = !s.estimates.empty() && e.psnr < s.estimates.back().psnr + kPlateauDb ? flat + 1 : 0;
      s.thresholds.push_back(threshold);
      s.estimates.push_back(e);
      s.rounds += runStats.rounds;
      s.pixelsPerRound.insert(s.pixelsPerRound.end(), runStats.pixelsPerRound.begin(), runStats.pixelsPerRound.end());
      s.timeEngineS += runStats.timeEngineS;
      s.timeExactS += runStats.timeExactS;
      s.last = std::move(runStats);
      best = std::move(rec);
      reached = e.low >= targetPsnr;
      if (flat >= 2) break;
    }
    // With the exact pixels' noise measured on the rounds, where it was.
    s.renderPsnr = RenderPsnr(previewPsnr, schedule);
    s.renderedPixels = planning.KnownCount();
    // As ReconstructToQuality's: the cost of every run (with noisy samples a
    // pixel an earlier run rendered is interpolated again, and still paid for).
    best.stats.exactPixels = s.renderedPixels;
    best.stats.timeProviderS = s.timeExactS;
    best.stats.providerCalls = s.rounds;

    QualityReport r;
    r.estimate = s.estimates.back();
    r.estimateSource = EstimateSource::kPreview;
    r.againstConverged = true;
    r.renderEstimate = {s.renderPsnr, NAN, NAN};
    r.targetPsnr = targetPsnr;
    r.exactPixels = s.renderedPixels;
    r.totalPixels = int64_t(caps.width) * int64_t(caps.height);
    r.threshold = s.thresholds.back();
    r.runs = int(s.thresholds.size());
    r.targetReached = reached;
    *out = std::move(best);
    if (report) *report = std::move(r);
  } catch (const std::bad_alloc&) {
    return Status::Error("out of memory in the target search on the preview's estimate");
  }
  return Status::Ok();
}

}  // namespace dcm
