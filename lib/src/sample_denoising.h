// Noisy exact samples (Monte Carlo renderers): before they are interpolated,
// each is replaced by a local linear fit through the exact samples around it
// that lie on its surface and do not differ from it significantly, in
// luminance or in any channel. Smooth blocks then interpolate estimates with
// a fraction of the noise instead of spreading four noisy corners over the
// block, and the dense samples along an edge average along the edge, not
// across it. Settings::denoise decides whether
// a reconstruction does it, with Settings::denoiseRadius and denoiseGate.
#pragma once

#include <cstdint>

#include "contrast_test.h"
#include "sample_store.h"

namespace dcm::detail {

/// Replaces every exact, finite sample with a variance by the value at its
/// pixel of a weighted least-squares plane fitted to the exact samples within
/// `radius` pixels (Chebyshev distance; Gaussian weights of sd radius/2) that
/// are finite, on the same surface, within `gate` standard deviations of it
/// in luminance (`noise.WithinNoise`) and in every channel within twice that
/// (a sigma filter, Lee 1983, with a local linear model rather than a mean,
/// so that gradients and one-sided neighbourhoods at edges are not biased). Deterministic: all fits read the samples as they
/// were before the pass. Returns the number of samples replaced.
int64_t DenoiseExactSamples(SampleStore& store, int radius, const ContrastTest& noise, float gate);

}  // namespace dcm::detail
