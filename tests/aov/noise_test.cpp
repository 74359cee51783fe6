// Noisy AOVs (issue #8): the variance of the samples from an independent
// second render or estimated from the data, and dcm reconstruct on noisy input.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "dcm/aov/aov_provider.h"
#include "dcm/noise_estimate.h"
#include "dcm/reconstructor.h"
#include "test_util.h"

namespace dcm::aov::test {
namespace {

constexpr float kSigma = 0.05f;

/// The generic channels of `sc` with Gaussian noise of sd `sigma` added to
/// L_i (split) or R, G, B (one deviate per pixel, shared by R, G, B).
std::vector<TestChannel> NoisyChannels(const Scene& sc, bool split, uint32_t seed, float sigma = kSigma) {
  std::vector<TestChannel> ch = sc.GenericChannels(split);
  std::mt19937 rng(seed);
  std::normal_distribution<float> normal(0.f, sigma);
  std::vector<float> n(size_t(sc.width) * size_t(sc.height));
  for (float& v : n) v = normal(rng);
  for (TestChannel& c : ch) {
    const bool target = split ? c.name.rfind("Li.", 0) == 0 : (c.name == "R" || c.name == "G" || c.name == "B");
    if (!target) continue;
    for (size_t i = 0; i < n.size(); ++i) c.values[i] += n[i];
  }
  return ch;
}

std::unique_ptr<AovProvider> Open(const std::vector<std::string>& inputs, const AovOptions& o) {
  std::unique_ptr<AovProvider> p;
  const Status st = AovProvider::Open(inputs, o, &p);
  EXPECT_TRUE(st.ok()) << st.message();
  return p;
}

std::vector<ExactSample> AllSamples(AovProvider& p, bool split) {
  std::vector<Point2i> px;
  for (int y = 0; y < p.height(); ++y)
    for (int x = 0; x < p.width(); ++x) px.push_back({x, y});
  std::vector<ExactSample> s(px.size());
  SampleRequest req;
  req.split = split;
  req.variance = true;
  const Status st = p.Evaluate(px, req, s);
  EXPECT_TRUE(st.ok()) << st.message();
  return s;
}

TEST(AovNoise, SecondRenderGivesTheMeanAndItsVariance) {
  ScratchDir dir;
  const Scene sc{128, 96};
  WriteExr(dir / "a.exr", sc.width, sc.height, NoisyChannels(sc, false, 1));
  WriteExr(dir / "b.exr", sc.width, sc.height, NoisyChannels(sc, false, 2));
  const std::vector<RGB> a = ReadRgbExr(dir / "a.exr"), b = ReadRgbExr(dir / "b.exr");
  AovOptions o;
  o.secondRender = {dir / "b.exr"};
  auto p = Open({dir / "a.exr"}, o);
  ASSERT_TRUE(p);
  EXPECT_TRUE(p->Capabilities().variance);
  const std::vector<ExactSample> s = AllSamples(*p, false);
  double meanVar = 0;
  for (size_t i = 0; i < s.size(); ++i) {
    ASSERT_EQ(s[i].L, (a[i] + b[i]) * 0.5f) << "pixel " << i;
    meanVar += s[i].variance.g;
  }
  meanVar /= double(s.size());
  // The mean of two renders of sd sigma has variance sigma^2 / 2. Over 12288
  // pixels the estimate's own error is about 1 %; 10 % leaves room for the
  // windows cut at surface boundaries.
  EXPECT_NEAR(meanVar, kSigma * kSigma / 2, 0.1 * kSigma * kSigma / 2);
}

TEST(AovNoise, VarianceEstimatedFromTheData) {
  // Noise on L_i of a textured scene: the estimate works in L_i (the checker
  // divided out) and reports sigma^2 tau^2 in L. The median pixel within 15 %
  // (the noise here is of a constant sd, the estimate's pooling as a share of
  // the value, over the shadow's 4x steps and the gradients).
  ScratchDir dir;
  const Scene sc{128, 96};
  WriteExr(dir / "a.exr", sc.width, sc.height, NoisyChannels(sc, true, 3));
  AovOptions o;
  o.estimateVariance = true;
  auto p = Open({dir / "a.exr"}, o);
  ASSERT_TRUE(p);
  const std::vector<ExactSample> s = AllSamples(*p, true);
  std::vector<double> ratio;
  for (int y = 0; y < sc.height; ++y)
    for (int x = 0; x < sc.width; ++x) {
      const float tau = sc.Tau(x, y).g;
      ratio.push_back(s[size_t(y * sc.width + x)].variance.g / (kSigma * kSigma * tau * tau));
    }
  // The mean too (1.01 here): no window mean of squared residuals takes the
  // shadow's edge for noise (that made it 1.17, and 8.6 within 3 px of it).
  // 12288 pixels in about 250 independent 7x7 windows of a skewed median (sd
  // about 0.3 of its mean): the mean's own sd is about 0.02, 0.06 is 3 sd.
  // Within 3 px of the edge (235 pixels) it runs high, the lit side's 4x
  // variance in half of a window: 2.0 here, below 3.
  double all = 0, edge = 0;
  int nearEdge = 0;
  for (int y = 0; y < sc.height; ++y)
    for (int x = 0; x < sc.width; ++x) {
      const double r = ratio[size_t(y * sc.width + x)];
      all += r;
      const float fx = float(x) / float(sc.width), fy = float(y) / float(sc.height);
      if (sc.ObjectId(x, y) == 1 && std::abs(fx + fy - 0.7f) * float(sc.width) < 3) edge += r, ++nearEdge;
    }
  std::printf("estimated / true variance: mean %.3f, within 3 px of the shadow's edge %.3f\n",
              all / double(ratio.size()), edge / nearEdge);
  EXPECT_NEAR(all / double(ratio.size()), 1.0, 0.06);
  EXPECT_LT(edge / nearEdge, 3.0);
  std::nth_element(ratio.begin(), ratio.begin() + ratio.size() / 2, ratio.end());
  EXPECT_NEAR(ratio[ratio.size() / 2], 1.0, 0.15);
}

TEST(AovNoise, NoiseDetectedWhereItMatters) {
  // detectNoise: a clean render is taken as noise-free; a render whose noise
  // alone costs clearly more than the kNoisyPsnr (42 dB) allow is noisy and
  // gets the estimated variance; one whose noise costs clearly less is taken
  // as noise-free. "Clearly": 4 dB either side, more than the detector's
  // error on the Cycles room (about 3 dB, docs/NOISE.md); the true PSNR of
  // each input's noise is measured here, so that the bands are checked too.
  ScratchDir dir;
  const Scene sc{128, 96};
  std::vector<RGB> clean;
  for (int y = 0; y < sc.height; ++y)
    for (int x = 0; x < sc.width; ++x) clean.push_back(sc.L(x, y));
  struct Case {
    float sigma;
    bool noisy;
  };
  for (const Case& c : {Case{0.f, false}, Case{0.008f, false}, Case{0.025f, true}, Case{0.05f, true}}) {
    const std::string path = dir / ("in" + std::to_string(c.sigma) + ".exr");
    WriteExr(path, sc.width, sc.height, NoisyChannels(sc, true, 11, c.sigma));
    double mse = 0;
    const std::vector<ExactSample> truth = [&] {
      AovOptions plain;
      auto p = Open({path}, plain);
      std::vector<Point2i> px;
      for (int y = 0; y < sc.height; ++y)
        for (int x = 0; x < sc.width; ++x) px.push_back({x, y});
      std::vector<ExactSample> s(px.size());
      EXPECT_TRUE(p->Evaluate(px, {}, s).ok());
      return s;
    }();
    for (size_t i = 0; i < clean.size(); ++i)
      for (int k = 0; k < 3; ++k) {
        const double e = std::clamp(SrgbEncode(truth[i].L[k]), 0.f, 1.f) - std::clamp(SrgbEncode(clean[i][k]), 0.f, 1.f);
        mse += e * e / double(3 * clean.size());
      }
    const double psnr = mse > 0 ? -10 * std::log10(mse) : 1e9;
    if (c.sigma > 0) {
      if (c.noisy) ASSERT_LE(psnr, kNoisyPsnr - 4) << "sigma " << c.sigma << ": not clearly noisy";
      else ASSERT_GE(psnr, kNoisyPsnr + 4) << "sigma " << c.sigma << ": not clearly faint";
    }
    AovOptions o;
    o.detectNoise = true;
    auto p = Open({path}, o);
    ASSERT_TRUE(p);
    EXPECT_EQ(p->Capabilities().variance, c.noisy) << "sigma " << c.sigma << ", noise PSNR " << psnr << " dB";
    const double detected = p->Noise().detectedPsnr;
    std::printf("sigma %.3f: noise %.1f dB PSNR, detected %.1f dB, %s\n", c.sigma, psnr, detected,
                p->Capabilities().variance ? "noisy" : "clean");
    // What it says is what it decided: the figure on the side of 42 dB it chose.
    EXPECT_EQ(p->Noise().variance, c.noisy ? "detected" : "none");
    EXPECT_FALSE(std::isnan(detected));
    EXPECT_EQ(detected < kNoisyPsnr, c.noisy) << detected;
    // The command says the same in its stats and the output's metadata (an
    // infinite figure, no noise seen at all, is null in JSON and absent there).
    const RunResult r = RunDcm({"reconstruct", path, "-o", dir / "out.exr", "--stats", dir / "s.json", "-q"}, dir);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto stats = nlohmann::json::parse(ReadText(dir / "s.json"));
    EXPECT_EQ(stats["noise"]["variance"], p->Noise().variance);
    auto in = OIIO::ImageInput::open(dir / "out.exr");
    ASSERT_TRUE(in);
    EXPECT_EQ(in->spec().get_string_attribute("dcm:variance"), p->Noise().variance);
    if (std::isfinite(detected)) {
      EXPECT_NEAR(stats["noise"]["detected_psnr"].get<double>(), detected, 1e-9);
      EXPECT_FLOAT_EQ(in->spec().get_float_attribute("dcm:detected_noise_psnr"), float(detected));
    } else {
      EXPECT_TRUE(stats["noise"]["detected_psnr"].is_null());
    }
    // Without the flag nothing is estimated.
    auto q = Open({path}, AovOptions{});
    ASSERT_TRUE(q);
    EXPECT_FALSE(q->Capabilities().variance);
    EXPECT_EQ(q->Noise().variance, "none");
    EXPECT_TRUE(std::isnan(q->Noise().detectedPsnr));
  }
}

/// A diffuse wall (x < width/2: tau 0.5) beside a mirror (tau 0) that shows
/// a texture of albedo 0.2 to 0.8 at the pixel scale (a fine pattern seen
/// from afar: no direction along which it does not change), lit by a
/// gradient: L is the
/// albedo times the light, each pixel's noise a share `rho` of its value (a
/// Monte Carlo estimate's is relative). Generic channels with "albedo."
/// (the texture on the mirror, tau on the wall) where `albedo`.
struct MirrorScene {
  int width = 128, height = 96;
  bool Mirror(int x) const { return x >= width / 2; }
  float Texel(int x, int y) const {
    uint32_t h = uint32_t(x) * 73856093u ^ uint32_t(y) * 19349663u;
    h ^= h >> 13, h *= 0x5bd1e995u, h ^= h >> 15;
    return 0.2f + 0.6f * float(h % 1024u) / 1023.f;
  }
  float Light(int x, int y) const { return 0.3f + 0.4f * float(x) / float(width) + 0.2f * float(y) / float(height); }
  float Albedo(int x, int y) const { return Mirror(x) ? Texel(x, y) : 0.5f; }
  /// Light on the mirror that its albedo does not modulate (a light's
  /// highlight): uniform here.
  float glow = 0;
  float L(int x, int y) const { return Albedo(x, y) * Light(x, y) + (Mirror(x) ? glow : 0.f); }
  /// `lr`: the Lr channels, what the albedo modulates (L less the glow).
  std::vector<TestChannel> Channels(bool albedo, float rho, uint32_t seed, bool lr = false) const {
    std::mt19937 rng(seed);
    std::normal_distribution<float> normal(0.f, 1.f);
    std::vector<float> noisy(size_t(width) * size_t(height));
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) noisy[size_t(y * width + x)] = L(x, y) * (1.f + rho * normal(rng));
    auto at = [&](int x, int y) { return noisy[size_t(y * width + x)]; };
    std::vector<TestChannel> ch;
    for (const char* c : {"R", "G", "B"}) ch.push_back(Fill(c, width, height, at));
    // L_i: the wall's light (its noise too); the mirror has none.
    for (const char* c : {"Li.R", "Li.G", "Li.B"})
      ch.push_back(Fill(c, width, height, [&](int x, int y) { return Mirror(x) ? 0.f : at(x, y) / 0.5f; }));
    for (const char* c : {"tau.R", "tau.G", "tau.B"})
      ch.push_back(Fill(c, width, height, [&](int x, int) { return Mirror(x) ? 0.f : 0.5f; }));
    if (albedo)
      for (const char* c : {"albedo.R", "albedo.G", "albedo.B"})
        ch.push_back(Fill(c, width, height, [&](int x, int y) { return Albedo(x, y); }));
    if (lr)
      for (const char* c : {"Lr.R", "Lr.G", "Lr.B"})
        ch.push_back(Fill(c, width, height, [&](int x, int y) { return Mirror(x) ? at(x, y) - glow : 0.f; }));
    AddIds(&ch);
    return ch;
  }
  /// The wall and the mirror as objects (and shaders) 1 and 2.
  void AddIds(std::vector<TestChannel>* ch) const {
    TestChannel id{"id", {}, {}}, shader{"shader", {}, {}};
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        id.ids.push_back(Mirror(x) ? 2u : 1u);
        shader.ids.push_back(Mirror(x) ? 2u : 1u);
      }
    ch->push_back(id);
    ch->push_back(shader);
  }
};

