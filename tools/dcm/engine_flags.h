// The engine switches shared by `dcm render`, `dcm reconstruct` and `dcm plan`.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "dcm/options.h"
#include "dcm/quality_target.h"
#include "dcm/reconstructor.h"
#include "dcm/round_schedule.h"
#include "dcm/status.h"

namespace dcm::cli {

/// --target-psnr render: the full render's own estimated PSNR against the
/// converged image (QualityGoal::targetRender), kept in EngineFlags::targetPsnr.
inline constexpr double kTargetRender = -1;

/// Flag values as parsed; turned into ReconstructionOptions by ToOptions().
/// An empty optional: the flag was not given, the method's default applies.
struct EngineFlags {
  std::string method = "dcm";  ///< dcm | paper | guo
  std::optional<float> threshold, noiseSignificance, creaseAngle, probeLcShare;
  /// --target-psnr (kTargetRender: `render`), --budget (dcm/quality_target.h)
  std::optional<double> targetPsnr, budget;
  /// Not a flag: a default's budget that bounds the search from the default
  /// threshold on (QualityGoal::budgetFromThreshold).
  bool budgetFromThreshold = false;
  std::optional<int> block, minBlock, directions, tile;
  std::optional<int> neighbourDirections, fallbackShadingChanges, crossingFill, simpleSurfaceChanges;
  int downsample = 1;
  int threads = 0;  ///< 0: all cores
  bool noThin = false, noTextureSplit = false, noLazy = false, noFallback = false;
  bool noSurfaceAware = false, full = false;
  bool noAdaptiveBorders = false, noCentreProbe = false, noDenoise = false, fallbackFilledBorders = false;
  bool noGuideFirstOrder = false, noCheckerboard = false;
  std::string smoothRefinement;  ///< always | centre-probe | never
  std::string objectTest;      ///< none | id | id+shader
  std::string thinTest;        ///< off | none-matches | any-differs | end-differs (default)
  std::string contrast;        ///< mitchell | display
  std::string progressive;     ///< folder for an image after each refinement level
  bool verbose = false, quiet = false;

