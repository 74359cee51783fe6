// The DCM reconstruction: the one entry point of the engine.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string_view>
#include <utility>
#include <vector>

#include "dcm/color.h"
#include "dcm/interpolation_record.h"
#include "dcm/options.h"
#include "dcm/sample_provider.h"
#include "dcm/status.h"

namespace dcm {

/// Why a pixel of the working image was evaluated exactly.
enum class SampleReason : uint8_t {
  kInterpolated = 0,  ///< not exact
  kCorner,            ///< corner of a block (lattice point)
  kBorder,            ///< border of an edge block
  kFirstOrderProbe,   ///< next to a border crossing, for the first-order test
  kLazyCentre,        ///< centre of a simple edge block (lazy evaluation)
  kCentreProbe,       ///< centre of a finest edge block, checking its interpolation
  kThinObject,        ///< interior pixel on another surface than its interpolants (3.1)
  kFallback,          ///< interior of a block no direction explains
  kFull,              ///< full evaluation (baseline)
  /// wanted exact, left at a preview's stand-in value after the last round
  /// (RoundSchedule::kPreview); not counted as exact
  kPreviewStandIn,
  /// evaluated in a round planned on the preview (RoundSchedule::kPreview)
  /// or by a run of a quality search (dcm/quality_target.h) that the final
  /// run did not ask for: keeps its exact value
  kRendered,
  /// a validation pixel of a quality target or budget (dcm/quality_target.h)
  /// the final run interpolated: keeps the exact value it was evaluated for
  kValidation,
  kCount
};
inline constexpr int kSampleReasonCount = int(SampleReason::kCount);
std::string_view ToString(SampleReason);

/// Whether a pixel of this reason holds an exact sample in the result: any
/// reason but kInterpolated and kPreviewStandIn (a wanted pixel left at its
/// preview value).
inline bool HoldsExactSample(SampleReason r) {
  return r != SampleReason::kInterpolated && r != SampleReason::kPreviewStandIn;
}

/// How a block was finally reconstructed.
enum class BlockType : uint8_t {
  kSmooth,       ///< bilinear from the four corners
  kSimpleEdge,   ///< finest level, oriented elements, at most two border changes
  kComplexEdge,  ///< finest level, oriented elements, more changes
  kLazy,         ///< simple edge block: parent's direction, corrected by its exact centre
  kFallback,     ///< interior evaluated exactly
};
std::string_view ToString(BlockType);

/// One leaf block of the final structure (corners inclusive).
struct BlockRecord {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  uint8_t level = 0;
  BlockType type = BlockType::kSmooth;
  int8_t direction = -1;  ///< index of the least-discrepancy direction, -1 for none
};

/// The engine's time per stage of one reconstruction: wall seconds, the
/// provider's time (Evaluate, Guides) excluded; they add up to about
/// ReconstructionStats::timeEngineS.
struct StageTimes {
  double surfaces = 0;       ///< the guides turned into the surface test (creases, regions)
  double refinement = 0;     ///< corners, smooth/edge classification, smooth refinement (paper 2.1, 2.2)
  double borders = 0;        ///< edge-block borders, adaptive or in full
  double directions = 0;     ///< least-discrepancy directions and border changes (2.1)
  double simpleComplex = 0;  ///< simple/complex classification (2.3)
  double lazy = 0;           ///< lazy boundary evaluation (2.1)
  double finest = 0;         ///< finest fallback and centre probes
  double interpolation = 0;  ///< fallback interiors, thin objects (3.1), checkerboard, final interpolation
  double denoising = 0;      ///< fits of noisy samples
  double output = 0;         ///< downsampling and the record of leaves

