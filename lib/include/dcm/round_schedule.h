// Rounds that cost something: a renderer that pays a fixed latency per batch of
// exact samples (a Blender render call, a POV-Ray process) is asked for its exact
// pixels in a few large rounds chosen from a cheap preview, instead of one round
// per step of the refinement.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "dcm/preview_correction.h"
#include "dcm/reconstructor.h"
#include "dcm/sample_provider.h"
#include "dcm/status.h"

namespace dcm {

/// What exact samples cost a provider: `latencyS` per Evaluate() call (a
/// round: process start-up, scene sync, a render call over the whole frame)
/// and `perSampleS` per pixel evaluated. Zero: unknown or negligible.
/// `previewS`: what the preview costs beyond what every schedule pays (0: it
/// comes with the guides, or was handed in); negative: unknown.
struct RoundCost {
  double latencyS = 0;
  double perSampleS = 0;
  double previewS = -1;
};

/// Calls the level schedule makes, about: one per refinement step (21 for
/// `dcm blender` at 256^2, about 20 at 512^2; docs/ENGINE.md).
inline constexpr int kLevelScheduleRounds = 20;

/// How the engine asks for its exact samples.
enum class RoundSchedule : uint8_t {
  /// As the refinement goes: each step's pixels in one call per batchSize
  /// pixels (the paper's order; about 20 rounds at 512^2). Right for providers
  /// without a latency (the internal tracer, EXR AOVs, in-process callbacks).
  kLevels,
  /// Plan on a preview: the engine runs on cheap stand-in samples (a
  /// low-resolution or few-samples render) to choose its exact pixels; the
  /// provider evaluates them in one call; the engine runs again on the exact
  /// samples and asks for the pixels whose choice changed; and so on, up to
  /// `maxRounds` calls. Pixels still wanted after the last round keep their
  /// preview value (SampleReason::kPreviewStandIn, not counted as exact);
  /// pixels a round evaluated that the final run did not ask for keep their
  /// exact value (SampleReason::kRendered, counted as exact).
  kPreview,
};
std::string_view ToString(RoundSchedule);
Status Parse(std::string_view, RoundSchedule*);

/// The schedule to use for a provider of cost `cost`, kLevels without a
/// latency. Where the preview's cost is known, the cheaper in latency and
/// preview: kPreview where the kLevelScheduleRounds - `previewRounds` calls
/// it saves cost more than the preview. Else kPreview where a round costs
/// more than evaluating `latencySamplesThreshold` samples (or the per-sample
/// cost is unknown), else kLevels.
RoundSchedule ChooseSchedule(const RoundCost& cost, int previewRounds = 3, double latencySamplesThreshold = 1000);

struct PreviewScheduleOptions {
  /// Calls to the exact provider at most (>= 1).
  int maxRounds = 3;
  /// Stop early when a round after the first would evaluate fewer than this
  /// share of the working pixels; those keep their preview value. 0: only
  /// `maxRounds` stops.
  double minRoundShare = 0;
  /// With noisy samples (the engine's noise regime) and more than one round:
  /// the engine run that plans a run's first round, on samples that are
  /// mostly the preview's, counts a difference only above this many standard
  /// deviations of it (ReconstructionOptions::noiseSignificance where that is
  /// larger; the later runs keep that one). A difference the plan misses
  /// costs a pixel in the next round, which the exact samples call for; one
  /// that noise passed for costs a pixel rendered for nothing. 1 chose on the
  /// tuning set (docs/TUNING.md); 0: the engine's.
  float planSignificance = 1.f;
  /// After the last round, where the preview carries its variance: the
  /// interpolated pixels move toward it by CorrectTowardPreview() in windows
  /// of this radius (0: off). 5 chose on the tuning set (docs/TUNING.md).
  int correctionRadius = 5;
  /// With the correction: the interpolated pixels end halfway to the preview
  /// filtered over windows of this radius, weighted by the provider's guides
  /// and the corrected image (FilterPreview(); 0: off). Its
  /// estimate takes the preview's noise as a path tracer's, of one sign in
  /// R, G and B; on the analytic scenes of the tests it errs low by 0.7-2 dB
  /// (docs/BLENDER.md). `dcm blender` uses 3 (chosen on the tuning set,
  /// docs/TUNING.md).
  int filterRadius = 0;
  /// After the last round, where the correction estimates each pixel's
  /// error: one more round renders the interpolated pixels whose estimated
  /// squared error exceeds what they would carry rendered by more than this
  /// many times the preview's display variance there (the noise of that
  /// estimate), most first, within the budget; they keep their exact values
  /// (also with noisy samples, which the final run would otherwise denoise
  /// away). Not where the result's estimate reaches `stopAtPsnr` already.
  /// 0: off.
  double errorRound = 0;
  /// The preview's own variance per working pixel (row-major), from two
  /// halves of its samples and not pooled over neighbours: the correction's
  /// estimate of the result's PSNR reads it (PreviewCorrectionStats::estimate).
  /// Empty: the preview provider's variance.
  std::vector<RGB> previewOwnVariance;
  /// The exact samples' variance as a share of the preview's (the preview's
  /// samples over the exact ones'), for the estimate: an exact pixel's error
  /// against the converged image. 0: exact samples count as noise-free.
  double exactVarianceShare = 0;
  /// The preview renders on random numbers of its own, independent of the
  /// exact samples': each exact pixel of the result ends pooled with its
  /// preview at the inverse-variance weight (PoolExactWithPreview, with the
  /// share ExactVarianceShare()), and the estimate counts it at the pooled
  /// variance. Off: a preview that is the first of the exact samples (a
  /// progressive renderer on one seed) would count them twice.
  bool poolPreview = false;
  /// Where set and it returns a positive number: that share as measured on
  /// the exact pixels rendered so far (two halves of their samples against
  /// the preview's at the same pixels). It replaces exactVarianceShare, whose
  /// ratio of samples assumes the noise falls as 1 / samples (a stratified
  /// sampler's often falls faster). Read after each run's rounds.
  std::function<double()> measuredExactVarianceShare;
  /// Where the texture guide comes from the preview's own samples (Blender's
  /// DiffCol of the same renders), the covariance of the preview's estimates
  /// of tau and of L per working pixel and channel, from its two halves: an
  /// interpolated pixel L_i tau + L_c shares the preview's noise through tau,
  /// and the estimate takes that out (CorrectTowardPreview). Empty: the
  /// texture guide is independent of the preview's noise.
  std::vector<RGB> previewTextureCovariance;
  /// At most this many working pixels exact over the planner's runs, those
  /// asked for and those the provider returns besides (TakeExtraSamples)
  /// alike; a round that would pass it renders the first pixels it asks for
  /// (the engine's order, coarse levels first) and the rest keep their
  /// preview value. 0: no bound.
  int64_t maxExactPixels = 0;
  /// A goal's target in dB (> 0): before each round after the first of all,
  /// the result with the pixels that round would render left at their preview
  /// value is finished and estimated; where its lower bound reaches this with
  /// each of those pixels taken at a display error of 0.1 besides, that result
  /// is the run's and the round is not rendered (a render call buys nothing
  /// the goal needs). Needs the preview correction. 0: off.
  double stopAtPsnr = 0;
  /// Where set, a goal in dB (ReconstructToTargetFromPreview) may render the
  /// exact pixels at 1/2^j of their samples, 0 < j <= maxExactSampleHalvings,
  /// their variance 2^j times exactVarianceShare (at most the preview's):
  /// before the first round it calls this with the largest j for which a full
  /// render at 1/2^j of the samples would lose at most what a prediction's
  /// margin is worth against one with all (the target's squared error times
  /// 1 - 10^(-1/10), a fifth; the render's own noise from the preview), a
  /// bound on what interpolation spreads of the exact pixels' added noise.
  std::function<Status(int)> halveExactSamples;
  int maxExactSampleHalvings = 0;
};

/// The exact samples' variance as a share of the preview's: the measured
/// share where there is one, else `schedule.exactVarianceShare`.
double ExactVarianceShare(const PreviewScheduleOptions& schedule);

/// What a preview-planned reconstruction did.
struct PreviewScheduleStats {
  int rounds = 0;                       ///< calls to the exact provider
  std::vector<int64_t> pixelsPerRound;  ///< exact pixels evaluated in each call
  int64_t previewStandIns = 0;          ///< wanted pixels left at their preview value
  int64_t errorRoundPixels = 0;         ///< rendered by PreviewScheduleOptions::errorRound
  int64_t pooledPixels = 0;             ///< exact pixels pooled with their preview (poolPreview)
  int engineRuns = 0;                   ///< reconstructions run (one more than the rounds, at most)
  double timeEngineS = 0;               ///< in the engine runs (preview evaluation included)
  double timeExactS = 0;                ///< in the exact provider's Evaluate()
  PreviewCorrectionStats correction;    ///< the preview correction (pixels 0: not made)
  bool budgetBound = false;             ///< maxExactPixels left wanted pixels at their preview value
  bool stoppedAtTarget = false;         ///< stopAtPsnr left wanted pixels at their preview value
};

/// Reconstructs `exact`'s image, choosing the exact pixels from `preview`
/// (RoundSchedule::kPreview). `exact` gives the guides (asked once) and the
/// exact samples; `preview` gives stand-in samples for any pixel, cheaply
/// (its guides are not used). The samples the engine sees in the final run
/// are exact except the reported stand-ins; `out->stats` are that run's, but
/// for `exactPixels`: every pixel the exact provider evaluated (with noisy
/// samples also those the final run did not ask for, which it denoises over
/// and the sample map does not show). With
/// a preview that carries its variance the interpolated pixels are then
/// corrected toward it (PreviewScheduleOptions::correctionRadius).
Status ReconstructWithPreview(SampleProvider& exact, SampleProvider& preview,
                              const ReconstructionOptions& options,
                              const PreviewScheduleOptions& schedule, Reconstruction* out,
                              PreviewScheduleStats* scheduleStats = nullptr);

/// The value of `image` (previewWidth x previewHeight, row-major) at work
/// pixel `p` of a workWidth x workHeight image: bilinear between pixel
/// centres, clamped at the edges (the same resolution returns its pixels).
RGB UpsampleBilinear(const std::vector<RGB>& image, int previewWidth, int previewHeight, int workWidth,
                     int workHeight, const Point2i& p);

/// A provider of stand-in samples from a dense image at `scale` times coarser
/// resolution than the working image (1: the same), upsampled bilinearly:
/// L, and L_i/L_c when given (empty vectors: not given), and the variance of
/// the preview's L when given (a few-samples render is noisy: with it, the
/// engine's noise regime tests the preview's contrasts against its noise
/// instead of taking the noise for edges). For previews that a renderer makes
/// at low resolution or at few samples.
class ImagePreviewProvider : public SampleProvider {
 public:
  ImagePreviewProvider(int workWidth, int workHeight, int previewWidth, int previewHeight,
                       std::vector<RGB> L, std::vector<RGB> Li = {}, std::vector<RGB> Lc = {},
                       std::vector<RGB> variance = {});
  ProviderCapabilities Capabilities() const override;
  Status Guides(const Bounds2i& region, const GuideRequest& what, GuideImage* out) override;
  Status Evaluate(std::span<const Point2i> pixels, const SampleRequest& what,
                  std::span<ExactSample> out) override;

 private:
  int workWidth_, workHeight_, previewWidth_, previewHeight_;
  std::vector<RGB> L_, Li_, Lc_, variance_;
};

/// A preview of a whole width x height working image from its stand-in
/// `samples` (row-major): an ImagePreviewProvider at the same resolution with
/// L, L_i and L_c where `split`, and where `variance` the samples' variance,
/// pooled over each pixel's surface (SurfaceWindowRelativeMean over the
/// object and shader IDs of `ids`, radius `varianceRadius`; 0: not pooled):
/// one pixel's variance from two halves has a degree of freedom or two.
/// `ownVariance` (if given): each pixel's own, not pooled (empty without
/// `variance`), for PreviewScheduleOptions::previewOwnVariance.
std::unique_ptr<SampleProvider> PreviewFromSamples(std::span<const ExactSample> samples, int width, int height,
                                                   bool split, bool variance, const GuideImage& ids,
                                                   int varianceRadius, std::vector<RGB>* ownVariance = nullptr);

}  // namespace dcm