  /// Whether --target-psnr is `render`.
  bool TargetsRender() const { return targetPsnr && *targetPsnr == kTargetRender; }
};

/// Adds the engine's flags in their help groups (flag_checks.h): quality
/// (--method, --threshold, --block, --min-block, --directions, --contrast,
/// --full, ...), guides (--object-test, --crease-angle, --no-surface-aware,
/// ...), noise (--noise-significance, --no-denoise-samples), engine
/// internals (--threads, --tile-size, the expert switches), and
/// --downsample, --progressive, -v, -q. Every numeric flag is checked at parse
/// time (exit 2, the flag named).
void AddEngineFlags(CLI::App* app, EngineFlags* flags);

/// How a command whose renderer pays a latency per round asks for its exact
/// samples (`dcm pipe`, `dcm povray`, `dcm blender`).
struct RoundFlags {
  std::string schedule = "auto";  ///< auto | levels | preview
  int maxRounds = 3;              ///< calls to the renderer at most, with the preview schedule
  /// A round after the first for fewer than this share of the pixels is not
  /// made: they keep their preview value (PreviewScheduleOptions::minRoundShare).
  double minRoundShare = 0.001;
  /// Window radius of the preview correction (PreviewScheduleOptions::correctionRadius); 0: off.
  int previewCorrection = PreviewScheduleOptions{}.correctionRadius;
  /// Window radius of the preview filter (PreviewScheduleOptions::filterRadius, off there: its estimate
  /// takes a renderer's noise, of one sign in R, G and B); 3 chose on the tuning set (docs/TUNING.md).
  int previewFilter = 3;
  /// PreviewScheduleOptions::errorRound (off there); 8 chose on the tuning set (docs/TUNING.md).
  double errorRound = 8;
  /// PreviewScheduleOptions::planSignificance.
  float planSignificance = PreviewScheduleOptions{}.planSignificance;
};

/// Adds --schedule, --max-rounds, --min-round-share, --preview-correction, --preview-filter, --error-round
/// and --plan-significance (help group "Rounds").
void AddRoundFlags(CLI::App* app, RoundFlags* flags);

/// Sets the preview schedule's rounds, minRoundShare, correctionRadius,
/// filterRadius, errorRound and planSignificance as the flags say.
void ApplyRoundFlags(const RoundFlags& flags, PreviewScheduleOptions* schedule);

/// The schedule of ReconstructToQualityWithPreview's runs: each in two rounds
/// at most (its validation pixels go with its first; pixels left at their
/// preview value after one round carry errors few validation pixels see,
/// docs/QUALITY.md), and no round skipped for being small (the search
/// validates what each run asks for).
void LimitRoundsForValidation(PreviewScheduleOptions* schedule);

/// The radius a preview's or an exact pixel's variance is pooled over: the
/// elementary block of the noisy regime with `options` on `caps`.
int VariancePoolRadius(const ReconstructionOptions& options, ProviderCapabilities caps);

/// The schedule the flags select for a renderer whose rounds cost `cost`:
/// the one named, or with "auto" ChooseSchedule(cost); kPreview only where
/// `previewAvailable` (a preview asked for without one is an error naming --schedule).
Status ScheduleFor(const RoundFlags& flags, const RoundCost& cost, bool previewAvailable, RoundSchedule* out);

/// --downsample `n` on an input of `width` x `height` pixels: both must be
/// multiples of n (a partial box at the edge would average fewer samples).
/// `what` names the input ("the provider's image", "the inputs").
Status CheckDownsample(int width, int height, int n, const std::string& what);

/// The options the flags select. The message names the flag at fault.
Status ToOptions(const EngineFlags& flags, ReconstructionOptions* options);

/// The goal --target-psnr and --budget ask for; false when neither is given.
bool QualityGoalOf(const EngineFlags& flags, QualityGoal* goal);

/// Reconstructs `provider` as the flags ask: to --target-psnr / --budget
/// (dcm::ReconstructToQuality, `quality` filled) or with the threshold
/// (dcm::Reconstruct, `quality` reset).
Status ReconstructFor(SampleProvider& provider, const ReconstructionOptions& options, const EngineFlags& flags,
                      Reconstruction* out, std::optional<QualityReport>* quality,
                      std::vector<Point2i>* pending = nullptr);

/// "estimated PSNR 40.8 dB (90 % interval 40.3 to 41.4; --target-psnr 40
/// reached), 6.12 % exact pixels in 7 runs (validation 1.00 %), threshold
/// 0.061", for -v and the summaries; where two judges spoke, "; the lower of
/// two judges, the preview's estimate 42.1 dB (41.0 to 43.3)" names the other;
/// where fewer than kFewEffectivePixels carry the validation's estimate, "; carried
/// by 1.6 effective validation pixels: ..." says so.
std::string QualityLine(const QualityReport& report, const EngineFlags& flags);

/// "this result is closer, by X dB" (toolkit::CloserThanRender), "the full
/// render is closer, by X dB" (the result's point estimate below the
/// render's), or, between the two, that the result's estimate lies above the
/// render's within its uncertainty; from the result's estimate and the
/// render's finite PSNR against the converged image.
std::string WhichIsCloser(const PsnrEstimate& result, double renderPsnr);

/// The warning of a --target-psnr that was not reached, empty when it was.
std::string QualityWarning(const QualityReport& report, const EngineFlags& flags);

/// For -v: the settings that depend on the supersampling and on the
/// provider, as the engine will use them on a provider with `caps`
/// ("contrast display-weighted, threshold 0.15, 16 directions, thin-object test
/// none-matches, crossing fill 2 (supersampled rules: --downsample 2);
/// smooth blocks: never (the provider's guides show what a probe would find)").
std::string SettingsSummary(const ReconstructionOptions& options, const ProviderCapabilities& caps);

}  // namespace dcm::cli
