// `dcm reconstruct` and `dcm plan` as a user runs them: the built binary on
// EXRs the tests write.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <tuple>

#include "common/metrics.h"
#include "common/sample_map.h"
#include "common/stats_json.h"
#include "engine_flags.h"
#include "test_util.h"

namespace dcm::aov::test {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
namespace fs = std::filesystem;

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

std::vector<RGB> SceneBeauty(const Scene& sc) {
  std::vector<RGB> v;
  for (int y = 0; y < sc.height; ++y)
    for (int x = 0; x < sc.width; ++x) v.push_back(sc.L(x, y));
  return v;
}

TEST(DcmReconstruct, DenseOutputsStatsAndMetrics) {
  ScratchDir dir;
  Scene sc{64, 48};
  WriteExr(dir / "in.exr", sc.width, sc.height, sc.GenericChannels(true));
  auto r = RunDcm({"reconstruct", dir / "in.exr", "-o", dir / "out.exr", "--stats", dir / "s.json",
                   "--sample-map", dir / "map.png", "--preview", dir / "prev.png", "--error-map",
                   dir / "err.png", "--threads", "2"},
                  dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("exact pixels"));  // the summary, on stdout

  int w = 0, h = 0;
  const auto out = ReadRgbExr(dir / "out.exr", &w, &h);
  ASSERT_EQ(w, 64);
  ASSERT_EQ(h, 48);
  auto in = OIIO::ImageInput::open(dir / "out.exr");
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().format, OIIO::TypeDesc::FLOAT);
  const float metaFraction = in->spec().get_float_attribute("dcm:exact_fraction", -1.f);
  EXPECT_THAT(in->spec().get_string_attribute("dcm:settings"), HasSubstr("\"object_test\""));
  in->close();

  const auto s = ReadJson(dir / "s.json");
  const int64_t exact = s["exact_pixels"], total = s["total_pixels"];
  EXPECT_EQ(total, 64 * 48);
  EXPECT_GT(exact, 0);
  EXPECT_LT(exact, total);
  EXPECT_DOUBLE_EQ(double(s["exact_fraction"]), double(exact) / double(total));
  EXPECT_FLOAT_EQ(metaFraction, float(double(exact) / double(total)));
  EXPECT_GE(double(s["time_s"]), 0.0);
  int64_t byReason = 0;
  for (const auto& [name, count] : s["by_reason"].items())
    if (name != "interpolated") byReason += int64_t(count);
  EXPECT_EQ(byReason, exact);
  EXPECT_EQ(s["mode"], "dense");
  EXPECT_TRUE(bool(s["used"]["split"]));
  EXPECT_TRUE(bool(s["capabilities"]["object_id"]));
  EXPECT_EQ(s["options"]["threads"], 2);

  // The reference error is that of the output against the full input,
  // recomputed here from the files.
  const auto ref = SceneBeauty(sc);
  const auto e = toolkit::Compare(out, ref, 64, 48);
  ASSERT_TRUE(s["reference"]["psnr"].is_number());
  EXPECT_NEAR(double(s["reference"]["psnr"]), e.psnr, 1e-9);
  EXPECT_NEAR(double(s["reference"]["rmse"]), e.rmse, 1e-12);
  EXPECT_NEAR(double(s["reference"]["relmse"]), e.relmse, 1e-12);
  // Wiring errors (a channel swapped, tau not applied, the wrong role) put the
  // error above 0.05 RMS; a working reconstruction of this smooth scene with
  // exact IDs is far below.
  EXPECT_LT(e.rmse, 0.05);
  // Exact pixels are exact.
  // The sample map (its top left 64x48 pixels, the legend below) marks
  // exactly `exact` pixels.
  auto map = OIIO::ImageInput::open(dir / "map.png");
  ASSERT_TRUE(map);
  const int mapWidth = map->spec().width;
  ASSERT_GE(mapWidth, 64);
  ASSERT_GT(map->spec().height, 48);
  std::vector<uint8_t> px(size_t(mapWidth) * size_t(map->spec().height) * 3);
  ASSERT_TRUE(map->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, px.data()));
  const auto gray = toolkit::ReasonColor(SampleReason::kInterpolated);
  int64_t marked = 0;
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 64; ++x) {
      const uint8_t* p = &px[(size_t(y) * size_t(mapWidth) + size_t(x)) * 3];
      marked += !(p[0] == gray[0] && p[1] == gray[1] && p[2] == gray[2]);
    }
  EXPECT_EQ(marked, exact);
  auto img = OIIO::ImageInput::open(dir / "prev.png");
  ASSERT_TRUE(img);
  EXPECT_EQ(img->spec().width, 64);
  EXPECT_EQ(img->spec().height, 48);
  img = OIIO::ImageInput::open(dir / "err.png");  // the map, its colour bar below
  ASSERT_TRUE(img);
  EXPECT_GE(img->spec().width, 64);
  EXPECT_GT(img->spec().height, 48);
  // Exactly the requested files, no temporaries.
  EXPECT_EQ(dir.Files(), (std::vector<std::string>{"err.png", "in.exr", "map.png", "out.exr", "prev.png", "s.json"}));
}

