// Every switch of the reconstruction, so that Guo's method, the paper's
// enhancements and dcm's own additions can be measured side by side.
#pragma once

#include <functional>
#include <optional>
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
  /// it. None where the provider's guides show every hard shadow and the
  /// samples are not noisy (ResolvedSettings::smoothRefinement): a probe there finds only
  /// what the guides already show (docs/TUNING.md).
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
/// the published methods. Which data chose each default, with the figures
/// and the commands: docs/TUNING.md.
struct ReconstructionOptions {
  // A std::optional field has a regime-aware default: unset, it takes dcm's
  // value for the regime (final resolution, the supersampled rules, noisy
  // samples), which ResolveSettings applies (lib/src/settings.cpp; which data
  // chose each value: docs/TUNING.md).

  /// Size of level-0 blocks, a power of two (the paper's 8). Unset: coarser
  /// without noise, where the centre probe splits smooth blocks only where
  /// needed; finer with noisy samples, whose denoising fits want denser corners.
  std::optional<int> elementaryBlock;
  int minBlock = 4;  ///< finest block size (a power of two <= the elementary block)
  /// Smooth/edge threshold of the contrast test. Unset: per regime, the
  /// largest tested that meets issue 3's target there.
  std::optional<float> contrastThreshold;
  /// How the contrast is measured. Unset: Mitchell's; display-weighted under
  /// the supersampled rules, as the error is judged on a display after the box filter.
  std::optional<ContrastMetric> contrastMetric;
  /// Candidate directions of the least-discrepancy search. Unset: the paper's
  /// 8; more under the supersampled rules, where an edge spans more working
  /// pixels per output pixel.
  std::optional<int> directions;

  /// dcm: a surface is one material of one object, as Cryptomatte's object
  /// IDs name them (docs/TUNING.md); IDs of primitives want kObjectAndShader.
  ObjectTest objectTest = ObjectTest::kObjectOrShader;
  /// The thin-object test. Unset: end-differs at final resolution, where a
  /// one-ended pixel errs in a whole output pixel; none-matches under the
  /// supersampled rules, where it errs in 1/downsample^2 of one.
  std::optional<ThinObjectTest> thinObjects;
  /// A thin-object pixel first tries this many other directions each side (over K/2:
  /// all), taking one whose ends on its surface agree (docs/ENGINE.md, docs/TUNING.md).
  int neighbourDirections = 8;  ///< every direction of 8 and of 16
  /// An interior pixel interpolates only border samples on its own surface.
  bool surfaceAware = true;
  /// Interpolate (L_i, L_c) and re-apply tau per pixel (paper 3.3).
  bool textureSplit = true;

  /// With normal guides: neighbours whose normals differ by more degrees (per output
  /// pixel: divided by downsample between work pixels) are a surface change; 0: unused.
  float creaseAngle = 30.f;

  /// What happens to a smooth block above the finest level (docs/TUNING.md).
  SmoothRefinement smoothRefinement = SmoothRefinement::kCentreProbe;
  /// Edge-block borders: evaluate surface changes and bisect gaps whose ends differ; fill
  /// the rest from the same surface (docs/TUNING.md). Off: every border pixel (the paper).
  bool adaptiveBorders = true;
  /// Under the supersampled rules only: a side's surface-change pixel takes its surface's exact
  /// pixels within this reach on the two neighbouring lattice lines where they agree (docs/TUNING.md).
  int crossingFillReach = 2;

  bool zeroOrderTest = true;   ///< simple/complex: exactly two changes along the border
  /// A block of at most twice the finest size whose border changes 3 to this many times,
  /// all at surface changes, is simple (docs/ENGINE.md, docs/TUNING.md). 2: Guo's test.
  int simpleSurfaceChanges = 8;
  /// An edge block with no significant change along its border (a smooth
  /// gradient that failed the corner contrast) counts as simple.
  bool gradientBlocksSimple = true;
  bool firstOrderTest = true;  ///< simple/complex: same edge direction at both crossings
  /// The first-order test reads a crossing at a surface change from the guides instead
  /// of evaluating the two pixels one row inside (docs/TUNING.md).
  bool firstOrderFromGuides = true;
  bool lazyEvaluation = true;  ///< children of simple edge blocks: centre pixel only
  /// At the finest level, evaluate an edge block's interior where its border shows more
  /// than fallbackMaxChanges changes or its centre probe misses.
  bool fallback = true;
  /// More significant changes than this along a finest block's border (three
  /// discontinuities) make it fall back (docs/TUNING.md).
  int fallbackMaxChanges = 6;
  /// A block over fallbackMaxChanges falls back only with more changes than this that are
  /// no surface change: two are one shading edge (docs/TUNING.md). -1: the paper's.
  int fallbackShadingChanges = 2;
  /// A fallback block also evaluates its border pixels that the bisection filled. Off:
  /// it trusts them, as its neighbours do (docs/TUNING.md).
  bool fallbackFilledBorders = false;
  /// At the finest level, probe each edge block's centre and fall back where the
  /// interpolation misses it: an error estimate below the finest size (docs/TUNING.md).
  bool finestCentreProbe = true;
  /// A finest edge block whose border changes only at surface changes is probed only where
  /// L_c exceeds this share of L on the border (docs/TUNING.md). 0: probe every one.
  float probeLcShare = 0.5f;
  /// Of the pixels wanted exact, x + y odd waits and is filled from agreeing exact
  /// 8-neighbours on its surface where it can (docs/TUNING.md). Off: every one exact.
  bool checkerboard = true;

  /// Noisy samples: a difference counts only above this many standard deviations of it,
  /// erring towards refining (docs/TUNING.md). 0: at face value, as in the paper.
  float noiseSignificance = 0.5f;
  /// Noisy samples: each exact sample becomes a local linear fit of its surface's exact
  /// samples within one elementary block, before interpolation (docs/NOISE.md).
  bool denoiseSamples = true;

  int downsample = 1;   ///< the working image is `downsample`x the output per axis
  bool fullEvaluation = false;  ///< baseline: evaluate every pixel exactly

  int threads = 0;      ///< 0: all cores
  int tileSize = 64;    ///< pixels per side of a unit of parallel work (multiple of the elementary block)
  int batchSize = 4096; ///< pixels per Evaluate() call

  /// Progress in [0,1] with the name of the stage; called from the calling thread.
  std::function<void(float, std::string_view)> progress;
  /// Progressive output (paper 1: "meaningful early images"): after each
  /// refinement level, a usable working-resolution image built from the
  /// samples so far (blocks not settled yet are interpolated from what their
  /// level knows). Costs one extra pass over the image per level when set.
  std::function<void(int level, int width, int height, const std::vector<RGB>& workImage)> onLevel;

  /// Keep Reconstruction::interpolation, the record of how every pixel got
  /// its value, to reconstruct other channels (passes) the same way
  /// (dcm/interpolation_record.h). Not a setting of the method: the image
  /// is the same bits either way; costs memory and time only when set.
  bool recordInterpolation = false;

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
