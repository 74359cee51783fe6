// Every switch of the reconstruction, so that Guo's method, the paper's
// enhancements and dcm's own additions can be measured side by side.
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "dcm/color.h"
#include "dcm/status.h"

namespace dcm {

/// When two neighbouring pixels see different surfaces (paper 2.2 and 3.2).
enum class ObjectTest {
  kNone,             ///< no ID test: contrast only
  kObjectId,         ///< Guo: the object ID differs
  kObjectAndShader,  ///< Scheel 3.2: object ID AND shader ID differ
  /// the object ID OR the shader ID differs: a surface is one material of
  /// one object (two objects of one material, a chair on a table of the same
  /// wood, are two surfaces; so are two materials of one object)
  kObjectOrShader,
};

/// The per-pixel thin-object test at the finest level (paper 3.1).
enum class ThinObjectTest {
  kOff,          ///< Guo: interpolate every interior pixel
  kNoneMatches,  ///< paper as written: exact when no border sample used is on the pixel's surface
  kAnyDiffers,   ///< exact when any border sample used lies on another surface
  /// exact when one of the two border points the pixel interpolates has no
  /// sample on the pixel's surface; a point between a sample on the surface
  /// and one off it snaps to the one on it (the edge passes between them)
  kEndDiffers,
};

/// What happens to a smooth block above the finest level.
enum class SmoothRefinement {
  kAlways,       ///< paper 2.1 as written: split it and classify the children again
  /// evaluate its centre; split only where the bilinear prediction misses
  /// it. Not where the provider's guides show every hard shadow
  /// (ProviderCapabilities::hardShadowsGuided) and the samples are not
  /// noisy (UsedSmoothRefinement): there the probes found nothing the guides
  /// miss (docs/AOV.md, session 10: on the Cycles views 0.13-0.21 points
  /// fewer exact pixels at the same PSNR; on the tracer's cactus, whose
  /// point lights' shadows no guide shows, they are worth 1.2 dB).
  kCentreProbe,
  kNever,        ///< smooth blocks are final at the level where they are found
};

/// How the contrast of a set of samples is measured.
enum class ContrastMetric {
  kMitchell,  ///< (max-min)/(max+min) of luminance, as in the paper
  kDisplay,   ///< max-min of sRGB-encoded luminance clipped to [0,1] (display units)
  /// Mitchell's contrast weighted by how far a relative change at the set's
  /// mean luminance L moves the displayed value: SrgbRelativeSlope(L)
  /// relative to its value at mid-grey (0.18), so that the threshold means
  /// Mitchell's at mid-grey. The contrast of a dark set counts less (its
  /// error is small on a display), that of a bright one more. L is of the
  /// radiance L = L_i tau + L_c. Not invariant under exposure, unlike
  /// kMitchell: it serves images seen through an sRGB-like display.
  kDisplayWeighted,
};

/// Options of one reconstruction. Defaults are dcm's; Guo() and Paper() give
/// the published methods.
struct ReconstructionOptions {
  /// Size of level-0 blocks (a power of two). dcm starts at 16 (the paper at
  /// 8): smooth blocks are split by the centre probe where needed, so large
  /// flat regions cost a quarter of the lattice samples (docs/ENGINE.md).
  int elementaryBlock = 16;
  /// Size of level-0 blocks when the samples are noisy (the provider reports
  /// their variance and noiseSignificance > 0): 8. The noise discount of the
  /// tests hides more of the detail between the corners of a coarse lattice,
  /// and the denoising fits gain from the denser exact samples (docs/NOISE.md:
  /// +0.7 to +2.2 dB at 64 spp for 1.5-2 points more exact pixels). 0: the
  /// same as elementaryBlock.
  int noisyElementaryBlock = 8;
  int minBlock = 4;          ///< finest block size (a power of two <= elementaryBlock)