TEST(DcmReconstruct, FullEvaluationReproducesTheInput) {
  ScratchDir dir;
  Scene sc{32, 32};
  WriteExr(dir / "in.exr", 32, 32, sc.GenericChannels(false));
  auto r = RunDcm({"reconstruct", dir / "in.exr", "--full", "-o", dir / "out.exr", "--stats", dir / "s.json", "--quiet"}, dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(r.err, "") << "--quiet";
  const auto s = ReadJson(dir / "s.json");
  EXPECT_EQ(s["exact_fraction"], 1.0);
  EXPECT_TRUE(s["reference"]["psnr"].is_null()) << "identical: infinite PSNR";
  EXPECT_EQ(s["reference"]["rmse"], 0.0);
  EXPECT_EQ(ReadRgbExr(dir / "out.exr"), SceneBeauty(sc));
}

TEST(DcmReconstruct, DownsampleComparesAtOutputResolution) {
  ScratchDir dir;
  Scene sc{64, 64};
  WriteExr(dir / "in.exr", 64, 64, sc.GenericChannels(false));
  auto r = RunDcm({"reconstruct", dir / "in.exr", "--downsample", "2", "--full", "-o", dir / "out.exr",
                   "--stats", dir / "s.json", "--quiet"},
                  dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  int w = 0, h = 0;
  const auto out = ReadRgbExr(dir / "out.exr", &w, &h);
  EXPECT_EQ(w, 32);
  EXPECT_EQ(h, 32);
  const auto s = ReadJson(dir / "s.json");
  EXPECT_EQ(s["total_pixels"], 64 * 64);
  EXPECT_EQ(s["width"], 32);
  // Full evaluation, downsampled by the engine and by the tool's reference:
  // the same 2x2 means up to float summation order (RMSE below 1e-6).
  EXPECT_LT(double(s["reference"]["rmse"]), 1e-6);
}

// Supersampled input whose samples are not noisy has its own threshold,
// directions, thin-object test and crossing fill (ResolveSettings): the stats
// record the settings and whether the run used those rules (the options
// leave them unset), -v says which it uses and why, and the flags set them
// at every supersampling.
TEST(DcmReconstruct, SupersampledInputHasItsOwnDefaults) {
  ScratchDir dir;
  Scene sc{64, 64};
  auto ch = sc.GenericChannels(false);
  WriteExr(dir / "in.exr", 64, 64, ch);
  for (const char* c : {"var.R", "var.G", "var.B"}) ch.push_back(Fill(c, 64, 64, [](int, int) { return 1e-4f; }));
  WriteExr(dir / "noisy.exr", 64, 64, ch);
  auto run = [&](const std::string& input, std::vector<std::string> extra) {
    std::vector<std::string> args = {"reconstruct", dir / input, "-o", dir / "out.exr", "--stats", dir / "s.json", "-v"};
    args.insert(args.end(), extra.begin(), extra.end());
    const auto r = RunDcm(args, dir);
    EXPECT_EQ(r.exitCode, 0) << r.err;
    return std::pair(ReadJson(dir / "s.json"), r.err);
  };
  const ReconstructionOptions defaults;
  // dcm's settings at `downsample`, with noisy samples or not.
  auto resolved = [&](int downsample, bool noisy) {
    ReconstructionOptions o = defaults;
    o.downsample = downsample;
    ProviderCapabilities caps;
    caps.variance = noisy;
    return ResolveSettings(o, caps);
  };
  auto said = [](const ResolvedSettings& r, const std::string& why) {
    std::ostringstream s;
    s << "contrast " << ToString(r.contrastMetric) << ", threshold " << r.contrastThreshold << ", " << r.directions
      << " directions, thin-object test " << ToString(r.thinObjects) << ", crossing fill " << r.crossingFillReach
      << " (" << why << ")";
    return s.str();
  };
  const auto [final1, final1Err] = run("in.exr", {});
  EXPECT_FALSE(bool(final1["used"]["supersampled_rules"]));
  EXPECT_THAT(final1Err, HasSubstr(said(resolved(1, false), "final resolution")));
  // No shadow guide: the smooth blocks keep their centre probes.
  EXPECT_FALSE(bool(final1["capabilities"]["hard_shadows_guided"]));
  EXPECT_THAT(final1Err, HasSubstr("smooth blocks: centre-probe\n"));
  const auto [x2, x2Err] = run("in.exr", {"--downsample", "2"});
  EXPECT_TRUE(bool(x2["used"]["supersampled_rules"]));
  const ResolvedSettings ss = resolved(2, false);
  EXPECT_THAT(x2Err, HasSubstr(said(ss, "supersampled rules: --downsample 2")));
  for (const char* f : {"elementary_block", "contrast_threshold", "contrast_metric", "directions", "thin_objects"})
    EXPECT_TRUE(x2["options"][f].is_null()) << f << ": unset, the regime's default";
  EXPECT_FLOAT_EQ(float(x2["settings"]["contrast_threshold"]), ss.contrastThreshold);
  EXPECT_EQ(x2["settings"]["thin_objects"], std::string(ToString(ss.thinObjects)));
  EXPECT_EQ(x2["settings"]["contrast_metric"], std::string(ToString(ss.contrastMetric)));
  EXPECT_NE(x2["settings"]["contrast_metric"], final1["settings"]["contrast_metric"]);
  EXPECT_EQ(x2["settings"]["directions"], ss.directions);
  EXPECT_NE(x2["settings"]["directions"], final1["settings"]["directions"]);
  EXPECT_EQ(x2["options"]["crossing_fill_reach"], defaults.crossingFillReach);
  EXPECT_EQ(x2["settings"]["crossing_fill_reach"], defaults.crossingFillReach);
  // Noisy samples (a variance channel): the noise regime's settings.
  const auto [noisy, noisyErr] = run("noisy.exr", {"--downsample", "2"});
  EXPECT_FALSE(bool(noisy["used"]["supersampled_rules"]));
  EXPECT_EQ(noisy["crossings_filled"], 0);
  EXPECT_THAT(noisyErr, HasSubstr(said(resolved(2, true), "noisy samples: the supersampled rules are off")));
  // The flags set both regimes.
  const auto [set, setErr] =
      run("in.exr", {"--downsample", "2", "--threshold", "0.1", "--thin-test", "any-differs", "--crossing-fill", "0",
                     "--contrast", "display", "--directions", "4"});
  for (const char* part : {"options", "settings"}) {
    EXPECT_FLOAT_EQ(float(set[part]["contrast_threshold"]), 0.1f) << part;
    EXPECT_EQ(set[part]["thin_objects"], "any-differs") << part;
    EXPECT_EQ(set[part]["contrast_metric"], "display") << part;
    EXPECT_EQ(set[part]["directions"], 4) << part;
    EXPECT_EQ(set[part]["crossing_fill_reach"], 0) << part;
  }
  EXPECT_EQ(set["crossings_filled"], 0);
}

// `dcm bench` on an AOV input reads the guides as `dcm reconstruct` does,
// --highlight-level included: small sharp highlights off the lattice
// (AovProvider.HighlightGuideFindsHighlightsSmallerThanTheLattice) are found
// with the default level and missed with a level above the guide's values.
TEST(DcmBench, AovInputTakesTheHighlightLevel) {
  ScratchDir dir;
  const HighlightScene scene;
  std::vector<TestChannel> ch = scene.Channels();
  ch.push_back(scene.Guide());
  WriteExr(dir / "guided.exr", scene.size, scene.size, ch);
  // The PSNR of dcm's point at threshold 0.14 in the bench's CSV.
  auto psnr = [&](const std::string& out, std::vector<std::string> extra) {
    std::vector<std::string> args = {"bench", dir / "guided.exr", "--quick", "--no-plots", "--thresholds", "0.14",
                                     "--quiet", "--out", dir / out};
    args.insert(args.end(), extra.begin(), extra.end());
    const auto r = RunDcm(args, dir);
    EXPECT_EQ(r.exitCode, 0) << r.err;
    const std::string csvPath = std::string(dir / out) + "/bench.csv";
    std::ifstream csv(csvPath);
    std::string line;
    std::getline(csv, line);
    std::vector<std::string> header;
    std::stringstream hs(line);
    for (std::string f; std::getline(hs, f, ',');) header.push_back(f);
    const size_t column = size_t(std::find(header.begin(), header.end(), "psnr_db") - header.begin());
    while (std::getline(csv, line)) {
      std::vector<std::string> fields;
      std::stringstream ls(line);
      for (std::string f; std::getline(ls, f, ',');) fields.push_back(f);
      if (fields.size() > column && fields[3] == "dcm t=0.14") return std::stod(fields[column]);
    }
    ADD_FAILURE() << "no point 'dcm t=0.14' in " << csvPath;
    return 0.0;
  };
  const double found = psnr("found", {}), missed = psnr("missed", {"--highlight-level", "10"});
  std::printf("highlights: %.2f dB found, %.2f dB missed\n", found, missed);
  // Found, every pixel is right (measured: infinite PSNR); missed, the 3x2
  // highlights (3.0 on 0.4) of 1/3 of the 16x16 cells are interpolated over
  // (30.6 dB). 10 dB between them is asked.
  EXPECT_GT(found, missed + 10) << "found " << found << " dB, missed " << missed << " dB";
  EXPECT_NE(RunDcm({"bench", dir / "guided.exr", "--highlight-level", "-1", "--out", dir / "bad"}, dir).exitCode, 0);
}

TEST(DcmReconstruct, VerboseSaysWhichTestsAreOff) {
  ScratchDir dir;
  Scene sc{16, 16};
  auto ch = sc.GenericChannels(false);
  WriteExr(dir / "beauty.exr", 16, 16, {ch[2], ch[3], ch[4]});
  auto r = RunDcm({"reconstruct", dir / "beauty.exr", "-o", dir / "out.exr", "-v"}, dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("contrast only"));
  EXPECT_THAT(r.err, HasSubstr("no tau: the texture split is off"));
}

TEST(DcmReconstruct, StatsHaveTheTimePerStageAndTheResolvedSettings) {
  ScratchDir dir;
  Scene sc{64, 48};
  WriteExr(dir / "in.exr", sc.width, sc.height, sc.GenericChannels(true));
  auto r = RunDcm({"reconstruct", dir / "in.exr", "-o", dir / "out.exr", "--stats", dir / "s.json", "-v",
                   "--downsample", "2"},
                  dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto s = ReadJson(dir / "s.json");
  // Every stage, each timed apart, the provider's time excluded: together
  // at most the engine time (the level loop between stages is not counted).
  const std::set<std::string> stages = {"surfaces", "refinement",    "borders",   "directions", "simple_complex",
                                        "lazy",     "finest",        "interpolation", "denoising", "output"};
  ASSERT_TRUE(s["stage_times_s"].is_object());
  std::set<std::string> reported;
  double sum = 0;
  for (const auto& [name, seconds] : s["stage_times_s"].items()) {
    reported.insert(name);
    ASSERT_TRUE(seconds.is_number()) << name;
    EXPECT_GE(double(seconds), 0.0) << name;
    sum += double(seconds);
  }
  EXPECT_EQ(reported, stages);
  EXPECT_GT(sum, 0.0);
  EXPECT_LE(sum, double(s["time_s"]));
  // The settings the stages used: the supersampled input (--downsample 2,
  // no variance) takes the supersampled rules' contrast threshold.
  ASSERT_TRUE(bool(s["used"]["supersampled_rules"]));
  ReconstructionOptions x2;
  x2.downsample = 2;
  const ResolvedSettings expected = ResolveSettings(x2, ProviderCapabilities{});
  EXPECT_EQ(float(double(s["settings"]["contrast_threshold"])), expected.contrastThreshold);  // written as the short decimal
  EXPECT_EQ(s["settings"]["directions"], expected.directions);
  EXPECT_FALSE(bool(s["settings"]["noisy"]));
  EXPECT_FALSE(s["settings"].contains("split"));  // "used" reports it
  EXPECT_THAT(r.err, HasSubstr("time per stage: surfaces "));
}

TEST(DcmReconstruct, PresetAndMapOnTheCommandLine) {
  ScratchDir dir;
  Scene sc{32, 16};
  std::vector<TestChannel> ch;
  ch.push_back(Fill("ViewLayer.IndexOB.X", 32, 16, [&](int x, int y) { return float(sc.ObjectId(x, y)); }));
  const char* comp[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    ch.push_back(Fill(std::string("ViewLayer.DiffCol.") + comp[c], 32, 16, [&](int x, int y) { return sc.Tau(x, y)[c]; }));
    ch.push_back(Fill(std::string("ViewLayer.DiffDir.") + comp[c], 32, 16, [&](int x, int y) { return sc.Li(x, y)[c]; }));
    ch.push_back(Fill(std::string("ViewLayer.DiffInd.") + comp[c], 32, 16, [](int, int) { return 0.f; }));
    ch.push_back(Fill(std::string("ViewLayer.Combined.") + comp[c], 32, 16, [&](int x, int y) { return sc.L(x, y)[c]; }));
  }
  ch.push_back(Fill("mat", 32, 16, [&](int x, int y) { return float(sc.ShaderId(x, y)); }));
  WriteExr(dir / "b.exr", 32, 16, ch);
  auto r = RunDcm({"reconstruct", dir / "b.exr", "--preset", "blender", "--map", "shader=mat", "-o",
                   dir / "out.exr", "--stats", dir / "s.json", "-v"},
                  dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("shader ID: channel 'mat'"));
  EXPECT_THAT(r.err, HasSubstr("Blender view layer 'ViewLayer'"));
  const auto s = ReadJson(dir / "s.json");
  EXPECT_TRUE(bool(s["capabilities"]["shader_id"]));
  EXPECT_TRUE(bool(s["capabilities"]["split_radiance"]));
  EXPECT_LT(double(s["reference"]["rmse"]), 0.05);  // see DenseOutputsStatsAndMetrics
}

/// The scripted renderer: renders the pixels of a plan list into a samples EXR.
void RenderList(const Scene& sc, bool split, const std::string& list, const std::string& out,
                std::set<std::pair<int, int>>* rendered) {
  const int w = sc.width, h = sc.height;
  std::vector<TestChannel> ch;
  const char* comp[3] = {"R", "G", "B"};
  auto zero = [&](const std::string& name) { return Fill(name, w, h, [](int, int) { return 0.f; }); };
  if (split) {
    for (int c = 0; c < 3; ++c) ch.push_back(zero(std::string("Li.") + comp[c]));
    for (int c = 0; c < 3; ++c) ch.push_back(zero(std::string("Lc.") + comp[c]));
  } else {
    for (int c = 0; c < 3; ++c) ch.push_back(zero(comp[c]));
  }
  ch.push_back(zero("mask"));
  std::istringstream in(ReadText(list));
  std::string line;
  int count = 0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    int x = -1, y = -1;
    std::istringstream(line) >> x >> y;
    ASSERT_TRUE(x >= 0 && x < w && y >= 0 && y < h) << line;
    EXPECT_TRUE(rendered->insert({x, y}).second) << "pixel asked for twice: " << line;
    const size_t i = size_t(y) * size_t(w) + size_t(x);
    for (int c = 0; c < 3; ++c) {
      if (split) {
        ch[size_t(c)].values[i] = sc.Li(x, y)[c];
        ch[size_t(3 + c)].values[i] = sc.Lc(x, y)[c];
      } else {
        ch[size_t(c)].values[i] = sc.L(x, y)[c];
      }
    }
    ch.back().values[i] = 1.f;
    ++count;
  }
  EXPECT_GT(count, 0);
  WriteExr(out, w, h, ch);
}

/// (texture split, supersampling): at 2x the supersampled rules add a round
/// (the crossings the fill could not take).
class PlanRoundTrip : public ::testing::TestWithParam<std::tuple<bool, int>> {};

TEST_P(PlanRoundTrip, SameImageAsDenseBitForBit) {
  const auto [split, supersampling] = GetParam();
  ScratchDir dir;
  Scene sc{72, 56};  // not a multiple of the 64-pixel tile: clipped tiles too
  // Both files carry a highlight guide (a 3x2 highlight between the lattice
  // lines): plan reads it from the guides as reconstruct does.
  const TestChannel highlight =
      Fill("highlight", sc.width, sc.height, [](int x, int y) { return x >= 21 && x <= 23 && y >= 9 && y <= 10 ? 3.f : 0.f; });
  auto denseChannels = sc.GenericChannels(split), guideChannels = sc.GenericChannels(split, /*guidesOnly=*/true);
  denseChannels.push_back(highlight);
  guideChannels.push_back(highlight);
  WriteExr(dir / "dense.exr", sc.width, sc.height, denseChannels);
  WriteExr(dir / "guides.exr", sc.width, sc.height, guideChannels);
  const std::vector<std::string> engine = {"--threads", "2", "--quiet", "--downsample", std::to_string(supersampling)};
  auto dense = engine;
  dense.insert(dense.begin(), {"reconstruct", dir / "dense.exr", "-o", dir / "dense_out.exr", "--stats", dir / "dense.json"});
  auto r = RunDcm(dense, dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;

  std::vector<std::string> samples;
  std::set<std::pair<int, int>> rendered;
  bool done = false;
  for (int round = 0; round < 64 && !done; ++round) {
    std::vector<std::string> plan = {"plan", dir / "guides.exr", "--list", dir / "next.txt", "--mask", dir / "next.exr"};
    for (const auto& s : samples) plan.insert(plan.end(), {"--samples", s});
    plan.insert(plan.end(), engine.begin(), engine.end());
    r = RunDcm(plan, dir);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    if (r.out == "done\n") {
      done = true;
      break;
    }
    ASSERT_THAT(r.out, HasSubstr("pending "));
    // The text list and the EXR mask name the same pixels.
    auto mask = OIIO::ImageInput::open(dir / "next.exr");
    ASSERT_TRUE(mask);
    std::vector<float> m(size_t(sc.width * sc.height));
    ASSERT_TRUE(mask->read_image(0, 0, 0, 1, OIIO::TypeDesc::FLOAT, m.data()));
    int64_t masked = 0;
    for (float v : m) masked += v > 0.f;
    EXPECT_EQ("pending " + std::to_string(masked) + "\n", r.out);
    EXPECT_THAT(ReadText(dir / "next.txt"), HasSubstr(split ? "Li.R,Li.G,Li.B,Lc.R" : "R,G,B,mask"));
    const std::string s = dir / ("samples_" + std::to_string(round) + ".exr");
    RenderList(sc, split, dir / "next.txt", s, &rendered);
    samples.push_back(s);
  }
  ASSERT_TRUE(done) << "plan did not finish in 64 rounds";

  std::vector<std::string> rec = {"reconstruct", dir / "guides.exr", "-o", dir / "sparse_out.exr", "--stats", dir / "sparse.json"};
  for (const auto& s : samples) rec.insert(rec.end(), {"--samples", s});
  rec.insert(rec.end(), engine.begin(), engine.end());
  r = RunDcm(rec, dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;

  const auto a = ReadRgbExr(dir / "dense_out.exr"), b = ReadRgbExr(dir / "sparse_out.exr");
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), size_t(sc.width * sc.height / (supersampling * supersampling)));
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(RGB)), 0) << "not bit-identical";
  const auto ds = ReadJson(dir / "dense.json"), ss = ReadJson(dir / "sparse.json");
  EXPECT_EQ(ds["exact_pixels"], ss["exact_pixels"]);
  EXPECT_EQ(ss["mode"], "sparse");
  EXPECT_EQ(ds["crossings_filled"], ss["crossings_filled"]);
  EXPECT_EQ(bool(ds["used"]["supersampled_rules"]), supersampling >= 2);
  // At 2x the fill is exercised (measured: 10 crossings beauty, 8 split).
  if (supersampling >= 2) {
    EXPECT_GT(int64_t(ds["crossings_filled"]), 0);
  }
  std::printf("plan round trip: %lld exact pixels, %lld crossings filled\n", (long long)int64_t(ds["exact_pixels"]),
              (long long)int64_t(ds["crossings_filled"]));
  // The renderer rendered exactly the exact pixels, each once.
  EXPECT_EQ(int64_t(rendered.size()), int64_t(ds["exact_pixels"]));
}

