// Noisy exact samples (Monte Carlo renderers): before they are interpolated,
// each is replaced by a local linear fit through the exact samples around it
// that lie on its surface and do not differ from it significantly. Smooth
// blocks then interpolate estimates with a fraction of the noise instead of
// spreading four noisy corners over the block, and the dense samples along an
// edge average along the edge, not across it.
#pragma once

#include <cstdint>

#include "contrast_test.h"
#include "dcm/options.h"
#include "dcm/sample_provider.h"
#include "sample_store.h"

namespace dcm::detail {

/// Whether the samples of a provider with `caps` count as noisy: they carry
/// their variance and the tests weigh it.
inline bool NoisySamples(const ReconstructionOptions& options, const ProviderCapabilities& caps) {
  return caps.variance && options.noiseSignificance > 0.f;
}

/// The elementary block of a reconstruction of a provider with `caps`.
inline int ElementaryBlock(const ReconstructionOptions& options, const ProviderCapabilities& caps) {
  return options.ElementaryBlockFor(NoisySamples(options, caps));
}

/// Whether a reconstruction with `options` of a provider with `caps`
/// denoises its exact samples: noisy samples (variance reported, the noise
/// weighed) with denoiseSamples on, and not the full-evaluation baseline.
inline bool DenoisesSamples(const ReconstructionOptions& options, const ProviderCapabilities& caps) {
  return NoisySamples(options, caps) && options.denoiseSamples && !options.fullEvaluation;
}

/// How far (pixels) the denoising fits reach: one elementary block.
inline int DenoiseRadius(const ReconstructionOptions& options, const ProviderCapabilities& caps) {
  return ElementaryBlock(options, caps);
}

/// Replaces every exact, finite sample with a variance by the value at its
/// pixel of a weighted least-squares plane fitted to the exact samples within
/// `radius` pixels (Chebyshev distance; Gaussian weights of sd radius/2) that
/// are finite, on the same surface, and within `gate` standard deviations of
/// it (`noise.WithinNoise`) (a sigma filter, Lee 1983, with a local linear model
/// rather than a mean, so that gradients and one-sided neighbourhoods at
/// edges are not biased). Deterministic: all fits read the samples as they
/// were before the pass. Returns the number of samples replaced.
int64_t DenoiseExactSamples(SampleStore& store, int radius, const ContrastTest& noise, float gate);

}  // namespace dcm::detail
