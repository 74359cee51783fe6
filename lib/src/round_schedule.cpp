// Preview-planned rounds (RoundSchedule::kPreview): the engine chooses its exact
// pixels on stand-in samples, the provider evaluates them in one call per round.
#include "dcm/round_schedule.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <new>
#include <string>
#include <utility>

#include "dcm/downsample.h"
#include "dcm/noise_estimate.h"
#include "dcm/preview_pooling.h"
#include "elapsed.h"
#include "planning_provider.h"

namespace dcm {

namespace {

constexpr std::array<std::pair<std::string_view, RoundSchedule>, 2> kSchedules{{
    {"levels", RoundSchedule::kLevels}, {"preview", RoundSchedule::kPreview}}};

}  // namespace

std::string_view ToString(RoundSchedule s) {
  for (const auto& [name, value] : kSchedules)
    if (value == s) return name;
  return "?";
}

Status Parse(std::string_view s, RoundSchedule* out) {
  for (const auto& [name, value] : kSchedules)
    if (name == s) {
      *out = value;
      return Status::Ok();
    }
  return Status::Error("unknown round schedule '" + std::string(s) + "' (levels, preview)");
}

RoundSchedule ChooseSchedule(const RoundCost& cost, int previewRounds, double latencySamplesThreshold) {
  if (!(cost.latencyS > 0)) return RoundSchedule::kLevels;
  if (cost.previewS >= 0)
    return (kLevelScheduleRounds - previewRounds) * cost.latencyS > cost.previewS ? RoundSchedule::kPreview
                                                                                   : RoundSchedule::kLevels;
  if (!(cost.perSampleS > 0)) return RoundSchedule::kPreview;
  return cost.latencyS > latencySamplesThreshold * cost.perSampleS ? RoundSchedule::kPreview
                                                                   : RoundSchedule::kLevels;
}

double ExactVarianceShare(const PreviewScheduleOptions& schedule) {
  const double measured = schedule.measuredExactVarianceShare ? schedule.measuredExactVarianceShare() : 0.0;
  return measured > 0 && std::isfinite(measured) ? measured : schedule.exactVarianceShare;
}

Status CheckPreviewSchedule(SampleProvider& exact, SampleProvider& preview, const ReconstructionOptions& options,
                            const PreviewScheduleOptions& schedule) {
  if (schedule.maxRounds < 1)
    return Status::Error("preview schedule: maxRounds must be at least 1 (is " +
                         std::to_string(schedule.maxRounds) + ")");
  if (schedule.correctionRadius < 0)
    return Status::Error("preview schedule: correctionRadius must not be negative");
  if (schedule.filterRadius < 0) return Status::Error("preview schedule: filterRadius must not be negative");
  if (!(schedule.planSignificance >= 0) || !std::isfinite(schedule.planSignificance))
    return Status::Error("preview schedule: planSignificance must be a finite number >= 0");
  if (!(schedule.minRoundShare >= 0 && schedule.minRoundShare <= 1))
    return Status::Error("preview schedule: minRoundShare must be in [0, 1]");
  const ProviderCapabilities exactCaps = exact.Capabilities();
  const ProviderCapabilities previewCaps = preview.Capabilities();
  if (previewCaps.width != exactCaps.width || previewCaps.height != exactCaps.height)
    return Status::Error("preview schedule: the preview is " + std::to_string(previewCaps.width) +
                         "x" + std::to_string(previewCaps.height) + ", the image " +
                         std::to_string(exactCaps.width) + "x" + std::to_string(exactCaps.height));
  if (exactCaps.splitRadiance && exactCaps.texture && options.textureSplit && !previewCaps.splitRadiance)
    return Status::Error("preview schedule: the provider splits the radiance and the preview does not");

  return Status::Ok();
}

Status ReconstructWithPreview(SampleProvider& exact, SampleProvider& preview,
                              const ReconstructionOptions& options,
                              const PreviewScheduleOptions& schedule, Reconstruction* out,
                              PreviewScheduleStats* scheduleStats) {
  DCM_RETURN_IF_ERROR(CheckPreviewSchedule(exact, preview, options, schedule));
  PreviewScheduleStats stats;
  try {
    PlanningProvider planning(exact, preview);
    DCM_RETURN_IF_ERROR(PlanRenderAndFinish(planning, preview, options, schedule, 0, out, &stats));
    // Every pixel rendered was paid for, also those a final run on noisy
    // samples interpolated and denoised over (kept nowhere in the sample map).
    out->stats.exactPixels = planning.KnownCount();
  } catch (const std::bad_alloc&) {
    return Status::Error("out of memory while planning rounds on the preview");
  }
  if (scheduleStats) *scheduleStats = std::move(stats);
  return Status::Ok();
}

namespace {

/// A display error of 0.1 in each channel, squared: what a preview pixel left
/// as a stand-in is taken to miss by at worst when a goal skips its round.
constexpr double kWorstStandInError = 0.01;

/// What was not rendered is not exact: `wanted` keep their preview value, and
/// the sample map and the counts say so.
void MarkStandIns(const std::vector<Point2i>& wanted, Reconstruction* out) {
  const int W = out->workWidth;
  for (const Point2i& p : wanted) {
    SampleReason& reason = out->sampleMap[size_t(p.y) * size_t(W) + size_t(p.x)];
    if (HoldsExactSample(reason)) {
      --out->stats.byReason[size_t(reason)];
      --out->stats.exactPixels;
    }
    reason = SampleReason::kPreviewStandIn;
    ++out->stats.byReason[size_t(SampleReason::kPreviewStandIn)];
  }
}

/// The rendered pixels kept (not with noisy samples, but `keep`), the
/// interpolated ones corrected toward the preview, the rendered values filled
/// in; `excess` as CorrectTowardPreview's.
Status Finish(PlanningProvider& planning, SampleProvider& preview, const ReconstructionOptions& options,
              const PreviewScheduleOptions& schedule, Reconstruction* out, PreviewScheduleStats* stats,
              std::vector<float>* excess = nullptr, std::span<const Point2i> keep = {}) {
  // Rendered pixels keep their exact values, but not with noisy samples: the
  // final run denoised its exact samples against their neighbours, and a raw
  // one among them is noise (docs/TUNING.md). The error round's are kept:
  // their interpolation missed by far more than that noise.
  const int64_t rendered = out->stats.settings.noisy ? planning.MarkRendered(out, keep) : planning.MarkRendered(out);
  // The correction sees their interpolated values: where the interpolation
  // missed at a rendered pixel, it missed around it too.
  if (schedule.correctionRadius > 0 && preview.Capabilities().variance) {
    const auto start = std::chrono::steady_clock::now();
    GuideImage guides;
    if (schedule.filterRadius > 0) {
      // Every guide the renderer has: the filter weighs each one it is given.
      const ProviderCapabilities caps = planning.Capabilities();
      DCM_RETURN_IF_ERROR(planning.Guides({{0, 0}, {out->workWidth, out->workHeight}},
                                          GuideRequest{caps.objectId, caps.shaderId, caps.texture, caps.normal},
                                          &guides));
    }
    DCM_RETURN_IF_ERROR(CorrectTowardPreview(preview, schedule.correctionRadius, options.downsample, out,
                                             &stats->correction, schedule.previewOwnVariance,
                                             ExactVarianceShare(schedule),
                                             out->stats.settings.split ? std::span<const RGB>(
                                                                             schedule.previewTextureCovariance)
                                                                       : std::span<const RGB>(),
                                             schedule.filterRadius, guides, excess, schedule.poolPreview));
    stats->timeEngineS += detail::SecondsSince(start);
  }
  if (rendered > 0) {
    planning.FillRendered(out);
    out->image = BoxDownsample(out->workImage, out->workWidth, out->workHeight, options.downsample, &out->width,
                               &out->height);
  }
  // Last: the correction's windows compared the exact values as rendered.
  if (schedule.poolPreview) {
    const auto start = std::chrono::steady_clock::now();
    DCM_RETURN_IF_ERROR(PoolExactWithPreview(preview, ExactVarianceShare(schedule), options.downsample, out,
                                             &stats->pooledPixels));
    stats->timeEngineS += detail::SecondsSince(start);
  }
  return Status::Ok();
}

}  // namespace

Status Plan(PlanningProvider& planning, ReconstructionOptions options, Reconstruction* out, int64_t* pixels,
            double* engineS) {
  options.progress = nullptr;  // a plan is no step of the result: no progress, no progressive level
  options.onLevel = nullptr;
  const auto start = std::chrono::steady_clock::now();
  Status s = Reconstruct(planning, options, out);
  *engineS += detail::SecondsSince(start) - out->stats.timeGuidesS;
  *pixels = int64_t(planning.TakeWanted().size());
  return s;
}

Status PredictFirstRound(PlanningProvider& planning, SampleProvider& preview, const ReconstructionOptions& options,
                         const PreviewScheduleOptions& schedule, int64_t fewerThan, PsnrEstimate* estimate,
                         int64_t* pixels, double* engineS) {
  Reconstruction dry;
  DCM_RETURN_IF_ERROR(Plan(planning, options, &dry, pixels, engineS));
  PreviewScheduleStats stats;
  *estimate = stats.correction.estimate;  // NaN: not made
  if (*pixels >= fewerThan) return Status::Ok();
  // The pixels asked for keep their reasons: the estimate counts them at the
  // exact share of the preview's noise, as once rendered.
  DCM_RETURN_IF_ERROR(Finish(planning, preview, options, schedule, &dry, &stats));
  *engineS += stats.timeEngineS;
  *estimate = stats.correction.estimate;
  return Status::Ok();
}

Status PlanRenderAndFinish(PlanningProvider& planning, SampleProvider& preview, const ReconstructionOptions& options,
                           const PreviewScheduleOptions& schedule, int roundsBefore, Reconstruction* out,
                           PreviewScheduleStats* stats) {
  const ProviderCapabilities caps = planning.Capabilities();
  const double total = double(caps.width) * double(caps.height);
  const bool canStop = schedule.stopAtPsnr > 0 && schedule.correctionRadius > 0 && preview.Capabilities().variance;
  const double allowed = Mse(schedule.stopAtPsnr);  // the target's squared error
  bool finished = false;  ///< the run ended with a result already finished without its round
  ReconstructionOptions firstPlan = options;
  if (schedule.maxRounds > 1 && options.noiseSignificance > 0)
    firstPlan.noiseSignificance = std::max(options.noiseSignificance, schedule.planSignificance);
  for (int rounds = 0;;) {
    const auto engineStart = std::chrono::steady_clock::now();
    Status s = Reconstruct(planning, rounds == 0 ? firstPlan : options, out);
    stats->timeEngineS += detail::SecondsSince(engineStart) - out->stats.timeGuidesS;
    ++stats->engineRuns;
    if (!s.ok()) return s;
    std::vector<Point2i> wanted = planning.TakeWanted();
    const bool small = roundsBefore + rounds > 0 && double(wanted.size()) < schedule.minRoundShare * total;
    const int64_t left = schedule.maxExactPixels > 0 ? schedule.maxExactPixels - planning.KnownCount() : INT64_MAX;
    const bool spent = !wanted.empty() && left <= 0;
    stats->budgetBound |= spent;
    if (wanted.empty() || rounds == schedule.maxRounds || small || spent) {
      stats->previewStandIns = int64_t(wanted.size());
      MarkStandIns(wanted, out);
      break;
    }
    // The round's pixels count at the preview's noise in the estimate, as
    // their halves tell it, and the engine wants them where those halves
    // look significant, which biases it low (8x on tests/blender's scene).
    // So they are taken at kWorstStandInError each: the round is skipped
    // only where the target holds even so.
    const double worstOfRound = double(wanted.size()) / total * kWorstStandInError;
    if (canStop && roundsBefore + rounds > 0 && worstOfRound < allowed) {
      // The result without this round, finished as it would be: where its
      // estimate reaches the goal already, the round's render call buys nothing.
      Reconstruction without = *out;
      PreviewScheduleStats withoutStats = *stats;
      MarkStandIns(wanted, &without);
      DCM_RETURN_IF_ERROR(Finish(planning, preview, options, schedule, &without, &withoutStats));
      const double atLow = Mse(withoutStats.correction.estimate.low);
      if (atLow + worstOfRound <= allowed) {
        withoutStats.previewStandIns = int64_t(wanted.size());
        withoutStats.stoppedAtTarget = true;
        *out = std::move(without);
        *stats = std::move(withoutStats);
        finished = true;
        break;
      }
      stats->timeEngineS = withoutStats.timeEngineS;  // the trial's time is spent all the same
    }
    if (int64_t(wanted.size()) > left) {
      wanted.resize(size_t(left));
      stats->budgetBound = true;
    }
    const auto exactStart = std::chrono::steady_clock::now();
    s = planning.EvaluateExactly(wanted, schedule.maxExactPixels);
    stats->timeExactS += detail::SecondsSince(exactStart);
    if (!s.ok()) return s;
    ++rounds;
    ++stats->rounds;
    stats->pixelsPerRound.push_back(int64_t(wanted.size()));
  }
  // The final run's engine time excludes the rounds; the provider time is the rounds'.
  out->stats.timeProviderS = stats->timeExactS;
  out->stats.providerCalls = stats->rounds;
  if (finished) return Status::Ok();
  if (!(schedule.errorRound > 0)) return Finish(planning, preview, options, schedule, out, stats);
  // The error round: the result finished once says, per pixel, where the
  // interpolation misses by more than a rendered pixel would. Where it
  // reaches the goal already, the render call buys nothing asked for.
  const Reconstruction unfinished = *out;
  std::vector<float> excess;
  DCM_RETURN_IF_ERROR(Finish(planning, preview, options, schedule, out, stats, &excess));
  if (canStop && Mse(stats->correction.estimate.low) <= allowed) return Status::Ok();
  std::vector<size_t> worst;
  for (size_t i = 0; i < excess.size(); ++i)
    if (excess[i] > schedule.errorRound) worst.push_back(i);
  const int64_t left = schedule.maxExactPixels > 0 ? schedule.maxExactPixels - planning.KnownCount() : INT64_MAX;
  if (worst.empty() || left <= 0) return Status::Ok();
  std::sort(worst.begin(), worst.end(), [&](size_t a, size_t b) { return excess[a] > excess[b]; });
  if (int64_t(worst.size()) > left) {
    worst.resize(size_t(left));
    stats->budgetBound = true;
  }
  // A pixel rendered before and interpolated by the run (noisy samples are
  // not kept unasked) takes its sample again without a render.
  std::vector<Point2i> pick, render;
  for (size_t i : worst) {
    const Point2i p{int(i % size_t(caps.width)), int(i / size_t(caps.width))};
    pick.push_back(p);
    if (!planning.Known(p)) render.push_back(p);
  }
  const auto exactStart = std::chrono::steady_clock::now();
  const Status s = render.empty() ? Status::Ok() : planning.EvaluateExactly(render, schedule.maxExactPixels);
  stats->timeExactS += detail::SecondsSince(exactStart);
  // A quality search's budget refused the round: the result stays as finished.
  if (s.overBudget()) {
    stats->budgetBound = true;
    return Status::Ok();
  }
  DCM_RETURN_IF_ERROR(s);
  if (!render.empty()) {
    ++stats->rounds;
    stats->pixelsPerRound.push_back(int64_t(render.size()));
  }
  stats->errorRoundPixels = int64_t(pick.size());
  *out = unfinished;
  out->stats.timeProviderS = stats->timeExactS;
  out->stats.providerCalls = stats->rounds;
  return Finish(planning, preview, options, schedule, out, stats, nullptr, pick);
}

ImagePreviewProvider::ImagePreviewProvider(int workWidth, int workHeight, int previewWidth,
                                           int previewHeight, std::vector<RGB> L,
                                           std::vector<RGB> Li, std::vector<RGB> Lc,
                                           std::vector<RGB> variance)
    : workWidth_(workWidth),
      workHeight_(workHeight),
      previewWidth_(previewWidth),
      previewHeight_(previewHeight),
      L_(std::move(L)),
      Li_(std::move(Li)),
      Lc_(std::move(Lc)),
      variance_(std::move(variance)) {}

ProviderCapabilities ImagePreviewProvider::Capabilities() const {
  ProviderCapabilities caps;
  caps.width = workWidth_;
  caps.height = workHeight_;
  caps.splitRadiance = !Li_.empty() && !Lc_.empty();
  caps.variance = !variance_.empty();
  caps.name = "preview";
  return caps;
}

Status ImagePreviewProvider::Guides(const Bounds2i&, const GuideRequest&, GuideImage*) {
  return Status::Error("a preview has no guides");
}

RGB UpsampleBilinear(const std::vector<RGB>& image, int previewWidth, int previewHeight, int workWidth,
                     int workHeight, const Point2i& p) {
  const float fx = std::clamp((float(p.x) + 0.5f) * float(previewWidth) / float(workWidth) - 0.5f, 0.f,
                              float(previewWidth - 1));
  const float fy = std::clamp((float(p.y) + 0.5f) * float(previewHeight) / float(workHeight) - 0.5f, 0.f,
                              float(previewHeight - 1));
  const int x0 = int(fx), y0 = int(fy);
  const int x1 = std::min(x0 + 1, previewWidth - 1), y1 = std::min(y0 + 1, previewHeight - 1);
  const float ax = fx - float(x0), ay = fy - float(y0);
  auto at = [&](int x, int y) { return image[size_t(y) * size_t(previewWidth) + size_t(x)]; };
  return (at(x0, y0) * (1.f - ax) + at(x1, y0) * ax) * (1.f - ay) +
         (at(x0, y1) * (1.f - ax) + at(x1, y1) * ax) * ay;
}

Status ImagePreviewProvider::Evaluate(std::span<const Point2i> pixels, const SampleRequest& what,
                                      std::span<ExactSample> out) {
  const size_t n = size_t(previewWidth_) * size_t(previewHeight_);
  if (previewWidth_ < 1 || previewHeight_ < 1 || L_.size() != n ||
      (!Li_.empty() && Li_.size() != n) || (!Lc_.empty() && Lc_.size() != n) ||
      (!variance_.empty() && variance_.size() != n))
    return Status::Error("preview image of " + std::to_string(previewWidth_) + "x" +
                         std::to_string(previewHeight_) + " pixels has " +
                         std::to_string(L_.size()) + " values");
  if (what.split && (Li_.empty() || Lc_.empty()))
    return Status::Error("the preview has no split radiance (L_i, L_c)");
  for (size_t i = 0; i < pixels.size(); ++i) {
    ExactSample& s = out[i];
    s = ExactSample{};
    auto at = [&](const std::vector<RGB>& image) {
      return UpsampleBilinear(image, previewWidth_, previewHeight_, workWidth_, workHeight_, pixels[i]);
    };
    s.L = at(L_);
    if (what.split) {
      s.Li = at(Li_);
      s.Lc = at(Lc_);
    }
    // Without a variance the stand-ins count as noise-free (0).
    if (what.variance && !variance_.empty()) s.variance = at(variance_);
  }
  return Status::Ok();
}

std::unique_ptr<SampleProvider> PreviewFromSamples(std::span<const ExactSample> samples, int width, int height,
                                                   bool split, bool variance, const GuideImage& ids,
                                                   int varianceRadius, std::vector<RGB>* ownVariance) {
  std::vector<RGB> L(samples.size()), Li, Lc, var;
  if (split) {
    Li.resize(samples.size());
    Lc.resize(samples.size());
  }
  if (variance) var.resize(samples.size());
  for (size_t i = 0; i < samples.size(); ++i) {
    L[i] = samples[i].L;
    if (split) {
      Li[i] = samples[i].Li;
      Lc[i] = samples[i].Lc;
    }
    if (variance) var[i] = samples[i].variance;
  }
  if (ownVariance) *ownVariance = var;
  if (variance && varianceRadius > 0)
    var = SurfaceWindowRelativeMean(var, L, width, height, ids.objectId, ids.shaderId, varianceRadius);
  return std::make_unique<ImagePreviewProvider>(width, height, width, height, std::move(L), std::move(Li),
                                                std::move(Lc), std::move(var));
}

}  // namespace dcm