INSTANTIATE_TEST_SUITE_P(BeautyAndSplit, PlanRoundTrip, ::testing::Combine(::testing::Bool(), ::testing::Values(1, 2)),
                         [](const auto& p) {
                           return std::string(std::get<0>(p.param) ? "Split" : "Beauty") + "_x" +
                                  std::to_string(std::get<1>(p.param));
                         });

// --target-psnr or --budget through `dcm plan` rounds: the validation pixels,
// then each run of the search, are asked for as the engine's own samples are;
// the result is the dense run's, bit for bit, with the same estimate, and
// keeps every pixel rendered (the budget's refused runs' too).
class DcmPlanGoal : public ::testing::TestWithParam<const char*> {};

TEST_P(DcmPlanGoal, RoundTripMatchesDense) {
  ScratchDir dir;
  Scene sc{72, 56};
  WriteExr(dir / "dense.exr", sc.width, sc.height, sc.GenericChannels(false));
  WriteExr(dir / "guides.exr", sc.width, sc.height, sc.GenericChannels(false, /*guidesOnly=*/true));
  const std::string goal = GetParam();
  const std::vector<std::string> engine = {"--threads", "2", "--quiet", goal.substr(0, goal.find(' ')),
                                           goal.substr(goal.find(' ') + 1)};
  auto dense = engine;
  dense.insert(dense.begin(), {"reconstruct", dir / "dense.exr", "-o", dir / "dense_out.exr", "--stats", dir / "dense.json"});
  auto r = RunDcm(dense, dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  std::vector<std::string> samples;
  std::set<std::pair<int, int>> rendered;
  bool done = false;
  for (int round = 0; round < 256 && !done; ++round) {
    std::vector<std::string> plan = {"plan", dir / "guides.exr", "--list", dir / "next.txt"};
    for (const auto& s : samples) plan.insert(plan.end(), {"--samples", s});
    plan.insert(plan.end(), engine.begin(), engine.end());
    r = RunDcm(plan, dir);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    done = r.out == "done\n";
    if (done) break;
    const std::string s = dir / ("samples_" + std::to_string(round) + ".exr");
    RenderList(sc, false, dir / "next.txt", s, &rendered);
    samples.push_back(s);
  }
  ASSERT_TRUE(done) << "plan did not finish in 256 rounds";
  std::printf("plan to a target: %zu rounds\n", samples.size());
  std::vector<std::string> rec = {"reconstruct", dir / "guides.exr", "-o", dir / "sparse_out.exr", "--stats", dir / "sparse.json"};
  for (const auto& s : samples) rec.insert(rec.end(), {"--samples", s});
  rec.insert(rec.end(), engine.begin(), engine.end());
  r = RunDcm(rec, dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto a = ReadRgbExr(dir / "dense_out.exr"), b = ReadRgbExr(dir / "sparse_out.exr");
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(RGB)), 0) << "not bit-identical";
  const auto ds = ReadJson(dir / "dense.json"), ss = ReadJson(dir / "sparse.json");
  EXPECT_EQ(ds["estimated_psnr"], ss["estimated_psnr"]);
  EXPECT_EQ(ds["quality"]["exact_pixels"], ss["quality"]["exact_pixels"]);
  // Every pixel rendered was needed: the plan asked for no more than the dense run evaluated.
  EXPECT_EQ(int64_t(rendered.size()), int64_t(ds["quality"]["exact_pixels"]));
  // And every one is exact in the result (noise-free samples).
  int64_t held = 0;
  for (const auto& [why, n] : ss["by_reason"].items())
    if (why != "interpolated" && why != "preview_stand_in") held += n.get<int64_t>();
  EXPECT_EQ(held, int64_t(rendered.size()));
  // The budget's search refuses runs part way: their pixels are among those kept.
  if (goal.rfind("--budget", 0) == 0) {
    EXPECT_GT(ss["by_reason"]["rendered"].get<int64_t>(), 0);
  }
}

