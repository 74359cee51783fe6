// The output EXR of `dcm reconstruct` keeps the input's layout: the beauty
// under its own names, the alpha, the other passes, the metadata; stored as
// -d, --compression and --ch say.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cstring>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>

#include "test_util.h"

namespace dcm::aov::test {
namespace {

using ::testing::UnorderedElementsAre;
using ::testing::HasSubstr;

/// A Blender multilayer EXR of Scene: the passes the preset reads, the
/// Combined's alpha, a half pass and an integer pass it does not read, and
/// Blender-like metadata.
void WriteBlenderInput(const std::string& path, const Scene& sc) {
  const int w = sc.width, h = sc.height;
  std::vector<TestChannel> ch;
  ch.push_back(Fill("ViewLayer.IndexOB.X", w, h, [&](int x, int y) { return float(sc.ObjectId(x, y)); }));
  const char* comp[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    ch.push_back(Fill(std::string("ViewLayer.DiffCol.") + comp[c], w, h, [&](int x, int y) { return sc.Tau(x, y)[c]; }));
    ch.push_back(Fill(std::string("ViewLayer.DiffDir.") + comp[c], w, h, [&](int x, int y) { return sc.Li(x, y)[c]; }));
    ch.push_back(Fill(std::string("ViewLayer.DiffInd.") + comp[c], w, h, [](int, int) { return 0.f; }));
    ch.push_back(Fill(std::string("ViewLayer.Combined.") + comp[c], w, h, [&](int x, int y) { return sc.L(x, y)[c]; }));
  }
  // Coverage that varies (an antialiased silhouette's would).
  ch.push_back(Fill("ViewLayer.Combined.A", w, h, [](int x, int y) { return float((x * 7 + y * 3) % 11) / 10.f; }));
  TestChannel depth = Fill("ViewLayer.Depth.Z", w, h, [](int x, int y) { return 1.f + 0.25f * float(x + y); });
  depth.half = true;
  ch.push_back(depth);
  TestChannel ids{"ViewLayer.Custom.id", {}, {}, false};
  for (int i = 0; i < w * h; ++i) ids.ids.push_back(uint32_t(i) * 2654435761u);  // beyond float's 2^24
  ch.push_back(ids);
  WriteExr(path, w, h, ch,
           {{"Camera", "Camera.001"}, {"cycles.ViewLayer.samples", "128"}, {"studio:shot", "sh010"}});
}

struct Exr {
  OIIO::ImageSpec spec;
  std::vector<std::vector<float>> planes;  ///< per channel, as float
  std::vector<std::vector<uint32_t>> ids;  ///< per channel, UINT channels only
  std::vector<std::string> names() const { return spec.channelnames; }
  const std::vector<float>& Plane(const std::string& name) const {
    const int i = spec.channelindex(name);
    EXPECT_GE(i, 0) << name;
    return planes.at(size_t(std::max(i, 0)));
  }
};

Exr ReadExr(const std::string& path) {
  Exr e;
  auto in = OIIO::ImageInput::open(path);
  EXPECT_TRUE(in) << path;
  if (!in) return e;
  e.spec = in->spec();
  const size_t n = size_t(e.spec.width) * size_t(e.spec.height);
  for (int c = 0; c < e.spec.nchannels; ++c) {
    e.planes.emplace_back(n);
    e.ids.emplace_back();
    EXPECT_TRUE(in->read_image(0, 0, c, c + 1, OIIO::TypeDesc::FLOAT, e.planes.back().data()));
    if (e.spec.channelformat(c) == OIIO::TypeDesc::UINT) {
      e.ids.back().resize(n);
      EXPECT_TRUE(in->read_image(0, 0, c, c + 1, OIIO::TypeDesc::UINT, e.ids.back().data()));
    }
  }
  return e;
}

TEST(OutputLayout, BlenderInputKeepsItsLayoutPassesAndMetadata) {
  ScratchDir dir;
  Scene sc{32, 16};
  WriteBlenderInput(dir / "in.exr", sc);
  auto r = RunDcm({"reconstruct", dir / "in.exr", "--preset", "blender", "-o", dir / "out.exr", "-v"}, dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("alpha ViewLayer.Combined.A from the inputs"));
  const Exr in = ReadExr(dir / "in.exr"), out = ReadExr(dir / "out.exr");
  // Every input channel, in the input's order, with its stored type.
  ASSERT_EQ(out.names(), in.names());
  for (int c = 0; c < in.spec.nchannels; ++c)
    EXPECT_EQ(out.spec.channelformat(c), in.spec.channelformat(c) == OIIO::TypeDesc::UINT ? OIIO::TypeDesc::UINT
                                         : in.spec.channelformat(c) == OIIO::TypeDesc::HALF ? OIIO::TypeDesc::HALF
                                                                                            : OIIO::TypeDesc::FLOAT)
        << in.spec.channelnames[size_t(c)];
  EXPECT_EQ(out.spec.alpha_channel, out.spec.channelindex("ViewLayer.Combined.A"));
  // The passes and the alpha are the input's, bit for bit (dense mode: every
  // pixel of them is known; docs/OUTPUT.md).
  for (const auto& name : in.names()) {
    if (name.rfind("ViewLayer.Combined.", 0) == 0 && name != "ViewLayer.Combined.A") continue;
    EXPECT_EQ(out.Plane(name), in.Plane(name)) << name;
  }
  const int id = in.spec.channelindex("ViewLayer.Custom.id");
  EXPECT_EQ(out.ids.at(size_t(id)), in.ids.at(size_t(id)));
  // The beauty is the reconstruction: close to the input, not a copy of it
  // everywhere (the engine evaluated a few percent of the pixels).
  const auto& outR = out.Plane("ViewLayer.Combined.R");
  const auto& inR = in.Plane("ViewLayer.Combined.R");
  size_t differ = 0;
  for (size_t i = 0; i < outR.size(); ++i) differ += outR[i] != inR[i];
  EXPECT_GT(differ, 0u);
  // The metadata: the renderer's, and dcm's provenance.
  EXPECT_EQ(out.spec.get_string_attribute("Camera"), "Camera.001");
  EXPECT_EQ(out.spec.get_string_attribute("cycles.ViewLayer.samples"), "128");
  EXPECT_EQ(out.spec.get_string_attribute("studio:shot"), "sh010");
  EXPECT_EQ(out.spec.get_string_attribute("dcm:version"), DCM_VERSION);
  EXPECT_THAT(out.spec.get_string_attribute("dcm:command_line"), HasSubstr("reconstruct"));
  EXPECT_THAT(out.spec.get_string_attribute("dcm:command_line"), HasSubstr("--preset blender"));
  EXPECT_THAT(out.spec.get_string_attribute("dcm:settings"), HasSubstr("\"downsample\":1"));
  EXPECT_EQ(out.spec.get_string_attribute("compression"), "zip");
}

TEST(OutputLayout, TypeCompressionAndChannels) {
  ScratchDir dir;
  Scene sc{32, 16};
  WriteBlenderInput(dir / "in.exr", sc);
  auto r = RunDcm({"reconstruct", dir / "in.exr", "--preset", "blender", "-o", dir / "half.exr", "-d", "half",
                   "--compression", "piz"},
                  dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const Exr half = ReadExr(dir / "half.exr");
  EXPECT_EQ(half.spec.get_string_attribute("compression"), "piz");
  // IDs keep their type: the UINT pass, and the float object IDs the
  // preset reads (a half holds integers up to 2048 only).
  for (int c = 0; c < half.spec.nchannels; ++c) {
    const std::string& name = half.spec.channelnames[size_t(c)];
    EXPECT_EQ(half.spec.channelformat(c), name == "ViewLayer.Custom.id"    ? OIIO::TypeDesc::UINT
                                          : name == "ViewLayer.IndexOB.X" ? OIIO::TypeDesc::FLOAT
                                                                           : OIIO::TypeDesc::HALF)
        << name;
  }

  r = RunDcm({"reconstruct", dir / "in.exr", "--preset", "blender", "-o", dir / "ch.exr", "--ch",
              "ViewLayer.Combined.A,ViewLayer.Combined.R,ViewLayer.Depth.Z"},
             dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const Exr ch = ReadExr(dir / "ch.exr");
  // OpenEXR stores channels sorted by name: --ch chooses them, not their order.
  EXPECT_THAT(ch.names(),
              UnorderedElementsAre("ViewLayer.Combined.A", "ViewLayer.Combined.R", "ViewLayer.Depth.Z"));
}

TEST(OutputLayout, BadFormatValuesAreUsageErrors) {
  ScratchDir dir;
  Scene sc{32, 16};
  WriteBlenderInput(dir / "in.exr", sc);
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"-d", "double"}, "-d double"},
      {{"--compression", "zip9"}, "--compression zip9"},
      {{"--ch", "ViewLayer.Combined.R,Nope"}, "--ch Nope"},
  };
  for (const auto& [flags, message] : cases) {
    std::vector<std::string> args = {"reconstruct", dir / "in.exr", "--preset", "blender", "-o", dir / "out.exr"};
    args.insert(args.end(), flags.begin(), flags.end());
    auto r = RunDcm(args, dir);
    EXPECT_EQ(r.exitCode, 2) << message << ": " << r.err;
    EXPECT_THAT(r.err, HasSubstr(message));
    EXPECT_FALSE(std::filesystem::exists(dir / "out.exr")) << message;
  }
}

TEST(OutputLayout, GenericAlpha) {
  ScratchDir dir;
  Scene sc{32, 16};
  auto ch = sc.GenericChannels(false);
  WriteExr(dir / "rgb.exr", sc.width, sc.height, ch);
  ch.push_back(Fill("A", sc.width, sc.height, [](int x, int) { return float(x % 4) / 4.f; }));
  WriteExr(dir / "rgba.exr", sc.width, sc.height, ch);

  auto r = RunDcm({"reconstruct", dir / "rgb.exr", "-o", dir / "a1.exr", "--alpha"}, dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const Exr a1 = ReadExr(dir / "a1.exr");
  ASSERT_GE(a1.spec.channelindex("A"), 0);
  EXPECT_EQ(a1.spec.channelindex("A"), a1.spec.channelindex("B") + 1);
  for (float a : a1.Plane("A")) ASSERT_EQ(a, 1.f);

  r = RunDcm({"reconstruct", dir / "rgba.exr", "-o", dir / "a.exr"}, dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(ReadExr(dir / "a.exr").Plane("A"), ReadExr(dir / "rgba.exr").Plane("A"));

  r = RunDcm({"reconstruct", dir / "rgb.exr", "-o", dir / "none.exr"}, dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_LT(ReadExr(dir / "none.exr").spec.channelindex("A"), 0);
}

TEST(OutputLayout, TilesOfABlenderInputMergeToTheWholeOutput) {
  ScratchDir dir;
  Scene sc{32, 16};
  WriteBlenderInput(dir / "in.exr", sc);
  auto r = RunDcm({"reconstruct", dir / "in.exr", "--preset", "blender", "-o", dir / "whole.exr", "--quiet"}, dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  for (const auto& [tile, name] : {std::pair{"0/2", "t0.exr"}, std::pair{"1/2", "t1.exr"}}) {
    r = RunDcm({"reconstruct", dir / "in.exr", "--preset", "blender", "--tile", tile, "-o", dir / name, "--quiet"}, dir);
    ASSERT_EQ(r.exitCode, 0) << r.err;
  }
  r = RunDcm({"merge", dir / "t0.exr", dir / "t1.exr", "-o", dir / "m.exr", "--quiet"}, dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const Exr whole = ReadExr(dir / "whole.exr"), merged = ReadExr(dir / "m.exr");
  // The layout, the types, every channel's values (the UINT IDs beyond 2^24
  // too) and the renderer's metadata are the whole run's.
  ASSERT_EQ(merged.names(), whole.names());
  for (int c = 0; c < whole.spec.nchannels; ++c) {
    EXPECT_EQ(merged.spec.channelformat(c), whole.spec.channelformat(c)) << whole.names()[size_t(c)];
    EXPECT_EQ(merged.planes[size_t(c)], whole.planes[size_t(c)]) << whole.names()[size_t(c)];
    EXPECT_EQ(merged.ids[size_t(c)], whole.ids[size_t(c)]) << whole.names()[size_t(c)];
  }
  EXPECT_EQ(merged.spec.alpha_channel, merged.spec.channelindex("ViewLayer.Combined.A"));
  EXPECT_EQ(merged.spec.get_string_attribute("Camera"), "Camera.001");
  EXPECT_EQ(merged.spec.get_string_attribute("studio:shot"), "sh010");
  EXPECT_EQ(merged.spec.get_string_attribute("dcm:raw_channels"), "") << "a part's bookkeeping stays in the parts";
}

TEST(OutputLayout, PartsTakeTheFormatFromMerge) {
  ScratchDir dir;
  Scene sc{32, 16};
  WriteExr(dir / "in.exr", sc.width, sc.height, sc.GenericChannels(false));
  auto r = RunDcm({"reconstruct", dir / "in.exr", "--tile", "0/2", "-o", dir / "t0.exr", "-d", "half"}, dir);
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_THAT(r.err, HasSubstr("give them to `dcm merge`"));
  for (const auto& [tile, name] : {std::pair{"0/2", "t0.exr"}, std::pair{"1/2", "t1.exr"}}) {
    r = RunDcm({"reconstruct", dir / "in.exr", "--tile", tile, "-o", dir / name, "--quiet"}, dir);
    ASSERT_EQ(r.exitCode, 0) << r.err;
  }
  r = RunDcm({"merge", dir / "t0.exr", dir / "t1.exr", "-o", dir / "m.exr", "--compression", "lzw"}, dir);
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_THAT(r.err, HasSubstr("--compression lzw"));
  r = RunDcm({"merge", dir / "t0.exr", dir / "t1.exr", "-o", dir / "m.exr", "-d", "half", "--compression", "piz",
              "--quiet"},
             dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const Exr m = ReadExr(dir / "m.exr");
  // The parts carry the input's passes; -d half stores the beauty as half
  // and leaves the IDs as they were (a part records them as raw).
  EXPECT_THAT(m.names(), UnorderedElementsAre("R", "G", "B", "id", "shader"));
  for (const char* c : {"R", "G", "B"}) EXPECT_EQ(m.spec.channelformat(m.spec.channelindex(c)), OIIO::TypeDesc::HALF) << c;
  for (const char* c : {"id", "shader"})
    EXPECT_EQ(m.spec.channelformat(m.spec.channelindex(c)), OIIO::TypeDesc::FLOAT) << c;
  EXPECT_EQ(m.spec.get_string_attribute("compression"), "piz");
}


/// The sparse round trip's scene: the generic beauty and guides, and passes
/// a renderer writes with the beauty: a depth (object ID x 10 plus a gentle
/// ramp), a half colour pass, an alpha, and a uint ID per pixel (beyond
/// float's 2^24: its bits must survive).
std::vector<TestChannel> SparseSceneChannels(const Scene& sc) {
  const int w = sc.width, h = sc.height;
  auto ch = sc.GenericChannels(false);
  ch.push_back(Fill("depth", w, h, [&](int x, int y) { return 10.f * float(sc.ObjectId(x, y)) + 0.01f * float(x + y); }));
  TestChannel diffuse = Fill("diffuse.R", w, h, [&](int x, int y) { return 0.5f * sc.L(x, y).r; });
  diffuse.half = true;
  ch.push_back(diffuse);
  ch.push_back(Fill("A", w, h, [&](int x, int y) { return sc.ObjectId(x, y) == sc.ObjectId(0, 0) ? 0.25f : 1.f; }));
  TestChannel ids{"pixel", {}, {}, false};
  for (int i = 0; i < w * h; ++i) ids.ids.push_back(uint32_t(i + 1) * 2654435761u);
  ch.push_back(ids);
  return ch;
}

/// The scripted renderer: every channel of `full` but the guides, at the
/// pixels of a plan list, and the mask.
void RenderPasses(const std::vector<TestChannel>& full, int w, int h, const std::string& list, const std::string& out,
                  std::set<int64_t>* rendered) {
  std::vector<TestChannel> ch;
  for (const auto& c : full) {
    if (c.name == "id" || c.name == "shader") continue;
    TestChannel z = c;
    std::fill(z.values.begin(), z.values.end(), 0.f);
    std::fill(z.ids.begin(), z.ids.end(), 0u);
    ch.push_back(z);
  }
  ch.push_back(Fill("mask", w, h, [](int, int) { return 0.f; }));
  std::istringstream in(ReadText(list));
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    int x = -1, y = -1;
    std::istringstream(line) >> x >> y;
    const size_t i = size_t(y) * size_t(w) + size_t(x);
    rendered->insert(int64_t(i));
    size_t k = 0;
    for (const auto& c : full) {
      if (c.name == "id" || c.name == "shader") continue;
      if (!c.ids.empty()) ch[k].ids[i] = c.ids[i];
      else ch[k].values[i] = c.values[i];
      ++k;
    }
    ch.back().values[i] = 1.f;
  }
  WriteExr(out, w, h, ch);
}

/// Plans rounds on `guides` (with `extra` flags, e.g. --tile) until done,
/// rendering each into a new samples file appended to `samples`.
void PlanUntilDone(const ScratchDir& dir, const std::vector<TestChannel>& full, const Scene& sc,
                   const std::vector<std::string>& extra, std::vector<std::string>* samples, std::set<int64_t>* rendered) {
  for (int round = 0; round < 64; ++round) {
    std::vector<std::string> plan = {"plan", dir / "guides.exr", "--list", dir / "next.txt", "--quiet"};
    for (const auto& s : *samples) plan.insert(plan.end(), {"--samples", s});
    plan.insert(plan.end(), extra.begin(), extra.end());
    auto r = RunDcm(plan, dir);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    if (r.out == "done\n") return;
    const std::string s = dir / ("samples_" + std::to_string(samples->size()) + ".exr");
    RenderPasses(full, sc.width, sc.height, dir / "next.txt", s, rendered);
    samples->push_back(s);
  }
  FAIL() << "plan did not finish in 64 rounds";
}

// Sparse mode (the `dcm plan` round trip): the passes the samples files
// carry are reconstructed with the beauty's interpolation record, the guides
// render's channels the samples lack are copied; the output has the dense
// run's channels and types, and at the exact pixels the input's bits (c).
TEST(OutputLayout, SparsePassesAreReconstructedWithTheBeautysInterpolation) {
  ScratchDir dir;
  Scene sc{72, 56};
  const auto full = SparseSceneChannels(sc);
  WriteExr(dir / "dense.exr", sc.width, sc.height, full);
  WriteExr(dir / "guides.exr", sc.width, sc.height, sc.GenericChannels(false, /*guidesOnly=*/true));
  std::vector<std::string> samples;
  std::set<int64_t> rendered;
  PlanUntilDone(dir, full, sc, {}, &samples, &rendered);
  ASSERT_FALSE(samples.empty());
  std::vector<std::string> rec = {"reconstruct", dir / "guides.exr", "-o", dir / "sparse.exr", "-v"};
  for (const auto& s : samples) rec.insert(rec.end(), {"--samples", s});
  auto r = RunDcm(rec, dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("alpha A reconstructed"));
  EXPECT_THAT(r.err, HasSubstr("2 passes copied, 3 reconstructed from the samples"));
  r = RunDcm({"reconstruct", dir / "dense.exr", "-o", dir / "dense_out.exr", "--quiet"}, dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;

  const Exr in = ReadExr(dir / "dense.exr"), dense = ReadExr(dir / "dense_out.exr"), sparse = ReadExr(dir / "sparse.exr");
  ASSERT_EQ(sparse.names(), dense.names());
  for (int c = 0; c < dense.spec.nchannels; ++c)
    EXPECT_EQ(sparse.spec.channelformat(c), dense.spec.channelformat(c)) << dense.names()[size_t(c)];
  // The beauty is the dense run's (PlanRoundTrip); the guides are copied.
  for (const char* name : {"R", "G", "B", "id", "shader"}) EXPECT_EQ(sparse.Plane(name), dense.Plane(name)) << name;

  const size_t n = size_t(sc.width) * size_t(sc.height);
  const int pixel = in.spec.channelindex("pixel");
  const auto& inIds = in.ids.at(size_t(pixel));
  const auto& outIds = sparse.ids.at(size_t(pixel));
  std::map<uint32_t, size_t> sourceOf;
  for (int64_t i : rendered) sourceOf[inIds[size_t(i)]] = size_t(i);
  int64_t interpolated = 0;
  for (size_t i = 0; i < n; ++i) {
    const int x = int(i % size_t(sc.width)), y = int(i / size_t(sc.width));
    if (rendered.count(int64_t(i))) {
      // Exact pixels: the renderer's values, bit for bit.
      for (const char* name : {"depth", "diffuse.R", "A"}) {
        const float a = in.Plane(name)[i], b = sparse.Plane(name)[i];
        ASSERT_EQ(std::memcmp(&a, &b, sizeof a), 0) << name << " at (" << x << "," << y << ")";
      }
      ASSERT_EQ(outIds[i], inIds[i]) << "(" << x << "," << y << ")";
      continue;
    }
    ++interpolated;
    // An ID: the value of one exact pixel on the same surface, never a blend.
    const auto src = sourceOf.find(outIds[i]);
    ASSERT_NE(src, sourceOf.end()) << "(" << x << "," << y << "): " << outIds[i] << " is no exact pixel's ID";
    const int sx = int(src->second % size_t(sc.width)), sy = int(src->second / size_t(sc.width));
    EXPECT_TRUE(sc.ObjectId(x, y) == sc.ObjectId(sx, sy) && sc.ShaderId(x, y) == sc.ShaderId(sx, sy))
        << "(" << x << "," << y << ") took the ID of (" << sx << "," << sy << ")";
    // Depth never across surfaces: objects lie 10 apart, the ramp changes
    // by 0.02 per pixel, so a value within 1 of the truth comes from the
    // pixel's own surface (the sources lie within one 16-pixel block).
    EXPECT_NEAR(sparse.Plane("depth")[i], in.Plane("depth")[i], 1.0) << "(" << x << "," << y << ")";
  }
  EXPECT_GT(interpolated, int64_t(n) / 2);

  // --ch: a pass chosen is the same; none chosen, none is reconstructed.
  for (const auto& [channels, name] : {std::pair{"R,G,B,depth", "ch.exr"}, std::pair{"R,G,B", "rgb.exr"}}) {
    auto ch = rec;
    ch[3] = dir / name;
    ch[4] = "--quiet";
    ch.insert(ch.end(), {"--ch", channels});
    r = RunDcm(ch, dir);
    ASSERT_EQ(r.exitCode, 0) << channels << ": " << r.err;
  }
  const Exr ch = ReadExr(dir / "ch.exr");
  EXPECT_THAT(ch.names(), ::testing::UnorderedElementsAre("R", "G", "B", "depth"));
  EXPECT_EQ(ch.Plane("depth"), sparse.Plane("depth"));
  EXPECT_EQ(ReadExr(dir / "rgb.exr").Plane("R"), sparse.Plane("R"));
}

// Sparse parts carry the reconstructed passes of their region: merged, they
// are the whole frame's output, every channel bit for bit.
TEST(OutputLayout, SparseTilesMergeToTheWholeOutput) {
  ScratchDir dir;
  Scene sc{96, 80};
  const auto full = SparseSceneChannels(sc);
  WriteExr(dir / "guides.exr", sc.width, sc.height, sc.GenericChannels(false, /*guidesOnly=*/true));
  std::vector<std::string> samples;
  std::set<int64_t> rendered;
  // The whole frame's rounds, then each tile's (its window's halo).
  PlanUntilDone(dir, full, sc, {}, &samples, &rendered);
  for (const char* tile : {"0/2", "1/2"}) PlanUntilDone(dir, full, sc, {"--tile", tile}, &samples, &rendered);
  auto with = [&](std::vector<std::string> args) {
    for (const auto& s : samples) args.insert(args.end(), {"--samples", s});
    args.push_back("--quiet");
    return args;
  };
  auto r = RunDcm(with({"reconstruct", dir / "guides.exr", "-o", dir / "whole.exr"}), dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  for (const auto& [tile, name] : {std::pair{"0/2", "t0.exr"}, std::pair{"1/2", "t1.exr"}}) {
    r = RunDcm(with({"reconstruct", dir / "guides.exr", "--tile", tile, "-o", dir / name}), dir);
    ASSERT_EQ(r.exitCode, 0) << r.err;
  }
  r = RunDcm({"merge", dir / "t0.exr", dir / "t1.exr", "-o", dir / "m.exr", "--quiet"}, dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const Exr whole = ReadExr(dir / "whole.exr"), merged = ReadExr(dir / "m.exr");
  ASSERT_EQ(merged.names(), whole.names());
  EXPECT_GE(whole.spec.channelindex("depth"), 0);
  for (int c = 0; c < whole.spec.nchannels; ++c) {
    EXPECT_EQ(merged.spec.channelformat(c), whole.spec.channelformat(c)) << whole.names()[size_t(c)];
    EXPECT_EQ(merged.planes[size_t(c)], whole.planes[size_t(c)]) << whole.names()[size_t(c)];
    EXPECT_EQ(merged.ids[size_t(c)], whole.ids[size_t(c)]) << whole.names()[size_t(c)];
  }
}

}  // namespace
}  // namespace dcm::aov::test
