// Noisy exact samples (Monte Carlo renderers, the paper's open problem): with
// the variance reported, differences count only where they are significant,
// and the exact samples are denoised before they are interpolated.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "noisy_provider.h"
#include "run_helpers.h"

namespace dcm::testing {
namespace {

constexpr int kSize = 256;

struct Outcome {
  Reconstruction r;
  double psnr = 0;  ///< against the noise-free truth
};

Outcome ReconstructNoisy(NoiseModel noise, ReconstructionOptions o = {}, SceneFunction scene = {}) {
  AnalyticProvider exact(kSize, kSize, scene ? scene : FurnishedScene(kSize, kSize));
  NoisyProvider noisy(exact, noise);
  Outcome run;
  run.r = ReconstructOrFail(noisy, o);
  run.psnr = DisplayPsnr(run.r.workImage, exact.FullRender());
  return run;
}

double NoisyFullPsnr(NoiseModel noise) {
  AnalyticProvider exact(kSize, kSize, FurnishedScene(kSize, kSize));
  return DisplayPsnr(NoisyProvider(exact, noise).NoisyFullRender(), exact.FullRender());
}

ReconstructionOptions Significance(float k) {
  ReconstructionOptions o;
  o.noiseSignificance = k;
  return o;
}

/// The elementary block of noisy samples under `o`: the noise regime's.
int NoisyElementaryBlock(const ReconstructionOptions& o) {
  ProviderCapabilities noisy;
  noisy.variance = true;
  return ResolveSettings(o, noisy).elementaryBlock;
}

TEST(Noise, ZeroVarianceChangesNothing) {
  // A provider that reports a variance of zero everywhere must give the
  // noiseless result bit for bit: the noise terms vanish, nothing else moves.
  // (A provider that reports variance gets the lattice of noisy samples,
  // the regime's elementary block, before any sample is seen: the noiseless
  // run uses the same lattice.)
  AnalyticProvider plain(kSize, kSize, FurnishedScene(kSize, kSize));
  ReconstructionOptions sameLattice;
  sameLattice.elementaryBlock = NoisyElementaryBlock(sameLattice);
  const Reconstruction expected = ReconstructOrFail(plain, sameLattice);
  const Outcome zero = ReconstructNoisy({0.f, 0.f});
  ASSERT_EQ(zero.r.workImage.size(), expected.workImage.size());
  for (size_t i = 0; i < expected.workImage.size(); ++i) {
    ASSERT_EQ(zero.r.workImage[i], expected.workImage[i]) << "pixel " << i;
    ASSERT_EQ(zero.r.sampleMap[i], expected.sampleMap[i]) << "pixel " << i;
  }
}

TEST(Noise, TheLiteralTestsChaseTheNoise) {
  // The problem the paper names: taken at face value, noise reads as detail.
  const double clean = ReconstructNoisy({0.f, 0.f}).r.stats.exactFraction();
  // Measured: 3.4x the noise-free fraction at 10 % noise.
  const double literal = ReconstructNoisy({0.1f, 0.01f}, Significance(0.f)).r.stats.exactFraction();
  EXPECT_GT(literal, 2.5 * clean) << "clean " << clean << ", literal " << literal;
}

TEST(Noise, SignificanceSamplesAtTheNoiselessRate) {
  // With the variance weighed at 3 sd, noise of 5-20 % costs no extra
  // samples: the exact fraction stays at or below the noise-free run's
  // (features whose contrast drowns in the noise are not chased either).
  const double clean = ReconstructNoisy({0.f, 0.f}).r.stats.exactFraction();
  for (float rel : {0.05f, 0.1f, 0.2f}) {
    const double f = ReconstructNoisy({rel, 0.01f}, Significance(3.f)).r.stats.exactFraction();
    EXPECT_LE(f, 1.05 * clean) << "relative noise " << rel;
  }
}

TEST(Noise, DefaultSignificanceSamplesFarLessThanTheLiteralTests) {
  // The default (0.5 sd) errs towards refining, to keep faint features, yet
  // spends at most 60 % of the samples the literal tests spend on the same
  // lattice at every noise level (measured: 53, 43 and 41 % at 5, 10 and
  // 20 % noise).
  for (float rel : {0.05f, 0.1f, 0.2f}) {
    const NoiseModel m{rel, 0.01f};
    const double aware = ReconstructNoisy(m).r.stats.exactFraction();
    ReconstructionOptions literalOptions = Significance(0.f);
    literalOptions.elementaryBlock = NoisyElementaryBlock(ReconstructionOptions{});
    const double literal = ReconstructNoisy(m, literalOptions).r.stats.exactFraction();
    EXPECT_LE(aware, 0.6 * literal) << "relative noise " << rel;
  }
}

TEST(Noise, CloserToTheTruthThanTheNoisyFullRender) {
  // The target: from noisy samples, the reconstruction is closer to
  // the converged image than the full noisy render. The margin asked, 1 dB,
  // is a fraction of the measured ones (several dB at every noise level)
  // and still rejects a reconstruction that merely matches the noisy image.
  for (float rel : {0.05f, 0.1f, 0.2f}) {
    const NoiseModel m{rel, 0.01f};
    const Outcome dcm = ReconstructNoisy(m);
    EXPECT_GE(dcm.psnr, NoisyFullPsnr(m) + 1.0) << "relative noise " << rel;
    EXPECT_LE(dcm.r.stats.exactFraction(), 0.35);
  }
}

TEST(Noise, NoisySamplesGetTheNoisyLattice) {
  // Default options on noisy samples: the noise regime's 8-pixel lattice,
  // bit for bit the run with elementaryBlock = 8, and not the 16-pixel
  // lattice of noiseless samples.
  const NoiseModel m{0.1f, 0.01f};
  const Outcome byDefault = ReconstructNoisy(m);
  ReconstructionOptions eight, sixteen;
  eight.elementaryBlock = 8;
  sixteen.elementaryBlock = 16;
  const Outcome explicitEight = ReconstructNoisy(m, eight), noiselessLattice = ReconstructNoisy(m, sixteen);
  ASSERT_EQ(byDefault.r.workImage.size(), explicitEight.r.workImage.size());
  for (size_t i = 0; i < byDefault.r.workImage.size(); ++i)
    ASSERT_EQ(byDefault.r.workImage[i], explicitEight.r.workImage[i]) << "pixel " << i;
  EXPECT_NE(byDefault.r.stats.exactPixels, noiselessLattice.r.stats.exactPixels);
  int widest = 0;  // of the level-0 leaves: 8 pixel steps (x1 - x0), 7 where clipped
  for (const auto& b : byDefault.r.blocks)
    if (b.level == 0) widest = std::max(widest, b.x1 - b.x0);
  EXPECT_EQ(widest, 8);
}

TEST(Noise, DenoisingTheSamplesPaysOff) {
  // Interpolating four raw noisy corners spreads their noise over the block;
  // the local fits must do better (measured: +1.5 dB at 10 % noise).
  const NoiseModel m{0.1f, 0.01f};
  ReconstructionOptions raw;
  raw.denoiseSamples = false;
  const Outcome denoised = ReconstructNoisy(m), plain = ReconstructNoisy(m, raw);
  EXPECT_GT(denoised.r.stats.denoisedSamples, 0);
  EXPECT_EQ(plain.r.stats.denoisedSamples, 0);
  EXPECT_GE(denoised.psnr, plain.psnr + 0.75);
}

TEST(Noise, DenoisingKeepsColoursOfEqualLuminanceApart) {
  // Stripes 4 px wide of one surface, a red and a blue of equal luminance,
  // under 10 % noise: the sigma filter's luminance test cannot tell them
  // apart, its per-channel test must. The mean of a red and a blue sample is
  // 0.1 off in red and 0.29 in blue; a denoised exact sample must not be
  // further from its truth than a raw one, so the RMS error of the denoised
  // exact samples stays below the raw samples' RMS sd (measured: 0.020
  // against 0.032 in red, 0.043 against 0.056 in blue; 0.091 and 0.27 with
  // the luminance test alone).
  const RGB red{0.3f, 0.1f, 0.1f}, blue{0.1f, 0.1f, 0.689f};
  ASSERT_NEAR(Luminance(red), Luminance(blue), 1e-3);
  const SceneFunction stripes = [=](int x, int) {
    PixelTruth t;
    t.Li = (x / 4) % 2 ? blue : red;
    return t;
  };
  const NoiseModel m{0.1f, 0.01f};
  const Outcome o = ReconstructNoisy(m, {}, stripes);
  ASSERT_GT(o.r.stats.denoisedSamples, 0);
  double err[3] = {}, sd[3] = {};
  int64_t n = 0;
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      const size_t i = size_t(y) * kSize + size_t(x);
      if (o.r.sampleMap[i] == SampleReason::kInterpolated) continue;
      const RGB truth = stripes(x, y).L();
      for (int c = 0; c < 3; ++c) {
        const double e = double(o.r.workImage[i][c]) - truth[c], s = m.relative * truth[c] + m.absolute;
        err[c] += e * e;
        sd[c] += s * s;
      }
      ++n;
    }
  ASSERT_GT(n, 0);
  for (int c = 0; c < 3; ++c) EXPECT_LT(std::sqrt(err[c] / double(n)), std::sqrt(sd[c] / double(n))) << "channel " << c;
}

TEST(Noise, EveryPixelIsInterpolatedAfterDenoising) {
  // The thin-object pass decides on the raw samples which pixels it defers
  // or interpolates; after denoising, the ends of a neighbouring direction
  // may no longer agree. Such a pixel must still be written, not left at 0.
  // The furnished scene lifted by 0.1 (its shadows reach 0.015): every
  // channel of the truth is at least m >= 0.1; under 10 % noise (+ 0.01) no
  // pixel, exact, denoised or interpolated, falls below m / 4 (more than 6
  // sd down). Several seeds and thresholds: which decisions change depends
  // on the draw.
  const SceneFunction furnished = FurnishedScene(kSize, kSize);
  const SceneFunction scene = [furnished](int x, int y) {
    PixelTruth t = furnished(x, y);
    t.Lc = t.Lc + RGB::Gray(0.1f);
    return t;
  };
  const std::vector<RGB> truth = AnalyticProvider(kSize, kSize, scene).FullRender();
  float m = 1e30f;
  for (const RGB& t : truth) m = std::min({m, t.r, t.g, t.b});
  ASSERT_GE(m, 0.1f);
  for (uint32_t seed : {1u, 2u, 3u})
    for (float threshold : {0.14f, 0.02f}) {
      ReconstructionOptions o;
      o.contrastThreshold = threshold;
      const Reconstruction r = ReconstructNoisy({0.1f, 0.01f, seed}, o, scene).r;
      ASSERT_GT(r.stats.denoisedSamples, 0);
      for (size_t i = 0; i < r.workImage.size(); ++i)
        for (int c = 0; c < 3; ++c)
          ASSERT_GE(r.workImage[i][c], m / 4) << "pixel (" << i % kSize << ", " << i / kSize << "), seed " << seed
                                              << ", threshold " << threshold << ", " << ToString(r.sampleMap[i]);
    }
}

TEST(Noise, SignificantEdgesAreStillFound) {
  // A step of 10x between two halves of one surface, under 10 % noise: far
  // beyond 3 standard deviations, so the step stays sharp. Every pixel next
  // to the step keeps its side's value to within 4 sd of the noise.
  const SceneFunction step = [](int x, int) {
    PixelTruth t;
    t.Li = RGB::Gray(x < 101 ? 0.05f : 0.5f);
    return t;
  };
  const Outcome o = ReconstructNoisy({0.1f, 0.f}, {}, step);
  for (int y = 0; y < kSize; ++y)
    for (int x : {99, 100, 101, 102}) {
      const float truth = x < 101 ? 0.05f : 0.5f;
      const float got = Luminance(o.r.workImage[size_t(y) * kSize + size_t(x)]);
      EXPECT_NEAR(got, truth, 4 * 0.1f * truth) << "pixel (" << x << ", " << y << ")";
    }
}

TEST(Noise, NonFiniteSamplesStayInTheirPixel) {
  // A NaN and an infinite sample among noisy ones: the denoising fits never
  // read them, so no other pixel becomes non-finite.
  const SceneFunction base = FurnishedScene(kSize, kSize);
  const SceneFunction scene = [base](int x, int y) {
    PixelTruth t = base(x, y);
    if (x == 64 && y == 64) t.renderedL = RGB::Gray(std::numeric_limits<float>::quiet_NaN());
    if (x == 128 && y == 128) t.renderedL = RGB::Gray(std::numeric_limits<float>::infinity());
    return t;
  };
  const Outcome o = ReconstructNoisy({0.1f, 0.01f}, {}, scene);
  for (int y = 0; y < kSize; ++y)
    for (int x = 0; x < kSize; ++x) {
      if ((x == 64 && y == 64) || (x == 128 && y == 128)) continue;
      ASSERT_TRUE(IsFinite(o.r.workImage[size_t(y) * kSize + size_t(x)])) << "pixel (" << x << ", " << y << ")";
    }
}

}  // namespace
}  // namespace dcm::testing