INSTANTIATE_TEST_SUITE_P(Goals, DcmPlanGoal, ::testing::Values("--target-psnr 20", "--budget 0.3"),
                         [](const auto& p) { return std::string(p.param[2] == 't' ? "Target" : "Budget"); });

TEST(QualityLine, SaysWhereAFewValidationPixelsCarryTheEstimate) {
  using cli::EngineFlags;
  using cli::QualityLine;
  QualityReport r;
  r.estimate = {40.71, 37.95, 50.17, 1.6};
  r.targetPsnr = 40;
  r.runs = 3;
  EngineFlags f;
  f.targetPsnr = 40;
  EXPECT_THAT(QualityLine(r, f), HasSubstr("carried by 1.6 effective validation pixels"));
  r.estimate.effective = 12;  // enough for the interval's normal approximation
  EXPECT_THAT(QualityLine(r, f), Not(HasSubstr("effective")));
  r.estimate.effective = std::numeric_limits<double>::infinity();  // no error seen
  EXPECT_THAT(QualityLine(r, f), Not(HasSubstr("effective")));
  r.estimate.effective = 1.6;  // the preview's estimate sees every pixel
  r.estimateSource = EstimateSource::kPreview;
  EXPECT_THAT(QualityLine(r, f), Not(HasSubstr("effective")));
}

