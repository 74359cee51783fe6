// dcm's own: the options and the provider's capabilities turned, once, into
// the values the stages use.
#include "settings.h"

#include <algorithm>

#include "dcm/reconstructor.h"

namespace dcm {
namespace detail {

Settings Resolve(const ReconstructionOptions& o, const ProviderCapabilities& caps) {
  Settings s;
  s.noisy = caps.variance && o.noiseSignificance > 0.f;
  s.split = o.textureSplit && caps.texture && caps.splitRadiance && !o.fullEvaluation;
  s.elementaryBlock = o.ElementaryBlockFor(s.noisy);
  s.supersampledRules = o.SupersampledRules(s.noisy);
  s.contrastMetric = o.ContrastMetricFor(s.supersampledRules);
  s.contrastThreshold = o.ContrastThresholdFor(s.supersampledRules);
  s.contrastSignificance = s.noisy ? o.noiseSignificance : 0.f;
  s.directions = o.DirectionsFor(s.supersampledRules);
  s.thinObjects = o.ThinObjectsFor(s.supersampledRules);
  s.crossingFillReach = o.CrossingFillReachFor(s.supersampledRules);
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
  s.creaseAngle = s.normals ? o.WorkCreaseAngle() : 0.f;
  s.denoise = s.noisy && o.denoiseSamples && !o.fullEvaluation;
  s.denoiseRadius = s.elementaryBlock;
  s.denoiseGate = std::max(o.noiseSignificance, kDenoiseGateMinSd);
  s.lazyCorrectionGate = std::max(o.noiseSignificance, kLazyCorrectionMinSd);
  return s;
}

}  // namespace detail

bool UsesSupersampledRules(const ReconstructionOptions& options, const ProviderCapabilities& caps) {
  return detail::Resolve(options, caps).supersampledRules;
}

SmoothRefinement UsedSmoothRefinement(const ReconstructionOptions& options, const ProviderCapabilities& caps) {
  return detail::Resolve(options, caps).smoothRefinement;
}

}  // namespace dcm
