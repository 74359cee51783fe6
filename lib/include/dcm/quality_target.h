// Quality asked for instead of a threshold: a PSNR to reach (--target-psnr)
// or a share of exact pixels not to exceed (--budget), with an estimate of
// the PSNR the result has against the full render and its uncertainty. With
// noisy samples of known variance, the estimate is against the converged
// (noise-free) image, and the full render's own PSNR is estimated beside it.
//
// The estimate comes from validation pixels drawn at random (seeded: the
// first draw stratified, the later ones by importance where the result shows
// detail, with Hansen-Hurwitz weights) and evaluated exactly; they count in
// the exact pixels. The knob is
// the contrast threshold, lowered until the estimate's lower bound reaches the
// target or the next step would exceed the budget (docs/QUALITY.md).
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <span>
#include <vector>

#include "dcm/color.h"
#include "dcm/options.h"
#include "dcm/reconstructor.h"
#include "dcm/sample_provider.h"
#include "dcm/status.h"

namespace dcm {

/// Fewer effective pixels (PsnrEstimate::effective) than this carry a
/// noise-free estimate: a few pixels hold the error it sees (a highlight on a
/// thin wire, hit by a validation pixel that stands for a hundred), and the
/// normal approximation behind its interval does not hold. A plateau of the
/// search then ends the descent (no threshold removes such error), and the
/// quality line says so. Chosen on the tuning set (docs/TUNING.md, Q).
inline constexpr double kFewEffectivePixels = 4;

/// The estimate of the PSNR of an image against the full render.
struct PsnrEstimate {
  double psnr = 0;  ///< from the mean squared error at the validation pixels; +inf with none
  /// Bounds of the two-sided 90 % interval (CLT on the weighted mean of the
  /// squared errors): `low` is also the one-sided 95 % lower bound.
  double low = 0, high = 0;
  /// Kish's effective number of validation pixels, (sum w d)^2 / sum (w
  /// d)^2 over the positive errors d with weights w: near 1 where one pixel
  /// carries the estimate (+inf with no error).
  double effective = std::numeric_limits<double>::infinity();
};

/// What to deliver: a target, a budget, or both (whichever binds first).
struct QualityGoal {
  /// dB of display-referred PSNR against the full render (against the
  /// converged image when the samples carry their variance), checked against
  /// the estimate's lower bound; 0: no target.
  double targetPsnr = 0;
  /// The target is the full render's own PSNR against the converged image,
  /// as estimated at the first validation draw (at most 99 dB): a result at
  /// least as close to the converged image as the noisy full render
  /// (--target-psnr render). Needs samples that carry their variance; not
  /// with targetPsnr.
  bool targetRender = false;
  /// Largest share of working pixels evaluated exactly, validation pixels and
  /// every run's samples included; 0: no budget (1: the whole image).
  double budget = 0;
  /// With a budget, the descent starts at the options' threshold, as without
  /// one, instead of 16 times above it: for a budget that bounds a search for
  /// a target rather than one to spend (dcm reconstruct's default on noisy
  /// input: at most 35 %), which the threshold's run is expected to fit. A
  /// first run the budget refuses is followed by coarser ones, as with any.
  bool budgetFromThreshold = false;
  /// Judged by the preview (ReconstructToTargetFromPreview): a target that
  /// the render's own noise, as the preview estimates it before the first
  /// round, leaves no room for is still searched for (true), or gets one run
  /// at the options' threshold (false: a default goal, which should not spend
  /// where it can gain little). That estimate has erred 0.4-3.4 dB low on
  /// clean renders (docs/BLENDER.md), so a target the user asked for is
  /// searched for.
  bool searchBeyondRender = true;
  /// Validation output pixels: this share of the output pixels, at least
  /// minValidationPixels, at most a quarter of the budget.
  double validationFraction = 0.01;
  int64_t minValidationPixels = 512;
  /// Seed of the validation pixels (the same seed, the same pixels).
  uint64_t seed = 0x9e3779b97f4a7c15ull;
  /// The display-referred encoding of a linear output pixel in which the
  /// squared error is measured, each channel in [0,1] (PSNR peak 1). Empty:
  /// sRGB of each channel clipped to [0,1], as the stats' PSNR
  /// (tools/common/metrics.h). A host with a colour pipeline passes its own.
  std::function<RGB(RGB)> display;
  /// How one run of the search reconstructs at the options it is given, from
  /// the provider the search hands it (a cache over the caller's, which
  /// counts the pixels and enforces the budget). Empty: dcm::Reconstruct. A
  /// renderer whose rounds cost a latency plans each run on a preview
  /// instead (ReconstructToQualityWithPreview, dcm/quality_preview.h).
  std::function<Status(SampleProvider& provider, const ReconstructionOptions& options, Reconstruction* out,
                       std::vector<Point2i>* pending)>
      reconstruct;
  /// Replaces `variance`, the variance the provider reported for each of
  /// `pixels` (working pixels), by that pixel's own where the provider
  /// knows it, for a provider that reports a variance pooled over
  /// neighbours for the engine's tests: pooled over the few exact pixels
  /// near a validation pixel, which gather at edges where the relative noise
  /// is highest, it is biased there; the pixel's own is not, and the
  /// estimate averages it over the validation pixels. Empty: the provider's.
  std::function<void(std::span<const Point2i> pixels, std::span<RGB> variance)> ownVariance;
  /// A second estimate, against the converged image, of the run that
  /// `reconstruct` made last (ReconstructToQualityWithPreview: the preview
  /// correction's, from every pixel). Where the samples carry their variance
  /// (the validation's estimate is then against the converged image too) a
  /// run meets the target only where this lower bound does as well: a draw
  /// of validation pixels can miss the few pixels that carry the error, and
  /// the two judges rarely miss them together. NaN low: no opinion. Empty:
  /// the validation alone.
  std::function<PsnrEstimate()> secondEstimate;