  /// The elementary block used with noisy samples or without (never below
  /// minBlock).
  int ElementaryBlockFor(bool noisySamples) const {
    const int b = noisySamples && noisyElementaryBlock > 0 ? noisyElementaryBlock : elementaryBlock;
    return b < minBlock ? minBlock : b;
  }
  /// The larger of the two: a lattice of it is also a lattice of the other
  /// (both powers of two), for tile alignment before the provider is known.
  int LargestElementaryBlock() const {
    return ElementaryBlockFor(false) > ElementaryBlockFor(true) ? ElementaryBlockFor(false) : ElementaryBlockFor(true);
  }
  /// Smooth/edge threshold of the contrast test at final resolution. 0.14 is
  /// the largest tested that keeps every Cycles view of docs/AOV.md at or
  /// above 40 dB (issue 3's target; 8.0-11.9 % exact there). It was 0.12
  /// until the highlight guide and the session-8 probe and fallback rules
  /// left the samples of 0.12 buying less than the points they cost.
  float contrastThreshold = 0.14f;
  /// The threshold under the supersampled rules (SupersampledRules), where
  /// the reconstruction is judged after the box filter, with
  /// contrastMetricSupersampled: 0.15 is the largest tested that keeps every
  /// Cycles view at 4x at or above 45 dB (issue 3's target there; view c at
  /// 45.45, 0.155 leaves it at 44.95) with directionsSupersampled,
  /// thinObjectsSupersampled and crossingFillReach (docs/AOV.md, session 11).
  float contrastThresholdSupersampled = 0.15f;
  /// The threshold in effect, with the supersampled rules or without.
  float ContrastThresholdFor(bool supersampledRules) const {
    return supersampledRules ? contrastThresholdSupersampled : contrastThreshold;
  }
  /// Sets the threshold of every supersampling (a command line's --threshold).
  void SetContrastThreshold(float t) { contrastThreshold = contrastThresholdSupersampled = t; }
  ContrastMetric contrastMetric = ContrastMetric::kMitchell;
  /// The metric under the supersampled rules. Display-weighted there: on the
  /// Cycles views at 4x it needs 0.15 (a) and 0.38 (c) points fewer exact
  /// pixels than Mitchell's at 45 dB, and on the tracer's scenes (2x and 4x)
  /// about a fifth fewer at equal PSNR on room, parquet and mirror, as many
  /// on the cactus. At final resolution the two are even on the Cycles views
  /// (-0.07 to -0.16 points, -0.29 to +0.58 dB), and the noise regime's
  /// targets are relative errors, which Mitchell's contrast measures.
  ContrastMetric contrastMetricSupersampled = ContrastMetric::kDisplayWeighted;
  /// The metric in effect, with the supersampled rules or without.
  ContrastMetric ContrastMetricFor(bool supersampledRules) const {
    return supersampledRules ? contrastMetricSupersampled : contrastMetric;
  }
  /// Sets the metric of every supersampling (a command line's --contrast).
  void SetContrastMetric(ContrastMetric m) { contrastMetric = contrastMetricSupersampled = m; }
  int directions = 8;        ///< candidate directions of the least-discrepancy search
  /// The directions under the supersampled rules: 16, 11.25 degrees apart.
  /// An edge there spans twice the working pixels per output pixel, so the
  /// 8 directions' 22.5-degree steps leave more of its pixels beside it
  /// whose line crosses it. With neighbourDirections covering all 16, on the
  /// Cycles views at 4x 0.02-0.08 points fewer exact pixels for -0.15 to
  /// +0.24 dB (c 5.95 % / 45.45 dB against 6.03 / 45.43), on the tracer's
  /// scenes up to 0.02 points fewer for +0.02 to +0.14 dB. At final
  /// resolution 16 costs the Cycles views 0.27-0.65 dB for 0.46-0.69 points,
  /// less than the threshold trades (docs/AOV.md, session 11).
  int directionsSupersampled = 16;
  /// The directions in effect, with the supersampled rules or without.
  int DirectionsFor(bool supersampledRules) const { return supersampledRules ? directionsSupersampled : directions; }
  /// Sets the directions of every supersampling (a command line's --directions).
  void SetDirections(int k) { directions = directionsSupersampled = k; }

