// dcm's own: the options and the provider's capabilities turned, once, into
// the values the stages use.
#include "settings.h"

#include <algorithm>

#include "dcm/reconstructor.h"

namespace dcm {
namespace detail {

namespace {
// dcm's values of the options with a regime-aware default, per regime
// (which data chose each: docs/TUNING.md).
constexpr int kElementaryBlock = 16;
constexpr int kNoisyElementaryBlock = 8;
constexpr float kContrastThreshold = 0.14f;
constexpr float kSupersampledContrastThreshold = 0.15f;
constexpr ContrastMetric kContrastMetric = ContrastMetric::kMitchell;
constexpr ContrastMetric kSupersampledContrastMetric = ContrastMetric::kDisplayWeighted;
constexpr int kDirections = 8;
constexpr int kSupersampledDirections = 16;
constexpr ThinObjectTest kThinObjects = ThinObjectTest::kEndDiffers;
constexpr ThinObjectTest kSupersampledThinObjects = ThinObjectTest::kNoneMatches;
}  // namespace

Settings Resolve(const ReconstructionOptions& o, const ProviderCapabilities& caps) {
  Settings s;
  s.noisy = caps.variance && o.noiseSignificance > 0.f;
  s.split = o.textureSplit && caps.texture && caps.splitRadiance && !o.fullEvaluation;
  // Never below the finest block.
  s.elementaryBlock = std::max(o.elementaryBlock.value_or(s.noisy ? kNoisyElementaryBlock : kElementaryBlock), o.minBlock);
  // The supersampled rules serve supersampled input whose samples are not
  // noisy: with noise, the noise regime's rules hold at any supersampling.
  s.supersampledRules = o.downsample >= 2 && !s.noisy;
  const bool ss = s.supersampledRules;
  s.contrastMetric = o.contrastMetric.value_or(ss ? kSupersampledContrastMetric : kContrastMetric);
  s.contrastThreshold = o.contrastThreshold.value_or(ss ? kSupersampledContrastThreshold : kContrastThreshold);
  s.contrastSignificance = s.noisy ? o.noiseSignificance : 0.f;
  s.directions = o.directions.value_or(ss ? kSupersampledDirections : kDirections);
  s.thinObjects = o.thinObjects.value_or(ss ? kSupersampledThinObjects : kThinObjects);
  s.crossingFillReach = ss ? o.crossingFillReach : 0;
  // Noisy samples keep the probes: they are also samples the denoising fits
  // use.
  s.smoothRefinement = o.smoothRefinement == SmoothRefinement::kCentreProbe && caps.hardShadowsGuided && !s.noisy
                           ? SmoothRefinement::kNever
                           : o.smoothRefinement;
  s.objectIds = caps.objectId && o.objectTest != ObjectTest::kNone;
  s.shaderIds = s.objectIds && caps.shaderId &&
                (o.objectTest == ObjectTest::kObjectAndShader || o.objectTest == ObjectTest::kObjectOrShader);
  s.normals = caps.normal && o.creaseAngle > 0.f;
  s.objectTest = s.objectIds ? o.objectTest : ObjectTest::kNone;
  // One threshold of curvature per output pixel at every supersampling.
  s.creaseAngle = !s.normals ? 0.f : o.downsample > 1 ? o.creaseAngle / float(o.downsample) : o.creaseAngle;
  s.denoise = s.noisy && o.denoiseSamples && !o.fullEvaluation;
  s.denoiseRadius = s.elementaryBlock;
  s.denoiseGate = std::max(o.noiseSignificance, kDenoiseGateMinSd);
  s.lazyCorrectionGate = std::max(o.noiseSignificance, kLazyCorrectionMinSd);
  return s;
}

}  // namespace detail

ResolvedSettings ResolveSettings(const ReconstructionOptions& options, const ProviderCapabilities& caps) {
  return detail::Resolve(options, caps);
}

int LargestElementaryBlock(const ReconstructionOptions& options) {
  return options.elementaryBlock.value_or(std::max(detail::kElementaryBlock, detail::kNoisyElementaryBlock));
}

}  // namespace dcm