TEST(AovNoise, ATextureSeenInAMirrorIsNotTakenForNoise) {
  // The estimate from one render reads residuals against neighbours: the
  // mirror's texture, with nothing to divide it out, is a residual at every
  // pixel in every direction. With the albedo, the split through mirrors
  // leaves the light in L_i; without the split, L is divided by the albedo.
  ScratchDir dir;
  const MirrorScene sc;
  constexpr float kRho = 0.05f;
  auto medianRatio = [&](bool albedo, bool split) {
    const std::string path = dir / (albedo ? "albedo.exr" : "plain.exr");
    WriteExr(path, sc.width, sc.height, sc.Channels(albedo, kRho, 5));
    AovOptions o;
    o.estimateVariance = true;
    o.split = split;
    auto p = Open({path}, o);
    if (!p) return -1.0;
    const std::vector<ExactSample> s = AllSamples(*p, split);
    std::vector<double> r;
    for (int y = 0; y < sc.height; ++y)
      for (int x = sc.width / 2 + 4; x < sc.width - 4; ++x) {
        const double truth = double(kRho * sc.L(x, y)) * double(kRho * sc.L(x, y));
        r.push_back(s[size_t(y * sc.width + x)].variance.g / truth);
      }
    std::nth_element(r.begin(), r.begin() + r.size() / 2, r.end());
    return r[r.size() / 2];
  };
  const double without = medianRatio(false, true), with = medianRatio(true, true), unsplit = medianRatio(true, false);
  std::printf("the mirror's estimated / true variance, median: without the albedo %.2f, with it %.2f, with it and "
              "no split %.2f\n", without, with, unsplit);
  // 5 % relative noise over a texture of 0.2 to 0.8: without the albedo the
  // texture's relative residual, about 0.5, is 100 times the noise's 0.05.
  // With it, the median of 7x7 windows over 2900 pixels within 25 %, as
  // VarianceEstimatedFromTheData allows 15 % for its median.
  EXPECT_NEAR(with, 1.0, 0.25);
  EXPECT_NEAR(unsplit, 1.0, 0.25);
  EXPECT_GT(without, 10.0);
}