  /// dcm: a surface is one material of one object. The paper's rule (a
  /// change only where object AND shader differ) joins objects of one
  /// material, so a chair on a table of the same wood interpolated the
  /// table's samples (docs/AOV.md: +0.02 to +0.98 dB on the Cycles views,
  /// +0.16 to +0.46 dB on the bundled scenes, for <= 0.09 points). IDs of
  /// primitives (one object of many parts) want kObjectAndShader.
  ObjectTest objectTest = ObjectTest::kObjectOrShader;
  ThinObjectTest thinObjects = ThinObjectTest::kEndDiffers;
  /// The thin-object test under the supersampled rules: a work pixel is
  /// 1/downsample^2 of an output pixel, so a pixel interpolated from one end
  /// on its surface errs in a fraction of an output pixel only.
  /// docs/AOV.md (session 9): on the Cycles views at 4x, 0.08-0.34 points
  /// fewer exact pixels than kEndDiffers at 45 dB; at final resolution it
  /// loses 1.0-1.7 dB at the same threshold (view b stays below 40 dB).
  ThinObjectTest thinObjectsSupersampled = ThinObjectTest::kNoneMatches;
  /// The thin-object test in effect, with the supersampled rules or without.
  ThinObjectTest ThinObjectsFor(bool supersampledRules) const {
    return supersampledRules ? thinObjectsSupersampled : thinObjects;
  }
  /// Sets the test with the supersampled rules and without (--thin-test).
  void SetThinObjects(ThinObjectTest t) { thinObjects = thinObjectsSupersampled = t; }
  /// An interior pixel that the thin-object test would make exact first
  /// tries this many neighbouring directions on each side of its block's
  /// (the nearer first, +pi/K before -pi/K) and is interpolated along the
  /// first one whose border points pass the test and whose two ends agree
  /// (no significant difference between them: the line crosses no shadow
  /// or highlight edge on the pixel's surface). The K directions are
  /// quantised: an edge between two of them leaves a pixel beside it whose
  /// line along the block's direction crosses the edge, while the next
  /// direction stays on its surface; a thin object crossing the block at
  /// another angle than the block's edge is served along its own direction.
  /// More than K/2 counts as K/2 (every direction; docs/AOV.md: on the
  /// Cycles views 0.25-0.53 points fewer exact pixels than one each side
  /// without the agreement, at -0.36 to +0.06 dB; on the POV-Ray scene
  /// -0.37 points for -1.35 dB, worse than the threshold's trade there).
  /// 0: the block's direction only. Above 0, also: a pixel that the
  /// none-matches test passes with one border point on its surface takes,
  /// of all K directions, the one whose two border points on its surface
  /// differ least, where there is one (docs/AOV.md, session 10).
  int neighbourDirections = 8;  ///< every direction of 8 and of 16
  /// An interior pixel interpolates only border samples on its own surface.
  bool surfaceAware = true;
  /// Interpolate (L_i, L_c) and re-apply tau per pixel (paper 3.3).
  bool textureSplit = true;

  /// With normal guides: neighbouring pixels whose normals differ by more
  /// than this many degrees are a surface change, as an ID change is (a
  /// crease inside one object with one material, such as a room's walls and
  /// ceiling, which no ID marks). Creases that enclose part of an object
  /// make it a surface of its own (a region), so no pixel interpolates
  /// samples from across them (docs/AOV.md: +0.5 to +2.2 dB on Cycles
  /// renders). 0: normals are not used. The angle is per output pixel: see
  /// WorkCreaseAngle.
  float creaseAngle = 30.f;

  SmoothRefinement smoothRefinement = SmoothRefinement::kCentreProbe;
  /// Edge-block borders: evaluate the pixels at surface changes and bisect
  /// every gap whose ends differ significantly; fill the rest along the border
  /// from known pixels of the same surface. Off: every border pixel exactly
  /// (the paper).
  bool adaptiveBorders = true;
  /// Adaptive borders under the supersampled rules, every level below the
  /// elementary block: a side on a lattice line the level adds (every other
  /// line of the level) takes the pixels at its surface changes from the two
  /// neighbouring lines, the parent's sides a block away on either side,
  /// where each has an exact pixel of the same surface within this many
  /// pixels along the line (inside the side's extent) and the two agree; the
  /// others are evaluated. An edge crossing three lattice lines is then
  /// sampled on the outer two and interpolated on the middle one. A finer
  /// level evaluates a filled pixel its own sides need. Below the elementary
  /// level and not only at the finest (session 11): 0.03-0.05 points fewer
  /// on the Cycles views at 4x for -0.01 dB. docs/AOV.md (session 9): at the
  /// supersampled defaults, 0.20-0.32 points fewer exact pixels for 0.08-0.17
  /// dB on the Cycles views at 4x (0.13-0.26 points fewer at 45 dB), 0.03-0.08
  /// points for <= 0.11 dB on the bundled scenes; at final resolution it is
  /// about even with the threshold's trade and costs view c the 1 dB the 1x
  /// target has no room for. 0: off.
  int crossingFillReach = 2;
  /// The crossing fill's reach in effect (0: off).
  int CrossingFillReachFor(bool supersampledRules) const { return supersampledRules ? crossingFillReach : 0; }

