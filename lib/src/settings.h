// The values the stages of one reconstruction use, resolved once from the
// user's options and the provider's capabilities: every rule that picks a
// regime (noisy samples, supersampled rules, texture split, guides) and every
// constant the stages share lives here.
#pragma once

#include "dcm/options.h"
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

/// One reconstruction's resolved settings (Resolve).
struct Settings {
  /// Samples carry their variance and the tests weigh it: a provider that
  /// reports variance, noiseSignificance > 0.
  bool noisy = false;
  /// Interpolate (L_i, L_c) and re-apply tau (paper 3.3): asked for, the
  /// provider gives tau and the split radiance, and not the full baseline.
  bool split = false;
  /// ReconstructionOptions::ElementaryBlockFor the samples.
  int elementaryBlock = 16;
  /// ReconstructionOptions::SupersampledRules: supersampled, not noisy.
  bool supersampledRules = false;
  ContrastMetric contrastMetric = ContrastMetric::kMitchell;  ///< ContrastMetricFor the rules
  float contrastThreshold = 0.f;                               ///< ContrastThresholdFor the rules
  /// The contrast test's significance: noiseSignificance with noisy
  /// samples, 0 (the paper's test) without.
  float contrastSignificance = 0.f;
  int directions = 8;                                       ///< DirectionsFor the rules
  ThinObjectTest thinObjects = ThinObjectTest::kOff;        ///< ThinObjectsFor the rules
  int crossingFillReach = 0;                                ///< CrossingFillReachFor the rules (0: off)
  /// The smooth blocks' refinement: kCentreProbe becomes kNever where the
  /// guides show every hard shadow and the samples are not noisy.
  SmoothRefinement smoothRefinement = SmoothRefinement::kAlways;
  /// Guides the engine asks for: object IDs (an object test and a provider
  /// that has them), shader IDs (with them, for the tests that read both),
  /// normals (a provider that has them and creaseAngle > 0).
  bool objectIds = false, shaderIds = false, normals = false;
  /// The surface test's rule: the options' with object IDs, kNone without.
  ObjectTest objectTest = ObjectTest::kNone;
  /// The crease angle between work pixels (WorkCreaseAngle), 0 without normals.
  float creaseAngle = 0.f;
  /// Noisy samples are replaced by their local fits before interpolation.
  bool denoise = false;
  int denoiseRadius = 0;  ///< pixels the fits reach: one elementary block
  float denoiseGate = 0.f;  ///< sd within which the fits average: max(noiseSignificance, kDenoiseGateMinSd)
  float lazyCorrectionGate = 0.f;  ///< max(noiseSignificance, kLazyCorrectionMinSd)
};

/// The settings of a reconstruction with `options` of a provider with `caps`.
Settings Resolve(const ReconstructionOptions& options, const ProviderCapabilities& caps);

}  // namespace dcm::detail
