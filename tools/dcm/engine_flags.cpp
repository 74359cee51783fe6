#include "engine_flags.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "common/image_io.h"
#include "common/stats_json.h"
#include "flag_checks.h"
#include "dcm/downsample.h"

namespace dcm::cli {

namespace {

/// A default as --help shows it ("0.14", "30").
std::string G(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

/// A name that `Parse` takes into an E, else its message.
template <typename E>
CLI::Validator EngineName() {
  return Parsed("", [](const std::string& s) {
    E e{};
    return Parse(s, &e);
  });
}

/// Sets the help group of the options added while it lives.
class InGroup {
 public:
  InGroup(CLI::App* app, const char* group) : app_(app), old_(app->option_defaults()->get_group()) {
    app_->option_defaults()->group(group);
  }
  ~InGroup() { app_->option_defaults()->group(old_); }

 private:
  CLI::App* app_;
  std::string old_;
};

/// dcm's settings in one regime: at final resolution, under the supersampled
/// rules (`supersampled`) or with noisy samples (`noisy`).
ResolvedSettings DefaultsOf(const ReconstructionOptions& o, bool supersampled, bool noisy) {
  ReconstructionOptions r = o;
  r.downsample = supersampled ? 2 : 1;
  ProviderCapabilities caps;
  caps.variance = noisy;
  return ResolveSettings(r, caps);
}

}  // namespace

void AddEngineFlags(CLI::App* app, EngineFlags* f) {
  const ReconstructionOptions d, paper = ReconstructionOptions::Paper();
  // The defaults of the options whose default depends on the regime.
  const ResolvedSettings rd = DefaultsOf(d, false, false), rss = DefaultsOf(d, true, false),
                         rnoisy = DefaultsOf(d, false, true), rp = DefaultsOf(paper, false, false);
  const std::string ss = "supersampled noiseless input, --downsample 2+: ";
  {
    InGroup g(app, kGroupIo);
    app->add_option("--downsample", f->downsample,
                    "the input is supersampled N times per axis (its size a multiple of N); box-filter the result down")
        ->transform(Integer(1, 64))
        ->capture_default_str();
    app->add_option("--progressive", f->progressive,
                    "write DIR/level_N.exr after each refinement level (an early, usable picture)");
  }
  {
    InGroup g(app, kGroupQuality);
    app->add_option("--method", f->method, "dcm, paper (Scheel et al. 2001) or guo (Guo 1998)")
        ->check(CLI::IsMember({"dcm", "paper", "guo"}))
        ->capture_default_str();
    app->add_option("--threshold", f->threshold,
                    "contrast threshold of the smooth/edge test (" + ss + G(rss.contrastThreshold) +
                        "; paper|guo: " + G(rp.contrastThreshold) + ")")
        ->transform(FiniteNumber(0))
        ->default_str(G(rd.contrastThreshold));
    app->add_option("--contrast", f->contrast,
                    "mitchell | display | display-weighted (" + ss + std::string(ToString(rss.contrastMetric)) +
                        "; docs/ENGINE.md)")
        ->check(EngineName<ContrastMetric>())
        ->default_str(std::string(ToString(rd.contrastMetric)));
    app->add_option("--block", f->block,
                    "elementary block size (noisy samples: " + G(rnoisy.elementaryBlock) +
                        "; paper|guo: " + G(rp.elementaryBlock) + ")")
        ->transform(PowerOfTwo(1, 256))
        ->default_str(G(rd.elementaryBlock));
    app->add_option("--min-block", f->minBlock, "finest block size, at most --block")
        ->transform(PowerOfTwo(1, 256))
        ->default_str(G(d.minBlock));
    app->add_option("--directions", f->directions,
                    "candidate directions of the least-discrepancy search, pi/N apart (" + ss +
                        G(rss.directions) + "; paper|guo: " + G(rp.directions) + ")")
        ->transform(PowerOfTwo(4, 64))
        ->default_str(G(rd.directions));
    app->add_flag("--full", f->full, "evaluate every pixel exactly (the baseline)");
    const CLI::Validator db = FiniteNumber(0, 99, /*above=*/true);
    app->add_option("--target-psnr", f->targetPsnr,
                    "refine until the estimated display-referred PSNR against the full render (the converged image "
                    "when the samples carry their variance) reaches DB (its 95 % lower bound; the threshold is "
                    "chosen; docs/QUALITY.md); `render`: the full render's own estimated PSNR against the converged "
                    "image (noisy samples with their variance)")
        ->transform(CLI::Validator(
            [db](std::string& s) {
              if (s != "render") return db(s);
              s = std::to_string(kTargetRender);
              return std::string();
            },
            "DB in (0, 99] or render"));
    app->add_option("--budget", f->budget,
                    "evaluate at most this share of the pixels exactly, validation included (with --target-psnr: "
                    "whichever binds first)")
        ->transform(FiniteNumber(0, 1, /*above=*/true));
  }
  {
    InGroup g(app, kGroupGuides);
    app->add_option("--object-test", f->objectTest, "none | id | id+shader (paper 3.2) | id|shader")
        ->check(EngineName<ObjectTest>())
        ->default_str(std::string(ToString(d.objectTest)));
    app->add_option("--crease-angle", f->creaseAngle,
                    "with normal guides: neighbours whose normals differ by more degrees are a surface change "
                    "(0: normals unused; paper|guo: " + G(paper.creaseAngle) + ")")
        ->transform(FiniteNumber(0, 180))
        ->default_str(G(d.creaseAngle));
    app->add_flag("--no-surface-aware", f->noSurfaceAware, "interpolate across surfaces (Guo)");
    app->add_flag("--no-texture-split", f->noTextureSplit, "interpolate L instead of (L_i, L_c) (paper 3.3)");
    app->add_flag("--no-thin", f->noThin, "switch off the thin-object test (paper 3.1)");
    app->add_option("--thin-test", f->thinTest,
                    "off | none-matches | any-differs | end-differs (" + ss +
                        std::string(ToString(rss.thinObjects)) + ")")
        ->check(EngineName<ThinObjectTest>())
        ->default_str(std::string(ToString(rd.thinObjects)));
    app->add_flag("--no-guide-first-order", f->noGuideFirstOrder,
                  "first-order test: evaluate the inner pixels at every crossing, also where the guides show the "
                  "surfaces meeting");
  }
  {
    InGroup g(app, kGroupNoise);
    app->add_option("--noise-significance", f->noiseSignificance,
                    "with noisy samples (a variance channel or samples_per_pixel > 1): a difference counts when it "
                    "exceeds this many standard deviations (0: ignore the noise, as the paper)")
        ->transform(FiniteNumber(0))
        ->default_str(G(d.noiseSignificance));
    app->add_flag("--no-denoise-samples", f->noDenoise, "noisy samples: interpolate the raw exact samples");
  }
  {
    InGroup g(app, kGroupInternals);
    app->add_option("--threads", f->threads, "worker threads (0: all cores)")
        ->transform(Integer(0, kMaxThreads))
        ->capture_default_str();
    app->add_option("--tile-size", f->tile,
                    "pixels per side of a unit of parallel work (whole elementary blocks: rounded down, at least one)")
        ->transform(Integer(1, 65536))
        ->default_str(G(d.tileSize));
    app->add_option("--neighbour-directions", f->neighbourDirections,
                    "directions each side of its block's that an interior pixel tries, where both ends agree, before "
                    "the thin-object test makes it exact (N/2 or more: every direction; paper|guo: " +
                        G(paper.neighbourDirections) + ")")
        ->transform(Integer(0, 32))
        ->default_str(G(d.neighbourDirections));
    app->add_option("--simple-surface-changes", f->simpleSurfaceChanges,
                    "a block of at most twice the finest size whose border changes only at surface changes, up to "
                    "N times, counts as simple (paper|guo: " + G(paper.simpleSurfaceChanges) + ")")
        ->transform(Integer(2, 64))
        ->default_str(G(d.simpleSurfaceChanges));
    app->add_option("--fallback-shading-changes", f->fallbackShadingChanges,
                    "a finest block with more than " + G(d.fallbackMaxChanges) +
                        " border changes is evaluated only when more than N of them are no surface change "
                        "(-1, paper: every such block)")
        ->transform(Integer(-1, 1024))
        ->default_str(G(d.fallbackShadingChanges));
    app->add_option("--crossing-fill", f->crossingFill,
                    "supersampled noiseless input: a finest side between two lattice lines of the level above takes "
                    "its surface-change pixels from exact pixels of the same surface on both lines within N pixels, "
                    "where they agree (0: evaluate them all)")
        ->transform(Integer(0, 256))
        ->default_str(G(d.crossingFillReach));
    app->add_option("--probe-lc-share", f->probeLcShare,
                    "with the texture split: a finest edge block whose border changes only at surface changes is "
                    "probed only where L_c exceeds this share of L at some border pixel (0: probe every finest edge "
                    "block)")
        ->transform(FiniteNumber(0, 1))
        ->default_str(G(d.probeLcShare));
    app->add_option("--smooth-refinement", f->smoothRefinement, "always (the paper) | centre-probe | never")
        ->check(EngineName<SmoothRefinement>())
        ->default_str(std::string(ToString(d.smoothRefinement)));
    app->add_flag("--no-lazy", f->noLazy, "full border evaluation for children of simple edge blocks");
    app->add_flag("--no-fallback", f->noFallback, "never fall back to exact evaluation of a block interior");
    app->add_flag("--fallback-filled-borders", f->fallbackFilledBorders,
                  "fallback blocks also evaluate the border pixels adaptive borders filled");
    app->add_flag("--no-adaptive-borders", f->noAdaptiveBorders, "evaluate every border pixel of edge blocks (the paper)");
    app->add_flag("--no-centre-probe", f->noCentreProbe, "no centre probe of the finest edge blocks");
    app->add_flag("--no-checkerboard", f->noCheckerboard,
                  "evaluate every pixel the thin-object test or a fallback wants exact, instead of one colour of a "
                  "checkerboard first and the other only where its exact neighbours disagree");
  }
  app->add_flag("-v,--verbose", f->verbose, "say more");
  app->add_flag("-q,--quiet", f->quiet, "no progress on stderr, no summary on stdout (warnings and errors stay)");
}

void AddRoundFlags(CLI::App* app, RoundFlags* f) {
  InGroup g(app, kGroupRounds);
  app->add_option("--schedule", f->schedule,
                  "how the renderer is asked for exact pixels: levels (as the refinement goes, a call per step), "
                  "preview (chosen on a cheap preview, then a few large calls), auto (preview where a call costs "
                  "more than about 1000 samples; docs/ENGINE.md)")
      ->check(CLI::IsMember({"auto", "levels", "preview"}))
      ->capture_default_str();
  app->add_option("--max-rounds", f->maxRounds,
                  "with the preview schedule: calls to the renderer at most; pixels still wanted after them keep "
                  "their preview value (counted in the stats). With --target-psnr or --budget: per run of the "
                  "search, at most 2)")
      ->transform(Integer(1, 1000))
      ->capture_default_str();
  app->add_option("--min-round-share", f->minRoundShare,
                  "with the preview schedule and no --target-psnr or --budget: a round after the first that would "
                  "render fewer than this share of the pixels is not made; they keep their preview value (a "
                  "render call costs its latency however few pixels it has)")
      ->check(FiniteNumber(0.0, 1.0))
      ->capture_default_str();
  app->add_option("--preview-correction", f->previewCorrection,
                  "with the preview schedule and a preview that carries its variance: interpolated pixels move "
                  "toward the preview by the share of their difference, in a window of this radius, that its "
                  "noise does not explain (lib/include/dcm/preview_correction.h); 0: off")
      ->transform(Integer(0, 64))
      ->capture_default_str();
  app->add_option("--preview-filter", f->previewFilter,
                  "with the preview correction: interpolated pixels end halfway to the preview averaged over the "
                  "neighbours, in a window of this radius, that the guides and the corrected image say show the "
                  "same surface (lib/include/dcm/preview_filter.h); 0: off")
      ->transform(Integer(0, 16))
      ->capture_default_str();
  app->add_option("--error-round", f->errorRound,
                  "with the preview correction: one more round renders the interpolated pixels whose estimated "
                  "error exceeds what they would carry rendered by more than Z times the preview's display "
                  "variance there, most first (lib/include/dcm/round_schedule.h); 0: off")
      ->check(FiniteNumber(0.0, 1e6))
      ->capture_default_str();
  app->add_option("--plan-significance", f->planSignificance,
                  "with noisy samples and the preview schedule: the plan of a run's first round counts a "
                  "difference only above K standard deviations (--noise-significance where that is larger; the "
                  "later rounds keep that); 0: --noise-significance")
      ->check(FiniteNumber(0.0, 1e3))
      ->capture_default_str();
}

void ApplyRoundFlags(const RoundFlags& f, PreviewScheduleOptions* so) {
  so->maxRounds = f.maxRounds;
  so->minRoundShare = f.minRoundShare;
  so->correctionRadius = f.previewCorrection;
  so->filterRadius = f.previewFilter;
  so->errorRound = f.errorRound;
  so->planSignificance = f.planSignificance;
}

void LimitRoundsForValidation(PreviewScheduleOptions* so) {
  so->maxRounds = std::min(so->maxRounds, 2);
  so->minRoundShare = 0;
}

int VariancePoolRadius(const ReconstructionOptions& options, ProviderCapabilities caps) {
  caps.variance = true;
  return ResolveSettings(options, caps).elementaryBlock;
}

Status ScheduleFor(const RoundFlags& flags, const RoundCost& cost, bool previewAvailable, RoundSchedule* out) {
  if (flags.schedule == "auto") {
    *out = previewAvailable ? ChooseSchedule(cost, flags.maxRounds) : RoundSchedule::kLevels;
    return Status::Ok();
  }
  DCM_RETURN_IF_ERROR(Parse(flags.schedule, out));
  if (*out == RoundSchedule::kPreview && !previewAvailable)
    return Status::Error("--schedule preview: the renderer gives no preview");
  return Status::Ok();
}

Status CheckDownsample(int width, int height, int n, const std::string& what) {
  if (n > 1 && (width % n != 0 || height % n != 0))
    return Status::Error("--downsample " + std::to_string(n) + ": " + what + " " + std::to_string(width) + "x" +
                         std::to_string(height) + " is not a multiple of " + std::to_string(n) + " pixels per axis");
  return Status::Ok();
}

std::string SettingsSummary(const ReconstructionOptions& o, const ProviderCapabilities& caps) {
  const ResolvedSettings s = ResolveSettings(o, caps);
  char threshold[32];
  std::snprintf(threshold, sizeof threshold, "%g", double(s.contrastThreshold));
  const std::string why = s.supersampledRules ? "supersampled rules: --downsample " + std::to_string(o.downsample)
                          : o.downsample >= 2 ? "noisy samples: the supersampled rules are off"
                                              : "final resolution";
  std::string refine(ToString(s.smoothRefinement));
  if (s.smoothRefinement != o.smoothRefinement) refine += " (the provider's guides show what a probe would find)";
  return std::string("contrast ") + std::string(ToString(s.contrastMetric)) + ", threshold " + threshold + ", " +
         std::to_string(s.directions) + " directions, thin-object test " + std::string(ToString(s.thinObjects)) +
         ", crossing fill " + std::to_string(s.crossingFillReach) + " (" + why + "); smooth blocks: " + refine;
}

bool QualityGoalOf(const EngineFlags& f, QualityGoal* goal) {
  *goal = QualityGoal{};
  if (f.TargetsRender()) goal->targetRender = true;
  else if (f.targetPsnr) goal->targetPsnr = *f.targetPsnr;
  if (f.budget) goal->budget = *f.budget;
  goal->budgetFromThreshold = f.budgetFromThreshold;
  return f.targetPsnr || f.budget;
}

Status ReconstructFor(SampleProvider& provider, const ReconstructionOptions& options, const EngineFlags& flags,
                      Reconstruction* out, std::optional<QualityReport>* quality, std::vector<Point2i>* pending) {
  quality->reset();
  QualityGoal goal;
  if (!QualityGoalOf(flags, &goal)) return Reconstruct(provider, options, out, pending);
  QualityReport report;
  DCM_RETURN_IF_ERROR(ReconstructToQuality(provider, options, goal, out, &report, pending));
  *quality = std::move(report);
  return Status::Ok();
}

namespace {

/// The target as the messages name it: "40", or "render (38.2 dB)".
std::string TargetName(const QualityReport& r, const EngineFlags& f) {
  if (*f.targetPsnr != kTargetRender) return G(*f.targetPsnr);
  char buf[64];
  std::snprintf(buf, sizeof buf, "render (%.2f dB)", r.targetPsnr);
  return buf;
}

}  // namespace

std::string QualityLine(const QualityReport& r, const EngineFlags& f) {
  char buf[512];
  const PsnrEstimate& e = r.estimate;
  std::string target;
  if (f.targetPsnr) target = "; --target-psnr " + TargetName(r, f) + (r.targetReached ? " reached" : " NOT reached");
  if (r.budgetBound) target += "; --budget " + G(*f.budget) + " bound";
  const bool fromPreview = r.estimateSource == EstimateSource::kPreview;
  char from[64];
  if (fromPreview && r.validationExactPixels == 0) std::snprintf(from, sizeof from, "from the preview");
  else
    std::snprintf(from, sizeof from, "%svalidation %.2f %%", fromPreview ? "from the preview; " : "",
                  r.totalPixels ? 100.0 * double(r.validationExactPixels) / double(r.totalPixels) : 0.0);
  std::snprintf(buf, sizeof buf,
                "estimated PSNR %.2f dB (%.0f %% interval %.2f to %.2f%s), %.2f %% exact pixels in %d runs "
                "(%s), threshold %s",
                e.psnr, 100 * r.confidence, e.low, e.high, target.c_str(), 100 * r.exactFraction(), r.runs, from,
                r.threshold < 0 ? "none (full evaluation)" : G(r.threshold).c_str());
  std::string line = buf;
  if (!fromPreview && e.effective < kFewEffectivePixels) {
    char few[160];
    std::snprintf(few, sizeof few, "; carried by %.1f effective validation pixels: a few pixels hold the error it sees",
                  e.effective);
    line += few;
  }
  if (std::isfinite(r.secondEstimate.psnr)) {
    // Two judges: the line names the one not reported.
    const PsnrEstimate& other = fromPreview ? r.validationEstimate : r.secondEstimate;
    char second[160];
    std::snprintf(second, sizeof second, "; the lower of two judges, the %s's estimate %.2f dB (%.2f to %.2f)",
                  fromPreview ? "validation" : "preview", other.psnr, other.low, other.high);
    line += second;
  }
  if (!r.againstConverged) return line;
  const PsnrEstimate& n = r.renderEstimate;
  // +inf: noise-free exact samples, the full render is the converged image.
  if (std::isinf(n.psnr)) return line + "; against the converged image (the exact samples carry no noise)";
  char noise[160];
  std::snprintf(noise, sizeof noise, "; against the converged image, the full render's own estimated PSNR %.2f dB",
                n.psnr);
  line += noise;
  if (std::isfinite(n.low) && std::isfinite(n.high)) {
    std::snprintf(noise, sizeof noise, " (%.2f to %.2f)", n.low, n.high);
    line += noise;
  }
  // Issue 26's question: which is closer to the converged image.
  if (toolkit::CloserThanRender(r)) line += ": " + WhichIsCloser(e, n.psnr);
  return line;
}

std::string WhichIsCloser(const PsnrEstimate& result, double renderPsnr) {
  char buf[160];
  if (toolkit::CloserThanRender(result, renderPsnr).value_or(false)) {
    if (std::isinf(result.psnr)) return "this result is closer (its validation pixels show no error beyond the noise)";
    std::snprintf(buf, sizeof buf, "this result is closer, by %.2f dB", result.psnr - renderPsnr);
  } else if (result.psnr < renderPsnr) {
    std::snprintf(buf, sizeof buf, "the full render is closer, by %.2f dB", renderPsnr - result.psnr);
  } else if (std::isinf(result.psnr)) {
    return "this result's validation pixels show no error beyond the noise, but its interval reaches below the full "
           "render's estimate: not shown to be closer";
  } else {
    // A claim needs the interval: a point estimate a little above can be a few lucky validation pixels.
    std::snprintf(buf, sizeof buf,
                  "this result's estimate lies %.2f dB above the full render's, but its interval reaches below it: "
                  "not shown to be closer",
                  result.psnr - renderPsnr);
  }
  return buf;
}

std::string QualityWarning(const QualityReport& r, const EngineFlags& f) {
  if (r.targetReached || !f.targetPsnr) return "";
  std::string within = r.budgetBound && f.budget ? " within --budget " + G(*f.budget) : "";
  if (!within.empty() && f.budgetFromThreshold) within += " (the default's bound; --target-psnr render alone spends more)";
  char buf[256];
  std::snprintf(buf, sizeof buf, "--target-psnr %s: not reached%s; estimated %.2f dB (lower bound %.2f) at %.2f %% exact pixels",
                TargetName(r, f).c_str(), within.c_str(), r.estimate.psnr, r.estimate.low, 100 * r.exactFraction());
  return buf;
}

Status ToOptions(const EngineFlags& f, ReconstructionOptions* o) {
  if ((f.targetPsnr || f.budget) && (f.threshold || f.full)) {
    const std::string goal = f.targetPsnr ? "--target-psnr" : "--budget";
    return Status::Error(goal + ": not with " + (f.full ? "--full" : "--threshold") +
                         " (the target or the budget chooses the threshold)");
  }
  if (f.method == "paper") *o = ReconstructionOptions::Paper();
  else if (f.method == "guo") *o = ReconstructionOptions::Guo();
  else *o = ReconstructionOptions{};
  // The flags set every regime's value: one flag, one meaning.
  if (f.threshold) o->contrastThreshold = *f.threshold;
  if (f.block) o->elementaryBlock = *f.block;
  if (f.minBlock) o->minBlock = *f.minBlock;
  // Both powers of two (checked at parse time); the finest block must fit.
  if (o->minBlock > LargestElementaryBlock(*o)) {
    const std::string block = std::to_string(LargestElementaryBlock(*o)), minBlock = std::to_string(o->minBlock);
    if (!f.minBlock)
      return Status::Error("--block " + block + ": below the finest block size " + minBlock +
                           "; give --min-block " + block + " or less too");
    if (!f.block)
      return Status::Error("--min-block " + minBlock + ": above the elementary block size " + block +
                           "; give --block " + minBlock + " or more too");
    return Status::Error("--min-block " + minBlock + " exceeds --block " + block);
  }
  if (f.directions) o->directions = *f.directions;
  if (f.noThin) o->thinObjects = ThinObjectTest::kOff;
  if (!f.thinTest.empty()) {
    ThinObjectTest t;
    DCM_RETURN_IF_ERROR(Parse(f.thinTest, &t));
    o->thinObjects = t;
  }
  if (f.neighbourDirections) o->neighbourDirections = *f.neighbourDirections;
  if (f.fallbackShadingChanges) o->fallbackShadingChanges = *f.fallbackShadingChanges;
  if (f.simpleSurfaceChanges) o->simpleSurfaceChanges = *f.simpleSurfaceChanges;
  if (f.noTextureSplit) o->textureSplit = false;
  if (!f.objectTest.empty()) DCM_RETURN_IF_ERROR(Parse(f.objectTest, &o->objectTest));
  if (!f.contrast.empty()) {
    ContrastMetric m;
    DCM_RETURN_IF_ERROR(Parse(f.contrast, &m));
    o->contrastMetric = m;
  }
  if (f.noLazy) o->lazyEvaluation = false;
  if (f.noFallback) o->fallback = false;
  if (f.fallbackFilledBorders) o->fallbackFilledBorders = true;
  if (f.noSurfaceAware) o->surfaceAware = false;
  if (f.noAdaptiveBorders) o->adaptiveBorders = false;
  if (f.crossingFill) o->crossingFillReach = *f.crossingFill;
  if (f.noCentreProbe) o->finestCentreProbe = false;
  if (f.noGuideFirstOrder) o->firstOrderFromGuides = false;
  if (f.noCheckerboard) o->checkerboard = false;
  if (!f.smoothRefinement.empty()) DCM_RETURN_IF_ERROR(Parse(f.smoothRefinement, &o->smoothRefinement));
  if (f.full) o->fullEvaluation = true;
  o->downsample = f.downsample;
  o->threads = f.threads;
  if (f.tile) o->tileSize = *f.tile;
  if (f.noDenoise) o->denoiseSamples = false;
  if (f.creaseAngle) o->creaseAngle = *f.creaseAngle;
  if (f.noiseSignificance) o->noiseSignificance = *f.noiseSignificance;
  if (f.probeLcShare) o->probeLcShare = *f.probeLcShare;
  if (!f.progressive.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(f.progressive, ec);
    if (ec) return Status::Error("--progressive: cannot create folder '" + f.progressive + "': " + ec.message());
    const std::string dir = f.progressive;
    const int s = o->downsample;
    const bool quiet = f.quiet;
    o->onLevel = [dir, s, quiet](int level, int w, int h, const std::vector<RGB>& work) {
      int ow = w, oh = h;
      const std::vector<RGB> image = dcm::BoxDownsample(work, w, h, s, &ow, &oh);
      const std::string path = dir + "/level_" + std::to_string(level) + ".exr";
      toolkit::Metadata meta;
      meta.floats.push_back({"dcm:level", float(level)});
      const Status st = toolkit::WriteRgbExr(path, ow, oh, image, meta);
      if (!st.ok()) std::fprintf(stderr, "dcm: warning: progressive image: %s\n", st.message().c_str());
      else if (!quiet) std::fprintf(stderr, "dcm: wrote %s\n", path.c_str());
    };
  }
  return o->Validate();
}

}  // namespace dcm::cli