  /// Each stage's snake_case name (the stats' stage_times_s keys) and time,
  /// in the order the engine runs them.
  std::array<std::pair<std::string_view, double>, 10> Named() const {
    return {{{"surfaces", surfaces},
             {"refinement", refinement},
             {"borders", borders},
             {"directions", directions},
             {"simple_complex", simpleComplex},
             {"lazy", lazy},
             {"finest", finest},
             {"interpolation", interpolation},
             {"denoising", denoising},
             {"output", output}}};
  }
};

/// The values the stages of one reconstruction use, resolved once from the
/// options and the provider's capabilities (ResolveSettings): the rules that
/// pick a regime (noisy samples, supersampled rules, texture split, guides)
/// and dcm's default of each option the user left unset for it.
struct ResolvedSettings {
  /// Samples carry their variance and the tests weigh it: a provider that
  /// reports variance, noiseSignificance > 0.
  bool noisy = false;
  /// Interpolate (L_i, L_c) and re-apply tau (paper 3.3): asked for, the
  /// provider gives tau and the split radiance, and not the full baseline.
  bool split = false;
  /// The level-0 block: the option's, or the regime's default (finer with
  /// noisy samples); never below minBlock.
  int elementaryBlock = 16;
  /// The supersampled rules apply: downsample >= 2 and samples that are not
  /// noisy (with noise, the noise regime's hold at any supersampling).
  bool supersampledRules = false;
  ContrastMetric contrastMetric = ContrastMetric::kMitchell;  ///< the option's, or the regime's default
  float contrastThreshold = 0.f;                               ///< the option's, or the regime's default
  /// The contrast test's significance: noiseSignificance with noisy
  /// samples, 0 (the paper's test) without.
  float contrastSignificance = 0.f;
  int directions = 8;                                 ///< the option's, or the regime's default
  ThinObjectTest thinObjects = ThinObjectTest::kOff;  ///< the option's, or the regime's default
  int crossingFillReach = 0;                          ///< crossingFillReach under the supersampled rules, else 0 (off)
  /// The smooth blocks' refinement: kCentreProbe becomes kNever where the
  /// guides show every hard shadow (ProviderCapabilities::hardShadowsGuided)
  /// and the samples are not noisy. Noisy samples keep the probes: they are
  /// also samples the denoising fits use (docs/NOISE.md).
  SmoothRefinement smoothRefinement = SmoothRefinement::kAlways;
  /// Guides the engine asks for: object IDs (an object test and a provider
  /// that has them), shader IDs (with them, for the tests that read both),
  /// normals (a provider that has them and creaseAngle > 0).
  bool objectIds = false, shaderIds = false, normals = false;
  /// The surface test's rule: the options' with object IDs, kNone without.
  ObjectTest objectTest = ObjectTest::kNone;
  /// The crease angle between work pixels (creaseAngle / downsample), 0 without normals.
  float creaseAngle = 0.f;
  /// Noisy samples are replaced by their local fits before interpolation.
  bool denoise = false;
  int denoiseRadius = 0;  ///< pixels the fits reach: one elementary block
  float denoiseGate = 0.f;  ///< sd within which the fits average: max(noiseSignificance, kDenoiseGateMinSd of lib/src/settings.h)
  float lazyCorrectionGate = 0.f;  ///< max(noiseSignificance, kLazyCorrectionMinSd of lib/src/settings.h)
};

struct ReconstructionStats {
  int64_t totalPixels = 0;   ///< working-image pixels
  int64_t exactPixels = 0;
  std::array<int64_t, kSampleReasonCount> byReason{};
  int64_t nonFiniteSamples = 0;  ///< exact samples with NaN or infinity, kept to their pixel
  int64_t clampedSamples = 0;    ///< exact samples with a finite value beyond kMaxSampleMagnitude, clamped to it
  int64_t denoisedSamples = 0;   ///< exact samples replaced by their local fit (noisy samples)
  int64_t smoothBlocks = 0, simpleEdgeBlocks = 0, complexEdgeBlocks = 0;
  int64_t lazyAccepted = 0, lazyRejected = 0, fallbackBlocks = 0;
  int64_t checkerboardFilled = 0;  ///< pixels the tests wanted exact, filled from their exact neighbours
  int64_t crossingsFilled = 0;  ///< surface-change border pixels filled from the neighbouring lattice lines
  int64_t providerCalls = 0;
  double timeGuidesS = 0;    ///< in the provider's Guides()
  double timeProviderS = 0;  ///< in the provider's Evaluate() (the illumination)
  double timeEngineS = 0;    ///< everything else
  StageTimes stageTimes;     ///< timeEngineS per stage
  ResolvedSettings settings;  ///< what the stages used
  bool usedSplit = false, usedObjectId = false, usedShaderId = false, usedNormals = false;
  bool usedSupersampledRules = false;  ///< ResolvedSettings::supersampledRules
  double exactFraction() const { return totalPixels ? double(exactPixels) / double(totalPixels) : 0.0; }
};

/// The result of a reconstruction.
struct Reconstruction {
  int width = 0, height = 0;          ///< output resolution
  std::vector<RGB> image;             ///< output, row-major
  int workWidth = 0, workHeight = 0;  ///< working (supersampled) resolution
  std::vector<RGB> workImage;         ///< reconstruction before downsampling
  std::vector<SampleReason> sampleMap;  ///< per working pixel
  std::vector<BlockRecord> blocks;    ///< final leaf blocks
  ReconstructionStats stats;
  /// With ReconstructionOptions::recordInterpolation: how each working
  /// pixel got its value, to reconstruct other channels the same way (its
  /// window() places it in the provider's working image); null otherwise.
  std::shared_ptr<InterpolationRecord> interpolation;
};

/// The settings a reconstruction with `options` of a provider with `caps`
/// uses (its ReconstructionStats::settings), known before it runs.
ResolvedSettings ResolveSettings(const ReconstructionOptions& options, const ProviderCapabilities& caps);

/// The largest elementary block a reconstruction with valid `options` uses,
/// noisy samples or not: a lattice of it is a lattice of each (powers of
/// two), for tile alignment before the provider is known.
int LargestElementaryBlock(const ReconstructionOptions& options);

/// Reconstructs the provider's image with DCM. On error `out` is unspecified.
/// With a provider that answers Status::Pending, returns that status and
/// leaves the requested pixels in `pending`.
Status Reconstruct(SampleProvider& provider, const ReconstructionOptions& options,
                   Reconstruction* out, std::vector<Point2i>* pending = nullptr);

}  // namespace dcm