/// The RMSE over the mirror of `sc` written noise-free to `path` (with the
/// albedo, and Lr, where asked) and reconstructed with the engine's
/// defaults; its exact share in `exact`.
double MirrorRmse(const MirrorScene& sc, const std::string& path, bool albedo, bool lr, double* exact) {
  WriteExr(path, sc.width, sc.height, sc.Channels(albedo, 0.f, 0, lr));
  auto p = Open({path}, AovOptions{});
  if (!p) return -1;
  Reconstruction r;
  const Status st = Reconstruct(*p, ReconstructionOptions{}, &r);
  EXPECT_TRUE(st.ok()) << st.message();
  double sq = 0;
  int n = 0;
  for (int y = 0; y < sc.height; ++y)
    for (int x = sc.width / 2; x < sc.width; ++x, ++n) {
      const double d = double(r.image[size_t(y * sc.width + x)].g) - double(sc.L(x, y));
      sq += d * d;
    }
  *exact = r.stats.exactFraction();
  return std::sqrt(sq / n);
}

TEST(AovAlbedo, AMirrorShowsTheTextureItReflects) {
  // Noise-free. With the albedo the split goes through the mirror: L_i =
  // L / albedo is the light, a gradient that the engine's blocks interpolate
  // exactly, and the texture comes back per pixel from the albedo. Without
  // it, the mirror's L_c holds the texture, and only exact pixels show it.
  ScratchDir dir;
  const MirrorScene sc;
  double exact[2] = {0, 0};
  const double without = MirrorRmse(sc, dir / "plain.exr", false, false, &exact[0]);
  const double with = MirrorRmse(sc, dir / "albedo.exr", true, false, &exact[1]);
  std::printf("the mirror's RMSE: without the albedo %.4f (%.1f %% exact), with it %.6f (%.1f %% exact)\n", without,
              100 * exact[0], with, 100 * exact[1]);
  // With it, what is left is float rounding of L / albedo * albedo and of the
  // bilinear weights: about 1e-7 of values of 0.06 to 0.6.
  EXPECT_GE(with, 0);
  EXPECT_LT(with, 1e-4);
  // Without it, the texture times the light, interpolated over where no
  // pixel was exact: far above that.
  EXPECT_GT(without, 100 * with);
}

