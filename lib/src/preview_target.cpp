// A PSNR target judged by the preview's estimate: a ladder of preview-planned
// runs over one planner, so that each renders only what is new.
#include "dcm/preview_target.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <new>
#include <string>
#include <utility>

#include "number_text.h"
#include "planning_provider.h"

namespace dcm {

namespace {

/// The ladder: from kStartFactor times the default threshold down by kStep
/// per run, at most kMaxRuns runs (chosen on the tuning set, docs/TUNING.md:
/// coarser starts save few pixels, as the lattice's corners remain; a finer
/// step costs a render call per run).
constexpr double kStartFactor = 3, kStep = 0.5;
constexpr int kMaxRuns = 7;
/// The ladder starts an octave coarser, and again, while the preview predicts
/// that run's first round alone reaches the target by this much
/// (PredictFirstRound) and the plan shrinks: where the target lies far below
/// what the start gives, its pixels were spent for nothing (docs/TUNING.md).
constexpr double kPredictMarginDb = 1;
/// Two runs in a row that each raise the estimate by less than this have
/// reached what the threshold can give (the exact samples' noise, stand-ins).
constexpr double kPlateauDb = 0.1;
/// With a budget, the share of what is left that a run's plan on the preview
/// may ask for: its later rounds add the pixels whose choice the exact values
/// changed (on the tuning room at 512 spp, 2.4 % of the first round's). Where
/// it does not hold the coarsest plan, the first run may take all of it.
constexpr double kPlanShare = 0.9;
/// The thresholds a budget chooses from, and the plans (engine runs on the
/// preview, no pixel rendered) its bisection in log threshold may make: 10
/// narrow the 14 octaves to a step of 1 %. Above 1 the contrast tests pass
/// nearly everything, and the lattice's corners and the thin-object tests
/// remain.
constexpr double kMinThreshold = 1e-3, kMaxThreshold = 16;
constexpr int kFitPlans = 10;

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

/// The pixels a run at `threshold` would ask for first, planned on what
/// `planning` knows (the preview, and the exact pixels rendered so far).
Status PlannedPixels(PlanningProvider& planning, ReconstructionOptions o, double threshold, double* engineS,
                     int64_t* pixels) {
  o.contrastThreshold = float(threshold);
  Reconstruction dry;
  return Plan(planning, o, &dry, pixels, engineS);
}

/// The smallest threshold in (lo, hi] whose plan asks for at most `allowed`
/// pixels, where `lo`'s asks for more: bisected in log threshold (the plan
/// shrinks as the threshold grows); `*fits` false where even `hi`'s does.
Status FitThreshold(PlanningProvider& planning, const ReconstructionOptions& o, double lo, double hi,
                    int64_t allowed, double* engineS, double* threshold, bool* fits) {
  int64_t n = 0;
  DCM_RETURN_IF_ERROR(PlannedPixels(planning, o, hi, engineS, &n));
  *threshold = hi;
  *fits = n <= allowed;
  if (!*fits) return Status::Ok();
  for (int k = 0; k < kFitPlans; ++k) {
    const double mid = std::sqrt(lo * hi);
    DCM_RETURN_IF_ERROR(PlannedPixels(planning, o, mid, engineS, &n));
    (n <= allowed ? hi : lo) = mid;
  }
  *threshold = hi;
  return Status::Ok();
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
                                      const ReconstructionOptions& options, const QualityGoal& goal,
                                      const PreviewScheduleOptions& scheduleIn, Reconstruction* out,
                                      QualityReport* report, PreviewTargetStats* stats) {
  DCM_RETURN_IF_ERROR(goal.Validate());
  if (goal.targetRender)
    return Status::Error("--target-psnr render: the preview judges a target in dB, not the render's own estimate");
  const double targetPsnr = goal.targetPsnr;
  PreviewScheduleOptions schedule = scheduleIn;
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
    s.beyondRender = targetPsnr > 0 && !(targetPsnr <= s.renderPsnrAtStart - kRenderNoiseMarginDb);
    const int64_t total = int64_t(caps.width) * int64_t(caps.height);
    schedule.maxExactPixels = goal.budget > 0 ? std::max<int64_t>(1, int64_t(goal.budget * double(total))) : 0;
    schedule.stopAtPsnr = std::max(0.0, targetPsnr);  // a run's rounds end where it reaches the target
    PlanningProvider planning(exact, preview);
    ReconstructionOptions o = options;
    const double defaultThreshold = double(ResolveSettings(options, caps).contrastThreshold);
    // A budget alone is one run at the finest threshold it affords.
    const bool oneRun = s.beyondRender && !goal.searchBeyondRender;
    double threshold = targetPsnr <= 0 ? kMinThreshold : oneRun ? defaultThreshold : kStartFactor * defaultThreshold;
    int maxRuns = targetPsnr <= 0 || oneRun ? 1 : kMaxRuns;
    if (maxRuns > 1) {
      // Planned on the preview alone: a run predicted short of the margin, or
      // one that asks for no fewer pixels, ends the climb. A prediction that
      // erred high costs a run: the ladder descends from there.
      int64_t fewest = INT64_MAX;
      for (double t = 2 * threshold; t <= kMaxThreshold; t *= 2) {
        o.contrastThreshold = float(t);
        PreviewTargetStats::Prediction p{t, {}, 0};
        DCM_RETURN_IF_ERROR(
            PredictFirstRound(planning, preview, o, schedule, fewest, &p.estimate, &p.pixels, &s.timeEngineS));
        s.predictions.push_back(p);
        if (!(p.pixels < fewest && p.estimate.low >= targetPsnr + kPredictMarginDb)) break;
        fewest = p.pixels;
        threshold = t;
        ++maxRuns;  // the ladder still reaches as fine a threshold
      }
    }
    if (maxRuns > 1 && schedule.halveExactSamples && schedule.maxExactSampleHalvings > 0) {
      // Each halving adds the exact pixels' noise once more; spread by the
      // interpolation (weights of sum 1) it costs at most what the full
      // render loses at half its samples, its own noise once more.
      const double perHalving = Mse(s.renderPsnrAtStart);
      const double allowed = (1 - Mse(kPredictMarginDb)) * Mse(targetPsnr);
      const double share = ExactVarianceShare(schedule);
      int j = 0;
      while (j < schedule.maxExactSampleHalvings && share * double(2 << j) <= 1 &&
             double((2 << j) - 1) * perHalving <= allowed)
        ++j;
      if (j > 0) {
        DCM_RETURN_IF_ERROR(schedule.halveExactSamples(j));
        schedule.exactVarianceShare *= double(1 << j);
        s.exactSampleHalvings = j;
      }
    }
    Reconstruction best;
    size_t kept = 0;  ///< the run whose result is kept
    bool reached = false, budgetBound = false;
    int flat = 0;
    for (int run = 0; run < maxRuns && !reached && !budgetBound; ++run, threshold *= kStep) {
      if (schedule.maxExactPixels > 0) {
        // Planned on the preview before anything is rendered: a run that
        // would pass the budget becomes the finest one within it, and the last.
        const int64_t left = schedule.maxExactPixels - planning.KnownCount();
        const int64_t allowed = int64_t(kPlanShare * double(left));
        int64_t planned = 0;
        DCM_RETURN_IF_ERROR(PlannedPixels(planning, o, threshold, &s.timeEngineS, &planned));
        if (planned > allowed) {
          const double coarser = s.thresholds.empty() ? std::max(kMaxThreshold, threshold) : s.thresholds.back();
          bool fits = false;
          const double from = threshold;
          DCM_RETURN_IF_ERROR(
              FitThreshold(planning, o, from, coarser, allowed, &s.timeEngineS, &threshold, &fits));
          // The first run may take the whole budget where its share does not
          // hold the coarsest plan: later rounds stop at the budget, and a
          // budget a single threshold's run fits is not refused.
          if (!fits && s.thresholds.empty() && left > allowed)
            DCM_RETURN_IF_ERROR(FitThreshold(planning, o, from, coarser, left, &s.timeEngineS, &threshold, &fits));
          if (!fits && s.thresholds.empty())
            return Status::Error("--budget " + Num(goal.budget) + ": below what the coarsest reconstruction "
                                 "needs (at threshold " + Num(coarser) + " the plan on the preview asks for more "
                                 "than the " + std::to_string(left) + " pixels the budget allows)");
          budgetBound = true;
          if (!fits || (!s.thresholds.empty() && threshold >= s.thresholds.back())) break;
        }
      }
      o.contrastThreshold = float(threshold);
      PreviewScheduleStats runStats;
      Reconstruction rec;
      DCM_RETURN_IF_ERROR(PlanRenderAndFinish(planning, preview, o, schedule, s.rounds, &rec, &runStats));
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
      reached = targetPsnr > 0 && e.low >= targetPsnr;
      budgetBound |= runStats.budgetBound;
      // The run that reaches the target, else the one estimated best: with
      // noisy exact samples more of them can estimate worse than interpolation.
      if (s.estimates.size() == 1 || reached || e.psnr > s.estimates[kept].psnr) {
        kept = s.estimates.size() - 1;
        s.last = std::move(runStats);
        best = std::move(rec);
      }
      if (flat >= 2) break;
    }
    // With the exact pixels' noise measured on the rounds, where it was, and
    // through the display at the kept result's values where it was made; the
    // full render's has all of their samples.
    const double keptRender = s.last.correction.renderPsnr;
    s.renderPsnr = (std::isfinite(keptRender) ? keptRender : RenderPsnr(previewPsnr, schedule)) +
                   10 * std::log10(double(1 << s.exactSampleHalvings));
    s.renderedPixels = planning.KnownCount();
    // As ReconstructToQuality's: the cost of every run (with noisy samples a
    // pixel an earlier run rendered is interpolated again, and still paid for).
    best.stats.exactPixels = s.renderedPixels;
    best.stats.timeProviderS = s.timeExactS;
    best.stats.providerCalls = s.rounds;

    QualityReport r;
    r.estimate = s.estimates[kept];
    r.estimateSource = EstimateSource::kPreview;
    r.againstConverged = true;
    r.renderEstimate = {s.renderPsnr, NAN, NAN};
    r.targetPsnr = targetPsnr;
    r.exactPixels = s.renderedPixels;
    r.totalPixels = int64_t(caps.width) * int64_t(caps.height);
    r.threshold = s.thresholds[kept];
    r.runs = int(s.thresholds.size());
    r.targetReached = targetPsnr <= 0 || reached;
    r.budgetBound = budgetBound && !reached;
    *out = std::move(best);
    if (report) *report = std::move(r);
  } catch (const std::bad_alloc&) {
    return Status::Error("out of memory in the target search on the preview's estimate");
  }
  return Status::Ok();
}

}  // namespace dcm