TEST(QualityLine, ClaimsCloserThanTheRenderOnlyWhereTheIntervalSaysSo) {
  // Issue 26's claim: the result is closer than the full render where the
  // lower end of its estimate's interval is at or above the render's
  // estimate; a point estimate above whose interval reaches below is no
  // claim (the held-out street's two renders: estimated 49.58 [47.64,
  // 53.17] against the render's 48.87, the truth 9 dB lower).
  using cli::EngineFlags;
  using cli::QualityLine;
  QualityReport r;
  r.againstConverged = true;
  r.renderEstimate = {48.87, 48.56, 49.20, HUGE_VAL};
  r.runs = 2;
  EngineFlags f;
  r.estimate = {49.58, 47.64, 53.17, 12.4};
  EXPECT_EQ(toolkit::CloserThanRender(r), false);
  EXPECT_THAT(QualityLine(r, f), HasSubstr("0.71 dB above the full render's, but its interval reaches below it: "
                                           "not shown to be closer"));
  r.estimate = {50.10, 48.90, 53.17, 12.4};
  EXPECT_EQ(toolkit::CloserThanRender(r), true);
  EXPECT_THAT(QualityLine(r, f), HasSubstr(": this result is closer, by 1.23 dB"));
  r.estimate = {47.00, 45.10, 49.50, 12.4};
  EXPECT_EQ(toolkit::CloserThanRender(r), false);
  EXPECT_THAT(QualityLine(r, f), HasSubstr(": the full render is closer, by 1.87 dB"));
  // No error seen beyond the noise: +inf, a claim only where the interval's lower end holds it.
  r.estimate = {HUGE_VAL, 49.00, HUGE_VAL, HUGE_VAL};
  EXPECT_THAT(QualityLine(r, f), HasSubstr(": this result is closer (its validation pixels show no error"));
  r.estimate = {HUGE_VAL, 40.00, HUGE_VAL, HUGE_VAL};
  EXPECT_THAT(QualityLine(r, f), HasSubstr("not shown to be closer"));
  // Against the full render itself (no variance) there is no such claim.
  r.againstConverged = false;
  EXPECT_FALSE(toolkit::CloserThanRender(r).has_value());
  EXPECT_THAT(QualityLine(r, f), Not(HasSubstr("closer")));
}

TEST(DcmReconstruct, TargetPsnrReportsTheEstimateBesideTheTruth) {
  ScratchDir dir;
  Scene sc{64, 48};
  WriteExr(dir / "in.exr", sc.width, sc.height, sc.GenericChannels(true));
  auto r = RunDcm({"reconstruct", dir / "in.exr", "-o", dir / "out.exr", "--stats", dir / "s.json", "--threads", "2",
                   "--target-psnr", "40", "-v"},
                  dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("estimated PSNR"));  // -v
  const auto s = ReadJson(dir / "s.json");
  ASSERT_TRUE(s.contains("estimated_psnr"));
  EXPECT_EQ(double(s["estimated_psnr_confidence"]), 0.9);
  // How many validation pixels carry it: null only where none saw an error.
  ASSERT_TRUE(s.contains("estimated_psnr_effective_pixels"));
  const auto& effective = s["estimated_psnr_effective_pixels"];
  if (!effective.is_null()) {
    EXPECT_GE(double(effective), 1.0);
  }
  // The quality line says where a few of them carry it.
  const bool few = !effective.is_null() && double(effective) < kFewEffectivePixels;
  EXPECT_EQ(r.err.find("effective validation pixels") != std::string::npos, few) << r.err;
  std::printf("target 40: estimate %s [%s, %s], true %s dB, reached %s\n", s["estimated_psnr"].dump().c_str(),
              s["estimated_psnr_low"].dump().c_str(), s["estimated_psnr_high"].dump().c_str(),
              s["reference"]["psnr"].dump().c_str(), s["quality"]["target_reached"].dump().c_str());
  // "Reached" says what the last draw's lower bound says (null: +infinity).
  const bool boundMeets = s["estimated_psnr_low"].is_null() || double(s["estimated_psnr_low"]) >= 40.0;
  EXPECT_EQ(bool(s["quality"]["target_reached"]), boundMeets);
  EXPECT_TRUE(bool(s["quality"]["confirmed"]));
  EXPECT_EQ(double(s["quality"]["target_psnr"]), 40.0);
  EXPECT_TRUE(s["quality"]["budget"].is_null());
  // The whole search's cost is the run's: every pixel evaluated, validation included.
  EXPECT_EQ(s["exact_pixels"], s["quality"]["exact_pixels"]);
  EXPECT_GT(int64_t(s["quality"]["validation_pixels"]), 0);
  // Dense input: the truth beside the estimate, and it meets the target.
  ASSERT_TRUE(s.contains("reference"));
  if (!s["reference"]["psnr"].is_null()) {
    EXPECT_GE(double(s["reference"]["psnr"]), 39.5);
  }
  auto in = OIIO::ImageInput::open(dir / "out.exr");
  ASSERT_TRUE(in);
  if (!s["estimated_psnr"].is_null()) {
    EXPECT_FLOAT_EQ(in->spec().get_float_attribute("dcm:estimated_psnr", -1.f), float(s["estimated_psnr"]));
  }
}