TEST(AovAlbedo, LightTheAlbedoDoesNotModulateStaysInLc) {
  // A glow over the mirror (a light's highlight on it) is no reflection of
  // the texture: with Lr (what the albedo modulates) given, L_i = Lr / albedo
  // and the glow is L_c, both smooth; with L / albedo instead, the glow
  // divided by the texture is a texture of its own in L_i.
  ScratchDir dir;
  MirrorScene sc;
  sc.glow = 0.3f;
  double exact = 0;
  const double overL = MirrorRmse(sc, dir / "l.exr", true, false, &exact);
  const double overLr = MirrorRmse(sc, dir / "lr.exr", true, true, &exact);
  std::printf("the mirror's RMSE with a glow: L over the albedo %.4f, Lr over it %.6f\n", overL, overLr);
  // Float rounding as in AMirrorShowsTheTextureItReflects; the other far above.
  EXPECT_GE(overLr, 0);
  EXPECT_LT(overLr, 1e-4);
  EXPECT_GT(overL, 100 * overLr);
}

TEST(AovAlbedo, WithoutABeautyTheMirrorsLKeepsItsDiffuseLight) {
  // No R, G, B: L is L_i tau + L_c. A mirror's tau (0.01 here, below the
  // floor) is replaced by the albedo for the split through mirrors, but L
  // must still be made of the tau the inputs gave, diffuse light included.
  ScratchDir dir;
  const MirrorScene sc;
  constexpr float kMirrorTau = 0.01f;
  auto tau = [&](int x) { return sc.Mirror(x) ? kMirrorTau : 0.5f; };
  auto lc = [&](int x, int y) { return sc.Mirror(x) ? sc.L(x, y) : 0.f; };
  std::vector<TestChannel> ch;
  for (const char* c : {"Li.R", "Li.G", "Li.B"})
    ch.push_back(Fill(c, sc.width, sc.height, [&](int x, int y) { return sc.Light(x, y); }));
  for (const char* c : {"Lc.R", "Lc.G", "Lc.B"}) ch.push_back(Fill(c, sc.width, sc.height, lc));
  for (const char* c : {"tau.R", "tau.G", "tau.B"})
    ch.push_back(Fill(c, sc.width, sc.height, [&](int x, int) { return tau(x); }));
  for (const char* c : {"albedo.R", "albedo.G", "albedo.B"})
    ch.push_back(Fill(c, sc.width, sc.height, [&](int x, int y) { return sc.Albedo(x, y); }));
  sc.AddIds(&ch);
  WriteExr(dir / "nobeauty.exr", sc.width, sc.height, ch);
  auto p = Open({dir / "nobeauty.exr"}, AovOptions{});
  ASSERT_TRUE(p);
  std::vector<Point2i> px;
  for (int y = 0; y < sc.height; ++y)
    for (int x = 0; x < sc.width; ++x) px.push_back({x, y});
  std::vector<ExactSample> s(px.size());
  SampleRequest req;
  req.split = true;
  const Status st = p->Evaluate(px, req, s);
  ASSERT_TRUE(st.ok()) << st.message();
  for (int y = 0; y < sc.height; ++y)
    for (int x = 0; x < sc.width; ++x) {
      const ExactSample& e = s[size_t(y * sc.width + x)];
      // One product and one sum in float: a few ulps of values up to 0.7;
      // dropping L_i tau would be off by 0.01 times a light of 0.3 to 0.9.
      const float want = sc.Light(x, y) * tau(x) + lc(x, y);
      ASSERT_NEAR(e.L.g, want, 1e-6f) << "pixel " << x << "," << y;
      // On the mirror the split went through: L_i is L over the albedo.
      if (sc.Mirror(x)) {
        ASSERT_NEAR(e.Li.g, want / sc.Albedo(x, y), 1e-5f) << "pixel " << x << "," << y;
      }
    }
}