  bool zeroOrderTest = true;   ///< simple/complex: exactly two changes along the border
  /// A block of at most twice the finest size whose border changes only
  /// where the surfaces change, more than twice and at most this many times
  /// (two to four boundaries: a spindle across it, a corner, two edges),
  /// also counts as simple: the lazy evaluation then settles it at its level
  /// when the oriented interpolation, surface-aware, predicts its centre,
  /// and its pixels that no direction serves are thin objects. With the
  /// guides, the interpolation serves each surface from its own samples, so
  /// the zero-order test's "one edge" is not what limits it (docs/AOV.md:
  /// 0.2-0.7 points fewer exact pixels for <= 0.15 dB on the Cycles views).
  /// 2: Guo's zero-order test alone.
  int simpleSurfaceChanges = 8;
  /// An edge block with no significant change along its border (a smooth
  /// gradient that failed the corner contrast) counts as simple.
  bool gradientBlocksSimple = true;
  bool firstOrderTest = true;  ///< simple/complex: same edge direction at both crossings
  /// The first-order test reads a crossing that is a surface change from the
  /// guides (where the surfaces meet one row inside) instead of evaluating
  /// the two pixels there (docs/AOV.md: 0.5-0.6 points fewer exact pixels on
  /// the Cycles views, 0.08-0.17 on the bundled scenes).
  bool firstOrderFromGuides = true;
  bool lazyEvaluation = true;  ///< children of simple edge blocks: centre pixel only
  /// At the finest level, evaluate the interior of an edge block whose border
  /// shows more than `fallbackMaxChanges` significant changes (more than two
  /// discontinuities cross it: no single direction can serve it), or whose
  /// centre probe (finestCentreProbe) the interpolation misses.
  bool fallback = true;
  /// More significant changes than this along a finest block's border make
  /// it fall back: 6, three discontinuities. Two (a thin object across the
  /// block) interpolate well; at 4, the third one's fallbacks cost 0.04-0.7
  /// points of exact pixels for 0.01-0.5 dB (docs/AOV.md), less than the
  /// same samples buy as a lower threshold.
  int fallbackMaxChanges = 6;
  /// A finest block over fallbackMaxChanges falls back only when more than
  /// this many of its border's changes are no surface change. A surface
  /// change is served by the surface-aware interpolation (each interior
  /// pixel reads border samples of its own surface, and the thin-object
  /// test evaluates those that have none); two changes are one shading edge,
  /// which the block's direction serves. On the Cycles views (chair slats,
  /// spindles and legs in one block) 2 saves 0.3-0.7 points at 1x for
  /// 0.4-0.9 dB and 0.2 points at 4x for 0.1 dB or less (docs/AOV.md,
  /// session 8). -1: every block over fallbackMaxChanges falls back (the
  /// paper).
  int fallbackShadingChanges = 2;
  /// With adaptive borders, a fallback block also evaluates the border
  /// pixels that the bisection filled (its ends agreed). Off: the fills are
  /// trusted, as the neighbouring blocks that share the side trust them
  /// (docs/AOV.md: 1-2 points fewer exact pixels on Cycles renders, bought
  /// back as a lower threshold for +0.3 to +1.9 dB).
  bool fallbackFilledBorders = false;
  /// At the finest level, evaluate the centre of each edge block and fall back
  /// to exact evaluation where its interpolation misses it (an error estimate
  /// that refines below the finest block size).
  bool finestCentreProbe = true;
  /// With the texture split, the centre probe of a finest edge block whose
  /// border changes only at surface changes is made only where L_c exceeds
  /// this share of L = L_i tau + L_c at some pixel of the border: where
  /// glossy light dominates, a highlight or a reflection can hide inside a
  /// 4x4 block; elsewhere the surfaces (IDs, shadow and highlight guides)
  /// explain the border. A border with any other significant change is
  /// always probed. On the Cycles views with both guides, 0.5 instead of
  /// probing every such block saves 0.5-0.9 points of exact pixels for
  /// 0.15 dB or less at 1x, and 0.3-0.7 points for 0.2 dB or less at 4x
  /// (docs/AOV.md, session 8). 0: probe every finest edge block (also
  /// without the split).
  float probeLcShare = 0.5f;
  /// Checkerboard refinement: of the pixels that the thin-object test or a
  /// fallback wants exact, those with x + y odd wait until the others are
  /// evaluated, and are filled from their exact 8-neighbours on their surface
  /// when an opposite pair brackets them and none of them differs
  /// significantly from the estimate; otherwise they are evaluated too
  /// (docs/AOV.md). Off: every such pixel exactly.
  bool checkerboard = true;

