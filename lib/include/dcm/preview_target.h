// A PSNR target for renderers whose rounds cost a latency, judged by the
// preview's own estimate of the result's error (PreviewCorrectionStats::
// estimate) instead of validation pixels: the contrast threshold steps down a
// ladder from coarser than the default, each step a preview-planned run that
// renders only the pixels no earlier step rendered, until the estimate's
// lower bound reaches the target.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "dcm/quality_target.h"
#include "dcm/round_schedule.h"

namespace dcm {

/// What the steps of ReconstructToTargetFromPreview cost and estimated.
struct PreviewTargetStats {
  std::vector<double> thresholds;        ///< per run: its contrast threshold
  std::vector<PsnrEstimate> estimates;   ///< per run: the preview's estimate of its result
  int rounds = 0;                        ///< calls to the exact provider over all runs
  std::vector<int64_t> pixelsPerRound;   ///< pixels evaluated in each call
  int64_t renderedPixels = 0;            ///< distinct working pixels the exact provider evaluated
  double timeEngineS = 0;                ///< engine runs and corrections of every run
  double timeExactS = 0;                 ///< in the exact provider's Evaluate()
  PreviewScheduleStats last;             ///< the run whose result was kept (not always the last)
  /// A threshold coarser than the ladder's start, predicted before any pixel
  /// is rendered (PredictFirstRound): the preview's estimate of its first
  /// round's result, and the pixels that round asks for.
  struct Prediction {
    double threshold = 0;
    PsnrEstimate estimate;
    int64_t pixels = 0;
  };
  /// The predictions made, each an octave above the last; the ladder starts
  /// at the coarsest that passed (none: three times the options' threshold).
  std::vector<Prediction> predictions;
  /// The target lies within 0.5 dB of what every pixel rendered exactly
  /// would reach, or beyond it (the render's own noise, as estimated before
  /// the first round): without QualityGoal::searchBeyondRender one run at the
  /// options' threshold was made.
  bool beyondRender = false;
  /// The exact pixels were rendered at 1/2^this of their samples
  /// (PreviewScheduleOptions::halveExactSamples; 0: all of them).
  int exactSampleHalvings = 0;
  /// That limit: the full render's own PSNR against the converged image, as
  /// the preview estimates it with the exact share known at the end
  /// (ExactVarianceShare), through the display at the kept result's values
  /// (PreviewCorrectionStats::renderPsnr; +inf with noise-free exact samples).
  double renderPsnr = 0;
  /// The same before the first round: what decided `beyondRender`.
  double renderPsnrAtStart = 0;
};

/// Whether ReconstructToTargetFromPreview can judge a target with this
/// preview: its own noise costs less than kMinPreviewPsnrForEstimate (else
/// the estimate is not made). On false, `why` (if given) says so.
bool CanTargetFromPreview(SampleProvider& preview, const PreviewScheduleOptions& schedule,
                          std::string* why = nullptr);

/// A target must stay this far below RenderPsnrFromPreview() for raw exact
/// samples to reach it.
inline constexpr double kRenderNoiseMarginDb = 0.5;

/// The full render's own display-referred PSNR against the converged image,
/// as the preview tells it: every pixel exact, each with
/// ExactVarianceShare(schedule) of the preview's noise (+inf at share 0, NaN
/// without the preview's variance). Raw exact samples cannot beat it; the
/// engine's denoising of noisy samples (ResolvedSettings::noisy) can.
double RenderPsnrFromPreview(SampleProvider& preview, const PreviewScheduleOptions& schedule);

/// Reconstructs `exact`'s image to `goal` (its targetPsnr and budget; the
/// other fields are the validation search's, and targetRender is refused),
/// judged by the preview correction's estimate against the converged image.
///
/// A target: the coarsest threshold of a ladder whose result reaches
/// goal.targetPsnr at the estimate's lower bound (the one-sided 95 % bound).
/// The ladder starts at three times the options' threshold (unset: the
/// regime's default), or octaves coarser where the preview predicts the
/// first round's result there 1 dB above the target with fewer pixels
/// (PreviewTargetStats::predictions), and halves it per run, at most 7 runs
/// below three times the options' threshold; it stops early where the
/// estimate stops rising. Each run is ReconstructWithPreview with
/// `schedule` (which needs the preview's variance, and its own variance and
/// the exact share for the estimate), planned on the preview and on every
/// exact sample earlier runs rendered: a pixel is rendered once, and what an
/// earlier run rendered that this one interpolates keeps its exact value.
///
/// A budget: at most goal.budget of the working pixels exact
/// (PreviewScheduleOptions::maxExactPixels). Alone, one run, at the smallest
/// threshold whose plan on the preview (the engine run on the preview before
/// any pixel is rendered) asks for at most 0.9 of the budget: the rounds after
/// the first add the pixels whose choice the exact values changed. With a
/// target, the ladder's run that would pass that share is bisected the same
/// way between its threshold and the one before, and ends the ladder
/// (`report->budgetBound`). Where 0.9 of the budget does not hold even the
/// plan at threshold 16, the first run may take the whole budget; a budget
/// below that plan is an error naming --budget, before any pixel is rendered.
///
/// `report` is that of ReconstructToQuality (estimate against the converged
/// image, from the preview: `estimateSource` kPreview, no validation pixels;
/// exactPixels every pixel rendered, as the result's stats.exactPixels; its
/// byReason and sample map are the kept run's). A target not reached is no
/// error: `report->targetReached` says so, and the result kept is the run
/// with the highest estimate (with noisy exact samples, more of them can
/// estimate worse than the interpolation they replace). A
/// target the render's own noise leaves no room for (the exact samples keep
/// `schedule.exactVarianceShare` of the preview's noise: what every pixel
/// rendered would reach, less 0.5 dB; decided before any exact pixel is
/// rendered, with the share known then, PreviewTargetStats::renderPsnrAtStart)
/// sets `stats->beyondRender`. It is searched for all the same where
/// goal.searchBeyondRender (the estimate of that limit can err low by
/// decibels), else it gets one run at the options' threshold (with a budget:
/// the threshold the budget allows, if that is coarser).
Status ReconstructToTargetFromPreview(SampleProvider& exact, SampleProvider& preview,
                                      const ReconstructionOptions& options, const QualityGoal& goal,
                                      const PreviewScheduleOptions& schedule, Reconstruction* out,
                                      QualityReport* report, PreviewTargetStats* stats = nullptr);

}  // namespace dcm
