#include "engine_flags.h"

#include <cstdio>
#include <filesystem>

#include "common/image_io.h"
#include "dcm/downsample.h"

namespace dcm::cli {

void AddEngineFlags(CLI::App* app, EngineFlags* f) {
  app->add_option("--method", f->method, "dcm (default), paper (Scheel et al. 2001) or guo (Guo 1998)")
      ->check(CLI::IsMember({"dcm", "paper", "guo"}));
  app->add_option("--threshold", f->threshold, "contrast threshold of the smooth/edge test (default 0.14, 0.15 with --downsample 2 or more and samples that are "
                  "not noisy; paper|guo: 0.06)");
  app->add_option("--block", f->block, "elementary block size (power of two; default 16, 8 with noisy samples; --method paper|guo: 8)");
  app->add_option("--min-block", f->minBlock, "finest block size (power of two, default 4)");
  app->add_option("--directions", f->directions, "candidate directions of the least-discrepancy search (default 8; 16 with --downsample 2 or more and samples "
                  "that are not noisy; paper|guo: 8)");
  app->add_flag("--no-thin", f->noThin, "switch off the thin-object test (paper 3.1)");
  app->add_option("--thin-test", f->thinTest,
                  "off | none-matches | any-differs | end-differs (default; none-matches with --downsample 2 or more and samples "
                  "that are not noisy)");
  app->add_option("--neighbour-directions", f->neighbourDirections,
                  "directions each side of its block's that an interior pixel tries, where both ends agree, before the "
                  "thin-object test makes it exact (default 8: every direction, of 8 or 16; paper|guo: 0)");
  app->add_option("--simple-surface-changes", f->simpleSurfaceChanges,
                  "a block of at most twice the finest size whose border changes only at surface changes, up to "
                  "N times, counts as simple (default 8; paper|guo: 2)");
  app->add_option("--fallback-shading-changes", f->fallbackShadingChanges,
                  "a finest block with more than 6 border changes is evaluated only when more than N of them are "
                  "no surface change (default 2: one shading edge; -1, paper: every such block)");
  app->add_flag("--no-texture-split", f->noTextureSplit, "interpolate L instead of (L_i, L_c) (paper 3.3)");
  app->add_option("--object-test", f->objectTest, "none | id | id+shader (paper 3.2) | id|shader");
  app->add_option("--contrast", f->contrast,
                  "mitchell | display | display-weighted (default mitchell; display-weighted with --downsample 2 or more and samples that "
                  "are not noisy; docs/ENGINE.md)");
  app->add_flag("--no-lazy", f->noLazy, "full border evaluation for children of simple edge blocks");
  app->add_flag("--no-fallback", f->noFallback, "never fall back to exact evaluation of a block interior");
  app->add_flag("--fallback-filled-borders", f->fallbackFilledBorders,
                "fallback blocks also evaluate the border pixels adaptive borders filled");
  app->add_flag("--no-surface-aware", f->noSurfaceAware, "interpolate across surfaces (Guo)");
  app->add_flag("--no-adaptive-borders", f->noAdaptiveBorders, "evaluate every border pixel of edge blocks (the paper)");
  app->add_option("--crossing-fill", f->crossingFill,
                  "with --downsample 2 or more and samples that are not noisy: a finest side between two lattice lines of the level above takes its "
                  "surface-change pixels from exact pixels of the same surface on both lines within N pixels, where "
                  "they agree (default 2; 0: evaluate them all)");
  app->add_flag("--no-centre-probe", f->noCentreProbe, "no centre probe of the finest edge blocks");
  app->add_flag("--no-guide-first-order", f->noGuideFirstOrder,
                "first-order test: evaluate the inner pixels at every crossing, also where the guides show the "
                "surfaces meeting");
  app->add_option("--probe-lc-share", f->probeLcShare,
                  "with the texture split: a finest edge block whose border changes only at surface changes is "
                  "probed only where L_c exceeds this share of L at some border pixel (default 0.5; 0: probe every "
                  "finest edge block)");
  app->add_flag("--no-checkerboard", f->noCheckerboard,
                "evaluate every pixel the thin-object test or a fallback wants exact, instead of one colour of a "
                "checkerboard first and the other only where its exact neighbours disagree");
  app->add_option("--smooth-refinement", f->smoothRefinement, "always (the paper) | centre-probe | never");
  app->add_flag("--full", f->full, "evaluate every pixel exactly (the baseline)");
  app->add_option("--downsample", f->downsample, "the input is supersampled N times per axis; box-filter the result down");
  app->add_option("--threads", f->threads, "worker threads (0: all cores)");
  app->add_option("--tile-size", f->tile, "pixels per side of a unit of parallel work (default 64)");
  app->add_option("--crease-angle", f->creaseAngle,
                  "with normal guides: neighbours whose normals differ by more degrees are a surface change "
                  "(default 30; 0: normals unused)");
  app->add_flag("--no-denoise-samples", f->noDenoise, "noisy samples: interpolate the raw exact samples");
  app->add_option("--noise-significance", f->noiseSignificance,
                  "with noisy samples (a variance channel or samples_per_pixel > 1): a difference counts when it "
                  "exceeds this many standard deviations (default 0.5; 0: ignore the noise, as the paper)");
  app->add_option("--progressive", f->progressive,
                  "write DIR/level_N.exr after each refinement level (an early, usable picture)");
  app->add_flag("-v,--verbose", f->verbose, "say more");
  app->add_flag("--quiet", f->quiet, "no progress on stderr");
}

std::string SettingsSummary(const ReconstructionOptions& o, const ProviderCapabilities& caps) {
  const bool rules = UsesSupersampledRules(o, caps);
  char threshold[32];
  std::snprintf(threshold, sizeof threshold, "%g", double(o.ContrastThresholdFor(rules)));
  const std::string why = rules ? "supersampled rules: --downsample " + std::to_string(o.downsample)
                          : o.downsample >= 2 ? "noisy samples: the supersampled rules are off"
                                              : "final resolution";
  const SmoothRefinement used = UsedSmoothRefinement(o, caps);
  std::string refine(ToString(used));
  if (used != o.smoothRefinement) refine += " (the guides show every hard shadow)";
  return std::string("contrast ") + std::string(ToString(o.ContrastMetricFor(rules))) + ", threshold " + threshold +
         ", " + std::to_string(o.DirectionsFor(rules)) + " directions, thin-object test " + std::string(ToString(o.ThinObjectsFor(rules))) +
         ", crossing fill " + std::to_string(o.CrossingFillReachFor(rules)) + " (" + why +
         "); smooth blocks: " + refine;
}

Status ToOptions(const EngineFlags& f, ReconstructionOptions* o) {
  if (f.method == "paper") *o = ReconstructionOptions::Paper();
  else if (f.method == "guo") *o = ReconstructionOptions::Guo();
  else *o = ReconstructionOptions{};
  if (f.threshold >= 0) o->SetContrastThreshold(f.threshold);
  if (f.block) o->elementaryBlock = f.block, o->noisyElementaryBlock = 0;  // with noisy samples too
  if (f.minBlock) o->minBlock = f.minBlock;
  if (f.directions) o->SetDirections(f.directions);
  if (f.noThin) o->SetThinObjects(ThinObjectTest::kOff);
  if (!f.thinTest.empty()) {
    ThinObjectTest t;
    DCM_RETURN_IF_ERROR(Parse(f.thinTest, &t));
    o->SetThinObjects(t);
  }
  if (f.neighbourDirections >= 0) o->neighbourDirections = f.neighbourDirections;
  if (f.fallbackShadingChanges >= -1) o->fallbackShadingChanges = f.fallbackShadingChanges;
  if (f.simpleSurfaceChanges) o->simpleSurfaceChanges = f.simpleSurfaceChanges;
  if (f.noTextureSplit) o->textureSplit = false;
  if (!f.objectTest.empty()) DCM_RETURN_IF_ERROR(Parse(f.objectTest, &o->objectTest));
  if (!f.contrast.empty()) {
    ContrastMetric m;
    DCM_RETURN_IF_ERROR(Parse(f.contrast, &m));
    o->SetContrastMetric(m);
  }
  if (f.noLazy) o->lazyEvaluation = false;
  if (f.noFallback) o->fallback = false;
  if (f.fallbackFilledBorders) o->fallbackFilledBorders = true;
  if (f.noSurfaceAware) o->surfaceAware = false;
  if (f.noAdaptiveBorders) o->adaptiveBorders = false;
  if (f.crossingFill >= 0) o->crossingFillReach = f.crossingFill;
  if (f.noCentreProbe) o->finestCentreProbe = false;
  if (f.noGuideFirstOrder) o->firstOrderFromGuides = false;
  if (f.noCheckerboard) o->checkerboard = false;
  if (!f.smoothRefinement.empty()) DCM_RETURN_IF_ERROR(Parse(f.smoothRefinement, &o->smoothRefinement));
  if (f.full) o->fullEvaluation = true;
  o->downsample = f.downsample;
  o->threads = f.threads;
  if (f.tile) o->tileSize = f.tile;
  if (f.noDenoise) o->denoiseSamples = false;
  if (f.creaseAngle >= 0) o->creaseAngle = f.creaseAngle;
  if (f.noiseSignificance >= 0) o->noiseSignificance = f.noiseSignificance;
  if (f.probeLcShare >= 0) o->probeLcShare = f.probeLcShare;
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