TEST(DcmReconstruct, TargetAndBudgetFlagsAreChecked) {
  ScratchDir dir;
  Scene sc{32, 32};
  WriteExr(dir / "in.exr", sc.width, sc.height, sc.GenericChannels(false));
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"--target-psnr", "0"}, "--target-psnr"},
      {{"--target-psnr", "120"}, "--target-psnr"},
      {{"--target-psnr", "rendered"}, "--target-psnr"},
      {{"--budget", "0"}, "--budget"},
      {{"--budget", "1.5"}, "--budget"},
      {{"--target-psnr", "40", "--threshold", "0.1"}, "--target-psnr: not with --threshold"},
      {{"--budget", "0.5", "--full"}, "--budget: not with --full"},
      {{"--budget", "0.5", "--tile", "0/2"}, "--target-psnr and --budget estimate the whole frame"},
  };
  for (const auto& [flags, message] : cases) {
    std::vector<std::string> args = {"reconstruct", dir / "in.exr", "-o", dir / "out.exr", "--quiet"};
    args.insert(args.end(), flags.begin(), flags.end());
    const auto r = RunDcm(args, dir);
    EXPECT_EQ(r.exitCode, 2) << flags.front() << ": " << r.err;
    EXPECT_THAT(r.err, HasSubstr(message));
    EXPECT_FALSE(fs::exists(dir / "out.exr"));
  }
  // --target-psnr render: the input carries no variance, so the render's own
  // error is unknown; an error (exit 1) naming the flag, nothing written.
  const auto r = RunDcm({"reconstruct", dir / "in.exr", "-o", dir / "out.exr", "--quiet", "--target-psnr", "render"}, dir);
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_THAT(r.err, HasSubstr("--target-psnr render"));
  EXPECT_FALSE(fs::exists(dir / "out.exr"));
}

// A farm's round trip: each tile plans and renders its own part (its window,
// halo included) until its plan is done; the tiles reconstructed from all the
// samples and merged are the dense frame, bit for bit.
TEST(PlanTiles, MergeToTheDenseImageBitForBit) {
  ScratchDir dir;
  Scene sc{96, 80};
  const bool split = true;
  WriteExr(dir / "dense.exr", sc.width, sc.height, sc.GenericChannels(split));
  WriteExr(dir / "guides.exr", sc.width, sc.height, sc.GenericChannels(split, /*guidesOnly=*/true));
  const std::vector<std::string> engine = {"--threads", "2", "--quiet"};
  auto with = [&](std::vector<std::string> args, const std::vector<std::string>& samples) {
    for (const auto& s : samples) args.insert(args.end(), {"--samples", s});
    args.insert(args.end(), engine.begin(), engine.end());
    return args;
  };
  auto r = RunDcm(with({"reconstruct", dir / "dense.exr", "-o", dir / "dense_out.exr", "--stats", dir / "dense.json"}, {}), dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;

  const int n = 4;
  std::vector<std::string> samples;
  std::set<std::pair<int, int>> rendered;  // RenderList fails on a pixel asked for twice
  for (int t = 0; t < n; ++t) {
    const std::string tile = std::to_string(t) + "/" + std::to_string(n);
    bool done = false;
    for (int round = 0; round < 64 && !done; ++round) {
      const std::string stats = dir / "plan.json";
      r = RunDcm(with({"plan", dir / "guides.exr", "--tile", tile, "--list", dir / "next.txt", "--stats", stats}, samples),
                 dir);
      ASSERT_EQ(r.exitCode, 0) << r.err;
      const auto j = ReadJson(stats);
      EXPECT_EQ(j["part"]["tile"], tile);
      if (r.out == "done\n") {
        done = true;
        EXPECT_TRUE(j["part"].contains("window_stats"));
        break;
      }
      // Every pixel asked for lies in the tile's window.
      const auto& w = j["part"]["window"];  // x, y, width, height
      std::istringstream in(ReadText(dir / "next.txt"));
      std::string line;
      while (std::getline(in, line)) {
        if (line.empty() || line[0] == '#') continue;
        int x = -1, y = -1;
        std::istringstream(line) >> x >> y;
        EXPECT_TRUE(x >= int(w[0]) && x < int(w[0]) + int(w[2]) && y >= int(w[1]) && y < int(w[1]) + int(w[3]))
            << "tile " << tile << ": pixel " << line << " outside its window";
      }
      const std::string s = dir / ("samples_" + std::to_string(t) + "_" + std::to_string(round) + ".exr");
      RenderList(sc, split, dir / "next.txt", s, &rendered);
      samples.push_back(s);
    }
    ASSERT_TRUE(done) << "tile " << tile << ": plan did not finish in 64 rounds";
  }
  std::vector<std::string> merge = {"merge", "-o", dir / "merged.exr", "--quiet"};
  for (int t = 0; t < n; ++t) {
    const std::string part = dir / ("part_" + std::to_string(t) + ".exr");
    r = RunDcm(with({"reconstruct", dir / "guides.exr", "--tile", std::to_string(t) + "/" + std::to_string(n), "-o", part},
                    samples),
               dir);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    merge.push_back(part);
  }
  r = RunDcm(merge, dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto a = ReadRgbExr(dir / "dense_out.exr"), b = ReadRgbExr(dir / "merged.exr");
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(RGB)), 0) << "not bit-identical";
  // Windows overlap by their halo: the tiles render at least the frame's
  // exact pixels, and the halos add some.
  EXPECT_GE(int64_t(rendered.size()), int64_t(ReadJson(dir / "dense.json")["exact_pixels"]));
}