  /// Noisy samples (a provider that reports variance): a difference between
  /// samples counts only when it exceeds `noiseSignificance` standard
  /// deviations of the difference, in the contrast test, the border
  /// bisection, the simple/complex tests and every probe. Monte Carlo noise
  /// then no longer reads as detail (the paper's open problem, section 5).
  /// 0: differences are taken at face value, as in the paper.
  float noiseSignificance = 0.5f;
  /// Noisy samples: before interpolation, each exact sample becomes a local
  /// linear fit through the exact samples within one elementary block of it
  /// on its surface and not significantly different (its own pixel too:
  /// the output is closer to the converged image than the raw sample).
  bool denoiseSamples = true;

  int downsample = 1;   ///< the working image is `downsample`x the output per axis
  /// Whether the supersampled rules (contrastThresholdSupersampled,
  /// contrastMetricSupersampled, directionsSupersampled, thinObjectsSupersampled, crossingFillReach) apply: supersampled input
  /// whose samples are not noisy. With noisy samples (a provider that
  /// reports variance, noiseSignificance > 0) the noise regime's settings
  /// hold at every supersampling: on the tracer's room at 2x with 16
  /// estimates per pixel the supersampled rules took 12.5 % exact pixels for
  /// 38.53 dB against a 256-spp render, the others 8.0 % for 38.47 dB
  /// (docs/NOISE.md). dcm::UsesSupersampledRules decides it for a provider.
  bool SupersampledRules(bool noisySamples) const { return downsample >= 2 && !noisySamples; }
  /// The crease angle between neighbouring work pixels: creaseAngle /
  /// downsample. A curved surface turns by 1/downsample of its turn per
  /// output pixel between neighbouring work pixels, so this keeps one
  /// threshold of curvature at every supersampling; a sharp edge (a wall
  /// meeting the ceiling) is a crease at any. docs/AOV.md (session 10): at
  /// 4x, 30 degrees per work pixel left the chair spindles' and the vase's
  /// rounded sides one region with their fronts (view c: 0.6 dB less).
  float WorkCreaseAngle() const { return downsample > 1 ? creaseAngle / float(downsample) : creaseAngle; }
  bool fullEvaluation = false;  ///< baseline: evaluate every pixel exactly

  int threads = 0;      ///< 0: all cores
  int tileSize = 64;    ///< pixels per side of a unit of parallel work (multiple of elementaryBlock)
  int batchSize = 4096; ///< pixels per Evaluate() call

  /// Progress in [0,1] with the name of the stage; called from the calling thread.
  std::function<void(float, std::string_view)> progress;
  /// Progressive output (paper 1: "meaningful early images"): after each
  /// refinement level, a usable working-resolution image built from the
  /// samples so far (blocks not settled yet are interpolated from what their
  /// level knows). Costs one extra pass over the image per level when set.
  std::function<void(int level, int width, int height, const std::vector<RGB>& workImage)> onLevel;

  /// Guo 1998 as described in section 2 of the paper: no thin-object test,
  /// object-ID test, no texture split, interpolation blind to surfaces.
  static ReconstructionOptions Guo();
  /// Scheel et al. 2001: Guo plus the three enhancements as written.
  static ReconstructionOptions Paper();

  /// Checks ranges and consistency; the message names the field.
  Status Validate() const;
};

/// Names for statistics, metadata and command lines.
std::string_view ToString(ObjectTest);
std::string_view ToString(ThinObjectTest);
std::string_view ToString(ContrastMetric);
std::string_view ToString(SmoothRefinement);
Status Parse(std::string_view, ObjectTest*);
Status Parse(std::string_view, ThinObjectTest*);
Status Parse(std::string_view, ContrastMetric*);
Status Parse(std::string_view, SmoothRefinement*);

}  // namespace dcm