TEST(AovNoise, ConflictingVarianceSourcesAreErrors) {
  ScratchDir dir;
  const Scene sc{32, 32};
  std::vector<TestChannel> withVar = sc.GenericChannels(false);
  for (const char* c : {"var.R", "var.G", "var.B"}) withVar.push_back(Fill(c, 32, 32, [](int, int) { return 0.01f; }));
  WriteExr(dir / "v.exr", 32, 32, withVar);
  WriteExr(dir / "b.exr", 32, 32, sc.GenericChannels(false));
  const Scene small{16, 32};
  WriteExr(dir / "small.exr", 16, 32, small.GenericChannels(false));
  std::unique_ptr<AovProvider> p;
  AovOptions second;
  second.secondRender = {dir / "b.exr"};
  Status st = AovProvider::Open({dir / "v.exr"}, second, &p);
  EXPECT_FALSE(st.ok());
  EXPECT_NE(st.message().find("the inputs carry variance (var.R"), std::string::npos) << st.message();

  second.secondRender = {dir / "small.exr"};
  st = AovProvider::Open({dir / "b.exr"}, second, &p);
  EXPECT_FALSE(st.ok());
  EXPECT_NE(st.message().find("second render '" + dir / "small.exr" + "' is 16x32"), std::string::npos)
      << st.message();

  AovOptions sparse;
  sparse.sparse = true;
  sparse.estimateVariance = true;
  st = AovProvider::Open({dir / "b.exr"}, sparse, &p);
  EXPECT_FALSE(st.ok());
  EXPECT_NE(st.message().find("need dense inputs"), std::string::npos) << st.message();
}