TEST(PlanTiles, FramesExpandEveryName) {
  ScratchDir dir;
  Scene sc{32, 32};
  for (int frame : {3, 4})
    WriteExr(dir / ("guides." + std::to_string(frame) + ".exr"), 32, 32, sc.GenericChannels(false, true));
  auto r = RunDcm({"plan", dir / "guides.#.exr", "--frames", "3-4", "--list", dir / "next.#.txt", "--quiet"}, dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const std::string first = r.out.substr(0, r.out.find('\n') + 1);
  EXPECT_THAT(first, HasSubstr("pending "));
  EXPECT_EQ(r.out, first + first) << "one line per frame, the same plan for the same guides";
  EXPECT_TRUE(fs::exists(dir / "next.3.txt"));
  EXPECT_TRUE(fs::exists(dir / "next.4.txt"));
  EXPECT_EQ(ReadText(dir / "next.3.txt"), ReadText(dir / "next.4.txt"));
  // Without a pattern, --frames is a usage error (exit 2) that says so.
  r = RunDcm({"plan", dir / "guides.3.exr", "--frames", "3-4", "--list", dir / "x.txt"}, dir);
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_THAT(r.err, HasSubstr("frame pattern"));
  EXPECT_FALSE(fs::exists(dir / "x.txt"));
}

TEST(DcmReconstruct, IncompleteSamplesAskForPlan) {
  ScratchDir dir;
  Scene sc{32, 32};
  WriteExr(dir / "guides.exr", 32, 32, sc.GenericChannels(false, true));
  auto all = sc.GenericChannels(false);
  WriteExr(dir / "s.exr", 32, 32, {all[2], all[3], all[4], Fill("mask", 32, 32, [](int x, int) { return x < 3 ? 1.f : 0.f; })});
  auto r = RunDcm({"reconstruct", dir / "guides.exr", "--samples", dir / "s.exr", "-o", dir / "out.exr"}, dir);
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_THAT(r.err, HasSubstr("dcm plan"));
  EXPECT_FALSE(fs::exists(dir / "out.exr"));
}

/// Bad input: exit code 1, a message naming the file (and channel), and no
/// output file of any kind left behind.
struct BadCase {
  const char* name;
  std::function<void(const ScratchDir&)> make;
  std::vector<std::string> extraArgs;
  std::vector<std::string> messageParts;
};

class BadInput : public ::testing::TestWithParam<int> {};

std::vector<BadCase> BadCases() {
  Scene sc{16, 16};
  return {
      {"MissingFile", [](const ScratchDir&) {}, {}, {"in.exr': no such file"}},
      {"NotAnExr",
       [](const ScratchDir& d) {
         const std::vector<uint8_t> rgb(16 * 16 * 3, 128);
         auto out = OIIO::ImageOutput::create(d / "in.png");
         OIIO::ImageSpec spec(16, 16, 3, OIIO::TypeDesc::UINT8);
         out->open(d / "in.png", spec);
         out->write_image(OIIO::TypeDesc::UINT8, rgb.data());
         out->close();
         fs::rename(d / "in.png", d / "in.exr");
       },
       {},
       {"in.exr': not an OpenEXR file"}},
      {"TruncatedExr",
       [sc](const ScratchDir& d) {
         WriteExr(d / "in.exr", 64, 64, Scene{64, 64}.GenericChannels(false));
         fs::resize_file(d / "in.exr", fs::file_size(d / "in.exr") * 2 / 3);
       },
       {},
       {"in.exr", "truncated or corrupt"}},
      {"AbsentChannel",
       [sc](const ScratchDir& d) { WriteExr(d / "in.exr", 16, 16, sc.GenericChannels(false)); },
       {"--map", "id=objectid"},
       {"no channel 'objectid'", "in.exr", "shader"}},
      {"DifferentResolutions",
       [sc](const ScratchDir& d) {
         WriteExr(d / "in.exr", 16, 16, sc.GenericChannels(false));
         WriteExr(d / "in2.exr", 16, 12, {Fill("u", 16, 12, [](int, int) { return 0.f; })});
       },
       {"INPUT2"},
       {"different resolutions", "in2.exr' is 16x12"}},
      {"NonIntegerIds",
       [sc](const ScratchDir& d) {
         auto ch = sc.GenericChannels(false);
         ch[0].values[17] = 1.25f;
         WriteExr(d / "in.exr", 16, 16, ch);
       },
       {},
       {"in.exr", "channel 'id'", "non-integer ID 1.25"}},
      {"AbsurdDimensions", [](const ScratchDir& d) { MakeHugeExr(d / "in.exr", 100000); }, {}, {"in.exr", "100000x100000"}},
      {"NonFiniteHighlightGuide",
       [sc](const ScratchDir& d) {
         auto ch = sc.GenericChannels(false);
         ch.push_back(Fill("highlight", 16, 16, [](int x, int y) { return x == 3 && y == 4 ? NAN : 0.f; }));
         WriteExr(d / "in.exr", 16, 16, ch);
       },
       {},
       {"highlight guide 'highlight'", "in.exr", "(3, 4)"}},
      {"BadSamplesFile",
       [sc](const ScratchDir& d) {
         WriteExr(d / "in.exr", 16, 16, sc.GenericChannels(false, true));
         WriteExr(d / "samples.exr", 16, 16, {Fill("R", 16, 16, [](int, int) { return 0.f; })});
       },
       {"--samples", "SAMPLES"},
       {"samples.exr", "mask"}},
  };
}

TEST_P(BadInput, FailsCleanly) {
  const BadCase c = BadCases()[size_t(GetParam())];
  ScratchDir dir;
  c.make(dir);
  const auto before = dir.Files();
  std::vector<std::string> args = {"reconstruct", dir / "in.exr"};
  for (const auto& a : c.extraArgs)
    args.push_back(a == "INPUT2" ? dir / "in2.exr" : a == "SAMPLES" ? dir / "samples.exr" : a);
  args.insert(args.end(), {"-o", dir / "out.exr", "--stats", dir / "s.json", "--sample-map", dir / "m.png",
                           "--preview", dir / "p.png"});
  auto r = RunDcm(args, dir);
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_THAT(r.err, HasSubstr("dcm reconstruct: error: "));
  for (const auto& part : c.messageParts) EXPECT_THAT(r.err, HasSubstr(part));
  EXPECT_EQ(dir.Files(), before) << "an output or temporary file was left behind";
}

INSTANTIATE_TEST_SUITE_P(Cases, BadInput, ::testing::Range(0, int(BadCases().size())),
                         [](const auto& p) { return std::string(BadCases()[size_t(p.param)].name); });

TEST(DcmReconstruct, NonFiniteSamplesAreReportedAndNotSpread) {
  ScratchDir dir;
  Scene sc{48, 48};
  auto ch = sc.GenericChannels(false);
  // A NaN on a lattice corner (always evaluated) and an Inf and a negative
  // value elsewhere.
  ch[2].values[size_t(8 * 48 + 8)] = std::numeric_limits<float>::quiet_NaN();
  ch[3].values[size_t(20 * 48 + 30)] = std::numeric_limits<float>::infinity();
  ch[4].values[size_t(40 * 48 + 5)] = -1.f;
  WriteExr(dir / "in.exr", 48, 48, ch);
  auto r = RunDcm({"reconstruct", dir / "in.exr", "-o", dir / "out.exr", "--stats", dir / "s.json"}, dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("channel 'R': 1 NaN/Inf"));
  EXPECT_THAT(r.err, HasSubstr("channel 'G': 1 NaN/Inf"));
  EXPECT_THAT(r.err, HasSubstr("channel 'B': 1 negative"));
  const auto out = ReadRgbExr(dir / "out.exr");
  std::set<size_t> nonFinite;
  for (size_t i = 0; i < out.size(); ++i)
    if (!IsFinite(out[i])) nonFinite.insert(i);
  EXPECT_TRUE(nonFinite.count(8 * 48 + 8)) << "the NaN corner stays in its pixel";
  for (size_t i : nonFinite) EXPECT_TRUE(i == 8 * 48 + 8 || i == 20 * 48 + 30) << "spread to pixel " << i;
  const auto s = ReadJson(dir / "s.json");
  EXPECT_GE(int64_t(s["non_finite_samples"]), 1);
  EXPECT_EQ(s["reference"]["non_finite_pixels"], int64_t(nonFinite.size()));
}

TEST(DcmReconstruct, UsageErrorsExitWith2) {
  ScratchDir dir;
  Scene sc{16, 16};
  WriteExr(dir / "in.exr", 16, 16, sc.GenericChannels(false));
  const std::vector<std::vector<std::string>> cases = {
      {"reconstruct", dir / "in.exr", "--preset", "maya", "-o", dir / "out.exr"},
      {"reconstruct", dir / "in.exr", "--map", "idchannel", "-o", dir / "out.exr"},
      {"reconstruct", dir / "in.exr", "--map", "colour=R", "-o", dir / "out.exr"},
      {"reconstruct", dir / "in.exr", "--block", "6", "-o", dir / "out.exr"},
      {"reconstruct", dir / "in.exr"},
      {"plan", dir / "in.exr"},
  };
  for (const auto& args : cases) {
    auto r = RunDcm(args, dir);
    EXPECT_EQ(r.exitCode, 2) << args[2] << ": " << r.err;
    EXPECT_FALSE(fs::exists(dir / "out.exr"));
  }
}

TEST(DcmReconstruct, UnwritableOutputLeavesNothing) {
  ScratchDir dir;
  Scene sc{16, 16};
  WriteExr(dir / "in.exr", 16, 16, sc.GenericChannels(false));
  // The EXR can be written, the stats cannot: the EXR goes again.
  auto r = RunDcm({"reconstruct", dir / "in.exr", "-o", dir / "out.exr", "--stats", dir / "nodir/s.json"}, dir);
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_THAT(r.err, HasSubstr("nodir/s.json"));
  EXPECT_EQ(dir.Files(), std::vector<std::string>{"in.exr"});
}

}  // namespace
}  // namespace dcm::aov::test

