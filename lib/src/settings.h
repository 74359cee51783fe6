// The values the stages of one reconstruction use, resolved once from the
// user's options and the provider's capabilities: every rule that picks a
// regime (noisy samples, supersampled rules, texture split, guides) and every
// constant the stages share lives here.
#pragma once

#include "dcm/options.h"
#include "dcm/reconstructor.h"
#include "dcm/sample_provider.h"

namespace dcm::detail {

/// The lazy evaluation's correction is applied only when the noise cannot
/// explain it, at this many standard deviations at least: spread over the
/// block by the tent, one sample moves a whole block, which needs stronger
/// evidence than a refinement (that costs samples, not error).
inline constexpr float kLazyCorrectionMinSd = 3.f;
/// The denoising averages samples within this many standard deviations at
/// least: wider than the detection's significance, which errs towards
/// refining.
inline constexpr float kDenoiseGateMinSd = 2.f;

/// One reconstruction's resolved settings (Resolve); public as
/// ReconstructionStats::settings.
using Settings = ResolvedSettings;

/// The settings of a reconstruction with `options` of a provider with `caps`.
Settings Resolve(const ReconstructionOptions& options, const ProviderCapabilities& caps);

}  // namespace dcm::detail