TEST(AovNoise, ReconstructFromTwoNoisyRendersBeatsTheirMean) {
  // The command-line path: two renders with noisy L_i in, the clean image as
  // the reference. dcm must come closer to the clean image than the mean of
  // the two renders (what a user would otherwise keep) while evaluating a
  // minority of the pixels. (The split matters: in the beauty alone, this
  // scene's 4-pixel checker is detail finer than the 16-pixel lattice.)
  ScratchDir dir;
  const Scene sc{256, 256};
  WriteExr(dir / "a.exr", sc.width, sc.height, NoisyChannels(sc, true, 5));
  WriteExr(dir / "b.exr", sc.width, sc.height, NoisyChannels(sc, true, 6));
  std::vector<TestChannel> clean;
  for (int c = 0; c < 3; ++c)
    clean.push_back(Fill(std::string(1, "RGB"[c]), sc.width, sc.height, [&](int x, int y) { return sc.L(x, y)[c]; }));
  WriteExr(dir / "clean.exr", sc.width, sc.height, clean);
  const RunResult r = RunDcm({"reconstruct", dir / "a.exr", "--second-render", dir / "b.exr", "--reference",
                              dir / "clean.exr", "-o", dir / "out.exr", "--stats", dir / "s.json", "--quiet"},
                             dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const RunResult mean = RunDcm({"reconstruct", dir / "a.exr", "--second-render", dir / "b.exr", "--reference",
                                 dir / "clean.exr", "--full", "-o", dir / "mean.exr", "--stats", dir / "m.json",
                                 "--quiet"},
                                dir);
  ASSERT_EQ(mean.exitCode, 0) << mean.err;
  const auto s = nlohmann::json::parse(ReadText(dir / "s.json"));
  const auto m = nlohmann::json::parse(ReadText(dir / "m.json"));
  EXPECT_EQ(s["noise"]["variance"], "second render");
  EXPECT_LE(s["exact_fraction"].get<double>(), 0.35);
  EXPECT_GE(s["reference"]["psnr"].get<double>(), m["reference"]["psnr"].get<double>())
      << "dcm " << s["reference"].dump() << " vs mean of the renders " << m["reference"].dump();
  std::printf("dcm %.2f %% %.2f dB; mean of two renders %.2f dB\n", 100 * s["exact_fraction"].get<double>(),
              s["reference"]["psnr"].get<double>(), m["reference"]["psnr"].get<double>());
}

TEST(AovNoise, StatsAndVerboseSayWhetherTheRenderIsCloser) {
  // Issue 26: where dcm cannot be as close to the converged image as the
  // full render, -v and the stats say so. Clear-cut cases either way (the
  // estimates printed): noise of sd 0.05, where the render's noise costs
  // about 33 dB and dcm's denoised result shows none beyond it (estimated
  // +inf), and noise of sd 0.00005 with a budget of 6 %, where the render's
  // costs about 94 dB and dcm's interpolation error about 71 dB.
  ScratchDir dir;
  const Scene sc{256, 256};
  for (float sigma : {kSigma, 0.00005f}) {
    const bool noisy = sigma == kSigma;
    WriteExr(dir / "a.exr", sc.width, sc.height, NoisyChannels(sc, true, 5, sigma));
    WriteExr(dir / "b.exr", sc.width, sc.height, NoisyChannels(sc, true, 6, sigma));
    std::vector<std::string> args = {"reconstruct", dir / "a.exr", "--second-render", dir / "b.exr", "-o",
                                     dir / "out.exr", "--stats", dir / "s.json", "-v"};
    if (!noisy) args.insert(args.end(), {"--budget", "0.06"});
    const RunResult r = RunDcm(args, dir);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const auto s = nlohmann::json::parse(ReadText(dir / "s.json"));
    ASSERT_TRUE(s.contains("closer_than_render")) << s.dump();
    EXPECT_EQ(s["closer_than_render"].get<bool>(), noisy) << s.dump();
    // JSON has no infinity: an estimate of +inf (no error seen beyond the noise) is written as null.
    const double estimate = s["estimated_psnr"].is_null() ? HUGE_VAL : s["estimated_psnr"].get<double>();
    // The claim needs the lower end of the estimate's interval at or above the render's estimate.
    EXPECT_EQ(s["closer_than_render"].get<bool>(),
              s["estimated_psnr_low"].get<double>() >= s["estimated_render_psnr"].get<double>());
    std::printf("sd %g: estimated %.2f dB, the render %.2f dB\n", sigma, estimate,
                s["estimated_render_psnr"].get<double>());
    EXPECT_NE(r.err.find(noisy ? ": this result is closer" : ": the full render is closer, by"), std::string::npos)
        << r.err;
  }
}

TEST(AovNoise, ReconstructWithTheNoiseEstimatedBeatsTheNoisyRender) {
  // One noisy render and no variance channel: --estimate-variance. dcm must
  // come closer to the clean image than the render itself.
  ScratchDir dir;
  const Scene sc{256, 256};
  WriteExr(dir / "a.exr", sc.width, sc.height, NoisyChannels(sc, true, 7));
  std::vector<TestChannel> clean;
  for (int c = 0; c < 3; ++c)
    clean.push_back(Fill(std::string(1, "RGB"[c]), sc.width, sc.height, [&](int x, int y) { return sc.L(x, y)[c]; }));
  WriteExr(dir / "clean.exr", sc.width, sc.height, clean);
  const RunResult r = RunDcm({"reconstruct", dir / "a.exr", "--estimate-variance", "--reference", dir / "clean.exr",
                              "-o", dir / "out.exr", "--stats", dir / "s.json", "--quiet"},
                             dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const RunResult full = RunDcm({"reconstruct", dir / "a.exr", "--reference", dir / "clean.exr", "--full", "-o",
                                 dir / "full.exr", "--stats", dir / "f.json", "--quiet"},
                                dir);
  ASSERT_EQ(full.exitCode, 0) << full.err;
  const auto s = nlohmann::json::parse(ReadText(dir / "s.json"));
  const auto f = nlohmann::json::parse(ReadText(dir / "f.json"));
  EXPECT_LE(s["exact_fraction"].get<double>(), 0.35);
  EXPECT_GE(s["reference"]["psnr"].get<double>(), f["reference"]["psnr"].get<double>())
      << "dcm " << s["reference"].dump() << " vs the noisy render " << f["reference"].dump();
  // No goal given: noisy samples aim at the render's own estimated PSNR (--target-psnr render)
  // with at most 35 % of the pixels exact (issue 26's bound), searched from the default threshold.
  ASSERT_TRUE(s.contains("estimated_render_psnr")) << s.dump();
  EXPECT_EQ(s["quality"]["budget"].get<double>(), 0.35);
  EXPECT_EQ(s["estimated_psnr_against"], "converged");
  // The target is the render's estimate at the first draw, the reported one the last draw's: two
  // draws of the same noise, within the 1.5 dB the estimate promises (issue 22).
  EXPECT_NEAR(s["quality"]["target_psnr"].get<double>(), s["estimated_render_psnr"].get<double>(), 1.5);
  std::printf("dcm %.2f %% %.2f dB; noisy render %.2f dB\n", 100 * s["exact_fraction"].get<double>(),
              s["reference"]["psnr"].get<double>(), f["reference"]["psnr"].get<double>());
}

TEST(AovNoise, AStripTheDefaultsBoundDoesNotFitRunsWithoutIt) {
  // One row of 1000 noisy pixels: the default's 35 % bound cannot hold the
  // coarsest lattice and the validation. The default then runs without it
  // (as --target-psnr render) instead of failing on a --budget nobody gave.
  ScratchDir dir;
  const Scene sc{1000, 1};
  WriteExr(dir / "strip.exr", sc.width, sc.height, NoisyChannels(sc, false, 9));
  const RunResult r = RunDcm({"reconstruct", dir / "strip.exr", "--estimate-variance", "-o", dir / "out.exr",
                              "--stats", dir / "s.json", "-v"},
                             dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.err.find("the default's bound of 35 % does not fit this image"), std::string::npos) << r.err;
  const auto s = nlohmann::json::parse(ReadText(dir / "s.json"));
  EXPECT_TRUE(s["quality"]["budget"].is_null()) << s["quality"].dump();
  EXPECT_TRUE(s["quality"]["target_render"].get<bool>());
}

}  // namespace
}  // namespace dcm::aov::test