namespace dcm::aov::test {
namespace {

// --progressive writes a usable image after each refinement level; the last
// one is the result.
TEST(DcmReconstruct, ProgressiveWritesOneImagePerLevel) {
  ScratchDir dir;
  Scene sc{64, 48};
  WriteExr(dir / "in.exr", sc.width, sc.height, sc.GenericChannels(true));
  auto r = RunDcm({"reconstruct", dir / "in.exr", "-o", dir / "out.exr", "--block", "16", "--min-block", "4",
                   "--progressive", dir / "levels", "--quiet"},
                  dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  // Levels of 16, 8 and 4 pixels.
  for (int level = 0; level < 3; ++level)
    EXPECT_TRUE(std::filesystem::exists(dir / ("levels/level_" + std::to_string(level) + ".exr"))) << level;
  EXPECT_FALSE(std::filesystem::exists(dir / "levels/level_3.exr"));
  EXPECT_EQ(ReadRgbExr(dir / "levels/level_2.exr"), ReadRgbExr(dir / "out.exr"));
}

TEST(DcmReconstruct, TextureMapJson) {
  // --texture MAP.json binds shaders to texture files like repeated
  // --texture SHADER=FILE (relative files from the JSON's folder): the same
  // image. Bad maps name the file and the key.
  ScratchDir dir;
  std::vector<TestChannel> tex;
  for (int c = 0; c < 3; ++c)
    tex.push_back(Fill(std::string(1, "RGB"[c]), 4, 4, [c](int x, int y) { return 0.1f * float(x + y) + 0.3f * float(c); }));
  fs::create_directories(dir.path() / "maps");
  WriteExr(dir / "maps/wood.exr", 4, 4, tex);
  const int w = 32, h = 16;
  std::vector<TestChannel> ch;
  ch.push_back(Fill("id", w, h, [](int x, int) { return x < 16 ? 1.f : 2.f; }));
  ch.push_back(Fill("shader", w, h, [](int x, int) { return x < 16 ? 5.f : 6.f; }));
  ch.push_back(Fill("u", w, h, [](int x, int) { return float(x % 16) / 16.f; }));
  ch.push_back(Fill("v", w, h, [](int, int y) { return float(y) / 16.f; }));
  for (const char* c : {"Li.R", "Li.G", "Li.B"}) ch.push_back(Fill(c, w, h, [](int x, int y) { return 0.01f * float(x + y); }));
  for (const char* c : {"Lc.R", "Lc.G", "Lc.B"}) ch.push_back(Fill(c, w, h, [](int, int) { return 0.05f; }));
  WriteExr(dir / "uv.exr", w, h, ch);
  {
    std::ofstream(dir / "maps/textures.json") << R"({"5": "wood.exr"})";
  }
  auto a = RunDcm({"reconstruct", dir / "uv.exr", "--texture", "5=" + (dir / "maps/wood.exr"), "-o", dir / "a.exr",
                   "--quiet"},
                  dir);
  ASSERT_EQ(a.exitCode, 0) << a.err;
  auto b = RunDcm({"reconstruct", dir / "uv.exr", "--texture", dir / "maps/textures.json", "-o", dir / "b.exr", "--quiet"},
                  dir);
  ASSERT_EQ(b.exitCode, 0) << b.err;
  EXPECT_EQ(ReadRgbExr(dir / "a.exr"), ReadRgbExr(dir / "b.exr"));

  const std::pair<std::string, std::string> bad[] = {
      {R"(["wood.exr"])", "expected an object of SHADER: FILE pairs"},
      {R"({"5": 7})", "\"5\": expected a texture file name"},
      {R"({"5": )", "not JSON"},
  };
  for (const auto& [text, message] : bad) {
    std::ofstream(dir / "maps/bad.json") << text;
    auto r = RunDcm({"reconstruct", dir / "uv.exr", "--texture", dir / "maps/bad.json", "-o", dir / "c.exr", "--quiet"},
                    dir);
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_THAT(r.err, HasSubstr("--texture '" + (dir / "maps/bad.json") + "': " + message));
    EXPECT_FALSE(fs::exists(dir / "c.exr"));
  }
}

}  // namespace
}  // namespace dcm::aov::test
