// dcm's own: the options and the provider's capabilities resolved once into
// the values the stages use (lib/src/settings.h). Each regime rule directly.
#include <gtest/gtest.h>

#include "../../lib/src/settings.h"
#include "dcm/reconstructor.h"

namespace dcm::testing {
namespace {

using detail::Resolve;
using detail::Settings;

ProviderCapabilities Caps(bool variance = false) {
  ProviderCapabilities c;
  c.width = c.height = 64;
  c.objectId = c.shaderId = c.texture = c.splitRadiance = true;
  c.variance = variance;
  return c;
}

// Samples with a variance are noisy only when the tests weigh the noise.
TEST(Settings, NoisySamplesNeedAVarianceAndASignificance) {
  ReconstructionOptions o;
  EXPECT_FALSE(Resolve(o, Caps(false)).noisy);
  EXPECT_TRUE(Resolve(o, Caps(true)).noisy);
  o.noiseSignificance = 0.f;  // the paper's test: differences at face value
  const Settings s = Resolve(o, Caps(true));
  EXPECT_FALSE(s.noisy);
  EXPECT_EQ(s.contrastSignificance, 0.f);
  EXPECT_FALSE(s.denoise);
}

// The noise regime: its own, finer elementary block, the fits one block
// wide, the tests weighing the noise at noiseSignificance, the named gates,
// and the final-resolution rules at any supersampling.
TEST(Settings, TheNoiseRegime) {
  ReconstructionOptions o;
  const Settings finalResolution = Resolve(o, Caps(false));
  o.downsample = 2;
  const Settings s = Resolve(o, Caps(true));
  EXPECT_LT(s.elementaryBlock, finalResolution.elementaryBlock);
  EXPECT_FALSE(s.supersampledRules);
  EXPECT_EQ(s.contrastThreshold, finalResolution.contrastThreshold);
  EXPECT_EQ(s.contrastMetric, finalResolution.contrastMetric);
  EXPECT_EQ(s.directions, finalResolution.directions);
  EXPECT_EQ(s.thinObjects, finalResolution.thinObjects);
  EXPECT_EQ(s.contrastSignificance, o.noiseSignificance);
  EXPECT_TRUE(s.denoise);
  EXPECT_EQ(s.denoiseRadius, s.elementaryBlock);
  EXPECT_EQ(s.denoiseGate, detail::kDenoiseGateMinSd);  // 0.5 sd is below the gate's floor
  EXPECT_EQ(s.lazyCorrectionGate, detail::kLazyCorrectionMinSd);
  o.noiseSignificance = 4.f;  // above both floors
  const Settings strict = Resolve(o, Caps(true));
  EXPECT_EQ(strict.denoiseGate, 4.f);
  EXPECT_EQ(strict.lazyCorrectionGate, 4.f);
  // The regime's elementary block never falls below the finest block.
  o.minBlock = finalResolution.elementaryBlock;
  EXPECT_EQ(Resolve(o, Caps(true)).elementaryBlock, o.minBlock);
  // A block set serves noisy samples too.
  o.elementaryBlock = 2 * finalResolution.elementaryBlock;
  EXPECT_EQ(Resolve(o, Caps(true)).elementaryBlock, *o.elementaryBlock);
  EXPECT_EQ(LargestElementaryBlock(o), *o.elementaryBlock);
}

// Supersampled input whose samples are not noisy has its own defaults (a
// display-weighted contrast, more directions, the paper's thin-object test)
// and the crossing fill; final resolution has neither. The noiseless
// elementary block is the same in both, and the largest of any regime.
TEST(Settings, TheSupersampledRulesHaveTheirOwnDefaults) {
  ReconstructionOptions o;
  const Settings one = Resolve(o, Caps());
  EXPECT_FALSE(one.supersampledRules);
  EXPECT_EQ(one.crossingFillReach, 0);
  EXPECT_EQ(one.elementaryBlock, LargestElementaryBlock(o));
  o.downsample = 2;
  const Settings two = Resolve(o, Caps());
  EXPECT_TRUE(two.supersampledRules);
  EXPECT_FALSE(Resolve(o, Caps(true)).supersampledRules);
  EXPECT_EQ(two.elementaryBlock, one.elementaryBlock);
  EXPECT_NE(two.contrastThreshold, one.contrastThreshold);
  EXPECT_EQ(two.contrastMetric, ContrastMetric::kDisplayWeighted);
  EXPECT_EQ(one.contrastMetric, ContrastMetric::kMitchell);
  EXPECT_GT(two.directions, one.directions);
  EXPECT_EQ(two.thinObjects, ThinObjectTest::kNoneMatches);
  EXPECT_EQ(one.thinObjects, ThinObjectTest::kEndDiffers);
  EXPECT_EQ(two.crossingFillReach, o.crossingFillReach);
}

// A value set serves every regime; the published methods set theirs, so
// they are the same at final resolution, supersampled and noisy.
TEST(Settings, AValueSetServesEveryRegime) {
  ReconstructionOptions set;
  set.elementaryBlock = 32;
  set.contrastThreshold = 0.2f;
  set.contrastMetric = ContrastMetric::kDisplay;
  set.directions = 4;
  set.thinObjects = ThinObjectTest::kAnyDiffers;
  for (const ReconstructionOptions& base : {set, ReconstructionOptions::Paper(), ReconstructionOptions::Guo()}) {
    const Settings one = Resolve(base, Caps());
    ReconstructionOptions o = base;
    o.downsample = 2;
    for (const Settings& s : {Resolve(o, Caps()), Resolve(o, Caps(true)), Resolve(base, Caps(true))}) {
      EXPECT_EQ(s.elementaryBlock, one.elementaryBlock);
      EXPECT_EQ(s.contrastThreshold, one.contrastThreshold);
      EXPECT_EQ(s.contrastMetric, one.contrastMetric);
      EXPECT_EQ(s.directions, one.directions);
      EXPECT_EQ(s.thinObjects, one.thinObjects);
    }
  }
  EXPECT_EQ(Resolve(set, Caps()).directions, 4);
  EXPECT_EQ(LargestElementaryBlock(set), 32);
}

// Centre probes of smooth blocks are left out where the guides show every
// hard shadow, unless the samples are noisy (the fits use the probes).
TEST(Settings, TheSmoothRefinementUsed) {
  ReconstructionOptions o;
  ProviderCapabilities guided = Caps();
  guided.hardShadowsGuided = true;
  EXPECT_EQ(Resolve(o, Caps()).smoothRefinement, SmoothRefinement::kCentreProbe);
  EXPECT_EQ(Resolve(o, guided).smoothRefinement, SmoothRefinement::kNever);
  guided.variance = true;
  EXPECT_EQ(Resolve(o, guided).smoothRefinement, SmoothRefinement::kCentreProbe);
  guided.variance = false;
  o.smoothRefinement = SmoothRefinement::kAlways;  // only the probe is dropped
  EXPECT_EQ(Resolve(o, guided).smoothRefinement, SmoothRefinement::kAlways);
  EXPECT_EQ(ResolveSettings(o, guided).smoothRefinement, SmoothRefinement::kAlways);
}

// The split needs tau and the split radiance from the provider, and is off
// for the full baseline, as are the guides' other uses of it.
TEST(Settings, TheTextureSplitNeedsTauAndTheSplitRadiance) {
  ReconstructionOptions o;
  EXPECT_TRUE(Resolve(o, Caps()).split);
  ProviderCapabilities c = Caps();
  c.splitRadiance = false;
  EXPECT_FALSE(Resolve(o, c).split);
  c = Caps();
  c.texture = false;
  EXPECT_FALSE(Resolve(o, c).split);
  o.fullEvaluation = true;
  EXPECT_FALSE(Resolve(o, Caps()).split);
  EXPECT_FALSE(Resolve(o, Caps(true)).denoise);
  o = {};
  o.textureSplit = false;
  EXPECT_FALSE(Resolve(o, Caps()).split);
}

// Which guides the surface test asks for: shader IDs only with object IDs
// and a test that reads them, normals only with a crease angle, which is
// per work pixel.
TEST(Settings, TheGuidesTheSurfaceTestReads) {
  ReconstructionOptions o;
  ProviderCapabilities c = Caps();
  c.normal = true;
  Settings s = Resolve(o, c);
  EXPECT_TRUE(s.objectIds && s.shaderIds && s.normals);
  EXPECT_EQ(s.objectTest, ObjectTest::kObjectOrShader);
  EXPECT_EQ(s.creaseAngle, o.creaseAngle);
  o.downsample = 4;
  EXPECT_EQ(Resolve(o, c).creaseAngle, o.creaseAngle / 4);
  o.objectTest = ObjectTest::kObjectId;
  s = Resolve(o, c);
  EXPECT_TRUE(s.objectIds);
  EXPECT_FALSE(s.shaderIds);
  o.objectTest = ObjectTest::kNone;
  s = Resolve(o, c);
  EXPECT_FALSE(s.objectIds || s.shaderIds);
  EXPECT_EQ(s.objectTest, ObjectTest::kNone);
  o.creaseAngle = 0.f;
  s = Resolve(o, c);
  EXPECT_FALSE(s.normals);
  EXPECT_EQ(s.creaseAngle, 0.f);
  c.objectId = false;  // a provider without IDs: contrast only
  o = {};
  s = Resolve(o, c);
  EXPECT_FALSE(s.objectIds || s.shaderIds);
  EXPECT_EQ(s.objectTest, ObjectTest::kNone);
}

}  // namespace
}  // namespace dcm::testing