  /// Checks the ranges ("--target-psnr: ..."); the message names the flag.
  Status Validate() const;
};

/// One refinement level of the final run (progressive output).
struct LevelEstimate {
  int level = 0;
  PsnrEstimate estimate;
};

/// Where an estimate of the result's PSNR comes from.
enum class EstimateSource : uint8_t {
  kValidation,  ///< exactly evaluated validation pixels (ReconstructToQuality)
  kPreview,     ///< the preview at every pixel (ReconstructToTargetFromPreview, dcm/preview_target.h; the
                ///< validation search's second judge where it is the lower)
};

/// What ReconstructToQuality delivered and what it cost.
struct QualityReport {
  /// Of the result: the validation's (`validationEstimate`), or where a
  /// second judge (QualityGoal::secondEstimate) has an opinion and a lower
  /// point estimate, the second judge's (`estimateSource` kPreview): the
  /// search meets a target only where both lower bounds do, and each judge
  /// misses error the other sees (docs/QUALITY.md, "Two judges"). Against
  /// the converged image where `againstConverged`, else against the full
  /// render (at the samples the provider gives).
  PsnrEstimate estimate;
  EstimateSource estimateSource = EstimateSource::kValidation;
  /// The validation pixels' estimate of the result: with a target, from a
  /// last draw that took no part in the search (`confirmed`); else from the
  /// search's.
  PsnrEstimate validationEstimate;
  /// The samples carry their variance: `estimate` is against the converged
  /// image (the noise of the exact values taken out) and `renderEstimate` is
  /// filled (docs/QUALITY.md, "Noise").
  bool againstConverged = false;
  /// The full render's own PSNR against the converged image, from the
  /// variance of the samples at every validation pixel; NaN without variance.
  PsnrEstimate renderEstimate;
  /// QualityGoal::secondEstimate of the result's run; NaN where none was asked.
  PsnrEstimate secondEstimate{std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(),
                              std::numeric_limits<double>::quiet_NaN()};
  /// The target the search aimed at: goal.targetPsnr, or with
  /// goal.targetRender the render's estimate it was set to (0: none).
  double targetPsnr = 0;
  /// The estimate comes from the last, independent draw (a target was given
  /// and the budget left room for it).
  bool confirmed = false;
  double confidence = 0.90;      ///< of [low, high]
  int64_t validationPixels = 0;  ///< output pixels compared
  /// Working pixels evaluated exactly over every run, the validation's
  /// included (each once): what the budget bounds.
  int64_t exactPixels = 0;
  int64_t validationExactPixels = 0;  ///< working pixels of the validation
  int64_t totalPixels = 0;            ///< working pixels
  double threshold = 0;               ///< contrast threshold of the result (-1: full evaluation)
  int runs = 0;                       ///< reconstructions tried
  bool targetReached = false;         ///< the lower bound of `estimate` reached the target (or no target)
  bool budgetBound = false;           ///< the budget stopped the refinement
  std::vector<LevelEstimate> levels;  ///< per refinement level of the final run, with options.onLevel
  double exactFraction() const { return totalPixels ? double(exactPixels) / double(totalPixels) : 0.0; }
};

/// Reconstructs with the contrast threshold that `goal` calls for: from the
/// options' threshold (sixteen times it, at most 1, with a budget) down, until
/// the estimate's lower bound reaches goal.targetPsnr, stops rising (a
/// plateau), or the next run would exceed the budget (then bisected between
/// the two); with a target, a last validation draw by importance estimates
/// the result, and where it finds the target missed the descent goes on (up
/// to three such draws). The
/// provider is evaluated at most once per pixel across the runs. Every other
/// option is used as given. A target that the budget (or the smallest
/// threshold, then the full evaluation) cannot reach is no error: `report`
/// says so (targetReached false) and the result is the best reached
/// (docs/QUALITY.md).
/// With a provider that answers Status::Pending, returns that status and
/// leaves the requested pixels in `pending` (a `dcm plan` round: repeat with
/// the samples rendered). The result's stats count the cost of the whole
/// search (exactPixels: every pixel evaluated, validation included; the
/// times and provider calls of every run); its byReason, blocks and sample
/// map are the final run's.
Status ReconstructToQuality(SampleProvider& provider, const ReconstructionOptions& options, const QualityGoal& goal,
                            Reconstruction* out, QualityReport* report, std::vector<Point2i>* pending = nullptr);

/// The estimate from per-pixel mean squared display errors `d` with weights
/// `w` (the share of the image each stands for): exposed for tests. A `d`
/// may be negative (an unbiased estimate of an error from which a noise
/// variance was subtracted); a mean at or below 0 gives +inf, and the lower
/// bound is then that of a mean of 0 (an error is not negative). With `total`
/// > 0, the weights are those of independent draws (1 / (draws * probability))
/// whose sum is `total` on average: the Hansen-Hurwitz mean sum(w d) / total
/// and its variance; else the weighted mean sum(w d) / sum(w) (a stratified
/// draw, whose weights sum to the pixel count exactly).
PsnrEstimate EstimatePsnr(const std::vector<double>& d, const std::vector<double>& w, double total = 0);

}  // namespace dcm
