// `dcm render|reconstruct --tile I/N` + `dcm merge` against one process: the
// merged frame is bit-identical; merge refuses parts that do not fit together,
// with a message naming them and no output.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cstring>
#include <map>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dcm/options.h"
#include "test_util.h"

namespace dcm::aov::test {
namespace {

const std::string kRoom = std::string(DCM_SOURCE_DIR) + "/examples/scenes/room.json";

/// Pixels of an EXR (all channels as float) with its data and display window.
struct Pixels {
  int x = 0, y = 0, width = 0, height = 0, fullWidth = 0, fullHeight = 0, channels = 0;
  std::vector<float> values;
};

Pixels Read(const std::string& path) {
  Pixels p;
  auto in = OIIO::ImageInput::open(path);
  EXPECT_TRUE(in) << path << ": " << OIIO::geterror();
  if (!in) return p;
  const OIIO::ImageSpec& s = in->spec();
  p = {s.x, s.y, s.width, s.height, s.full_width, s.full_height, s.nchannels, {}};
  p.values.resize(size_t(s.width) * size_t(s.height) * size_t(s.nchannels));
  EXPECT_TRUE(in->read_image(0, 0, 0, s.nchannels, OIIO::TypeDesc::FLOAT, p.values.data())) << path;
  return p;
}

/// Bit-for-bit comparison of two whole frames; the message counts the differing values.
::testing::AssertionResult SameFrame(const std::string& a, const std::string& b) {
  const Pixels pa = Read(a), pb = Read(b);
  if (pa.width != pb.width || pa.height != pb.height || pa.channels != pb.channels || pa.x != pb.x || pa.y != pb.y)
    return ::testing::AssertionFailure() << a << " and " << b << " differ in size or channels";
  if (pa.width != pa.fullWidth || pa.height != pa.fullHeight)
    return ::testing::AssertionFailure() << a << " is not a whole frame";
  size_t differ = 0;
  for (size_t i = 0; i < pa.values.size(); ++i)
    differ += std::memcmp(&pa.values[i], &pb.values[i], sizeof(float)) != 0;
  if (differ) return ::testing::AssertionFailure() << differ << " values differ between " << a << " and " << b;
  return ::testing::AssertionSuccess();
}

/// "p1_8_3.exr" from ("p", {1, 8, 3}); built by append (GCC 12 warns falsely,
/// -Wrestrict, on "literal" + std::string).
std::string Name(const char* prefix, std::initializer_list<int> numbers) {
  std::string s(prefix);
  bool first = true;
  for (int n : numbers) {
    if (!first) s.push_back('_');
    s.append(std::to_string(n));
    first = false;
  }
  s.append(".exr");
  return s;
}

nlohmann::json ReadJson(const std::string& path) { return nlohmann::json::parse(ReadText(path)); }

void ExpectOk(const RunResult& r, const std::string& what) {
  EXPECT_EQ(r.exitCode, 0) << what << "\nstdout: " << r.out << "\nstderr: " << r.err;
}

TEST(TilesCli, RenderedTilesMergeToTheSameBits) {
  ScratchDir dir;
  for (int ss : {1, 2}) {
    // 90x66 is not a multiple of the 16-pixel block (nor, with 2x2
    // supersampling, of its 8 output pixels).
    const std::vector<std::string> common = {"--size", "90x66", "--supersampling", std::to_string(ss), "--quiet"};
    auto args = [&](std::vector<std::string> a) {
      a.insert(a.begin(), {"render", kRoom});
      a.insert(a.end(), common.begin(), common.end());
      return a;
    };
    const std::string whole = dir / ("whole" + std::to_string(ss) + ".exr");
    ExpectOk(RunDcm(args({"-o", whole, "--stats", whole + ".json"}), dir), "whole frame");
    for (int n : {2, 3, 8}) {
      SCOPED_TRACE("supersampling " + std::to_string(ss) + ", " + std::to_string(n) + " tiles");
      std::vector<std::string> merge = {"merge"};
      for (int i = 0; i < n; ++i) {
        const std::string part = dir / Name("p", {ss, n, i});
        ExpectOk(RunDcm(args({"--tile", std::to_string(i) + "/" + std::to_string(n), "-o", part}), dir), part);
        merge.push_back(part);
      }
      const std::string merged = dir / ("merged" + std::to_string(ss) + "_" + std::to_string(n) + ".exr");
      merge.insert(merge.end(), {"-o", merged, "--stats", merged + ".json", "--quiet"});
      ExpectOk(RunDcm(merge, dir), "merge");
      EXPECT_TRUE(SameFrame(whole, merged));
      // The exact pixels of the parts add up to those of the whole frame.
      EXPECT_EQ(ReadJson(merged + ".json")["exact_pixels"], ReadJson(whole + ".json")["exact_pixels"]);
    }
  }
}

TEST(TilesCli, NoisyRenderedTilesMergeToTheSameBits) {
  // 4 samples per pixel: the tracer reports the variance, the engine weighs
  // the noise and denoises the exact samples (a fit over an elementary block
  // around each), which needs a halo of two blocks.
  ScratchDir dir;
  const std::vector<std::string> common = {"render", kRoom, "--size", "90x66", "--spp", "4", "--set",
                                           "render.shadow_rays=2", "--quiet"};
  auto args = [&](std::vector<std::string> a) {
    a.insert(a.begin(), common.begin(), common.end());
    return a;
  };
  ExpectOk(RunDcm(args({"-o", dir / "whole.exr", "--stats", dir / "whole.json"}), dir), "whole frame");
  ASSERT_GT(ReadJson(dir / "whole.json").value("denoised_samples", 0), 0) << "the noisy path was not taken";
  std::vector<std::string> merge = {"merge", "--quiet", "-o", dir / "merged.exr"};
  for (int i = 0; i < 8; ++i) {
    const std::string part = dir / Name("p", {i});
    ExpectOk(RunDcm(args({"--tile", std::to_string(i) + "/8", "-o", part}), dir), part);
    merge.push_back(part);
  }
  ExpectOk(RunDcm(merge, dir), "merge");
  EXPECT_TRUE(SameFrame(dir / "whole.exr", dir / "merged.exr"));
}

TEST(TilesCli, ReconstructedTilesMergeToTheSameBits) {
  ScratchDir dir;
  Scene scene;
  scene.width = 202;  // with --downsample 2: 101x77 output pixels
  scene.height = 154;
  WriteExr(dir / "in.exr", scene.width, scene.height, scene.GenericChannels(true));
  for (int ds : {1, 2}) {
    const std::string whole = dir / ("whole" + std::to_string(ds) + ".exr");
    const std::vector<std::string> common = {"--downsample", std::to_string(ds), "--quiet"};
    auto args = [&](std::vector<std::string> a) {
      a.insert(a.begin(), {"reconstruct", dir / "in.exr"});
      a.insert(a.end(), common.begin(), common.end());
      return a;
    };
    // A part carries the input's passes too: the merged frame is the whole run's.
    ExpectOk(RunDcm(args({"-o", whole}), dir), "whole frame");
    for (int n : {2, 3, 8}) {
      SCOPED_TRACE("downsample " + std::to_string(ds) + ", " + std::to_string(n) + " tiles");
      std::vector<std::string> merge = {"merge"};
      for (int i = 0; i < n; ++i) {
        const std::string part = dir / Name("p", {ds, n, i});
        ExpectOk(RunDcm(args({"--tile", std::to_string(i) + "/" + std::to_string(n), "-o", part}), dir), part);
        merge.push_back(part);
      }
      const std::string merged = dir / ("merged" + std::to_string(ds) + "_" + std::to_string(n) + ".exr");
      merge.insert(merge.end(), {"-o", merged, "--quiet"});
      ExpectOk(RunDcm(merge, dir), "merge");
      EXPECT_TRUE(SameFrame(whole, merged));
    }
  }
  // A part is a region of the frame: display window = frame, data window = region.
  const Pixels part = Read(dir / "p1_8_5.exr");
  EXPECT_EQ(part.fullWidth, 202);
  EXPECT_EQ(part.fullHeight, 154);
  EXPECT_LT(part.width * part.height, 202 * 154 / 4);
}

TEST(TilesCli, RegionsAndFramePatterns) {
  ScratchDir dir;
  Scene a, b;
  a.width = b.width = 70;
  a.height = b.height = 50;
  WriteExr(dir / "in.0001.exr", a.width, a.height, a.GenericChannels(false));
  WriteExr(dir / "in.0002.exr", b.width, b.height,
           std::vector<TestChannel>{Fill("R", 70, 50, [](int x, int) { return 0.01f * float(x); }),
                                    Fill("G", 70, 50, [](int, int y) { return 0.02f * float(y); }),
                                    Fill("B", 70, 50, [](int x, int y) { return (x / 9 + y / 7) % 2 ? 1.f : 0.2f; })});
  // Whole frames 1 and 2 in one process.
  ExpectOk(RunDcm({"reconstruct", dir / "in.####.exr", "--frames", "1-2", "-o", dir / "whole.####.exr", "--quiet"},
                  dir), "frames");
  // Explicit regions of both frames, then a merge per frame with a pattern.
  for (const char* region : {"0,0,70,20", "0,20,33,30", "33,20,37,30"})
    ExpectOk(RunDcm({"reconstruct", dir / "in.####.exr", "--frames", "1-2", "--region", region, "-o",
                     dir / (std::string("part.####.") + region + ".exr"), "--quiet"},
                    dir),
             region);
  ExpectOk(RunDcm({"merge", "--frames", "1-2", dir / "part.####.*.exr", "-o", dir / "merged.####.exr", "--quiet"}, dir),
           "merge frames");
  EXPECT_TRUE(SameFrame(dir / "whole.0001.exr", dir / "merged.0001.exr"));
  EXPECT_TRUE(SameFrame(dir / "whole.0002.exr", dir / "merged.0002.exr"));
  // Frame 2's parts with frame 1's: other inputs, other settings.
  auto r = RunDcm({"merge", dir / "part.0001.0,0,70,20.exr", dir / "part.0002.0,20,33,30.exr",
                   dir / "part.0001.33,20,37,30.exr", "-o", dir / "mixed.exr"}, dir);
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_NE(r.err.find("other settings"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("input.inputs"), std::string::npos) << r.err;
}

class MergeErrors : public ::testing::Test {
 protected:
  void SetUp() override {
    Scene s;
    s.width = 96;
    s.height = 64;
    WriteExr(dir_ / "in.exr", s.width, s.height, s.GenericChannels(true));
    for (int i = 0; i < 4; ++i) ExpectOk(Part(i, {}), "tile " + std::to_string(i));
  }
  RunResult Part(int i, std::vector<std::string> extra, const std::string& name = "") {
    std::vector<std::string> a = {"reconstruct", dir_ / "in.exr", "--tile", std::to_string(i) + "/4", "-o",
                                  dir_ / (name.empty() ? Name("t", {i}) : name), "--quiet"};
    a.insert(a.end(), extra.begin(), extra.end());
    return RunDcm(a, dir_);
  }
  /// Runs dcm merge on `parts`; checks exit code 1 and that nothing was written.
  std::string MergeFails(const std::vector<std::string>& parts) {
    std::vector<std::string> a = {"merge"};
    for (const auto& p : parts) a.push_back(dir_ / p);
    a.insert(a.end(), {"-o", dir_ / "out.exr", "--stats", dir_ / "out.json"});
    const auto before = dir_.Files();
    const RunResult r = RunDcm(a, dir_);
    EXPECT_EQ(r.exitCode, 1) << r.err;
    EXPECT_EQ(dir_.Files(), before) << "merge must write nothing on error";
    return r.err;
  }
  ScratchDir dir_;
};

TEST_F(MergeErrors, MissingTileIsNamed) {
  const std::string err = MergeFails({"t0.exr", "t1.exr", "t3.exr"});
  EXPECT_NE(err.find("uncovered"), std::string::npos) << err;
  EXPECT_NE(err.find("missing tile 2/4"), std::string::npos) << err;
}

TEST_F(MergeErrors, OverlappingTilesAreNamed) {
  // A tile given twice, and an explicit region over two tiles.
  std::string err = MergeFails({"t0.exr", "t1.exr", "t2.exr", "t3.exr", "t2.exr"});
  EXPECT_NE(err.find("overlap"), std::string::npos) << err;
  EXPECT_NE(err.find("t2.exr"), std::string::npos) << err;
  ExpectOk(RunDcm({"reconstruct", dir_ / "in.exr", "--region", "40,20,20,20", "-o", dir_ / "r.exr", "--quiet"}, dir_),
           "region");
  err = MergeFails({"t0.exr", "t1.exr", "t2.exr", "t3.exr", "r.exr"});
  EXPECT_TRUE(err.find("overlap") != std::string::npos || err.find("explicit region") != std::string::npos) << err;
}

TEST_F(MergeErrors, DifferentSettingsAreNamed) {
  ExpectOk(Part(3, {"--threshold", "0.1"}, "t3b.exr"), "other threshold");
  const std::string err = MergeFails({"t0.exr", "t1.exr", "t2.exr", "t3b.exr"});
  EXPECT_NE(err.find("other settings"), std::string::npos) << err;
  EXPECT_NE(err.find("contrast_threshold"), std::string::npos) << err;
  // Threads do not change a bit: parts made with other thread counts merge.
  ExpectOk(Part(3, {"--threads", "1"}, "t3c.exr"), "one thread");
  ExpectOk(RunDcm({"merge", dir_ / "t0.exr", dir_ / "t1.exr", dir_ / "t2.exr", dir_ / "t3c.exr", "-o",
                   dir_ / "ok.exr", "--quiet"}, dir_), "merge with another thread count");
}

TEST_F(MergeErrors, NotAPartAndBadTileFlags) {
  ExpectOk(RunDcm({"reconstruct", dir_ / "in.exr", "-o", dir_ / "whole.exr", "--quiet"}, dir_), "whole");
  std::string err = MergeFails({"t0.exr", "whole.exr"});
  EXPECT_NE(err.find("not a part"), std::string::npos) << err;
  err = MergeFails({"t0.exr", "nonexistent.exr"});
  EXPECT_NE(err.find("nonexistent.exr"), std::string::npos) << err;
  auto r = Part(4, {}, "bad.exr");
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.err.find("numbered from 0"), std::string::npos) << r.err;
  r = RunDcm({"reconstruct", dir_ / "in.exr", "--region", "90,0,10,10", "-o", dir_ / "bad.exr"}, dir_);
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.err.find("beyond"), std::string::npos) << r.err;
  EXPECT_FALSE(std::ifstream(dir_ / "bad.exr").good());
}

// Hostile flag values (issue 25): each is refused by every command that takes
// the flag, with exit 2, a message naming the flag as typed and the value,
// and no file written; none is replaced by the default.
struct Hostile {
  std::vector<std::string> commands;
  std::string flag, value;
};

TEST(HostileFlags, RefusedWithTheFlagNamed) {
  ScratchDir dir;
  Scene s;  // 64x64: --downsample 3 does not divide it
  WriteExr(dir / "in.exr", s.width, s.height, s.GenericChannels(true));
  WriteExr(dir / "guides.exr", s.width, s.height, s.GenericChannels(true, /*guidesOnly=*/true));
  const std::map<std::string, std::vector<std::string>> base = {
      {"render", {"render", kRoom, "-o", dir / "out.exr", "--stats", dir / "s.json"}},
      {"reconstruct", {"reconstruct", dir / "in.exr", "-o", dir / "out.exr", "--stats", dir / "s.json"}},
      {"plan", {"plan", dir / "guides.exr", "--list", dir / "next.txt", "--stats", dir / "s.json"}},
      {"merge", {"merge", dir / "in.exr", "-o", dir / "out.exr"}}};
  const std::vector<std::string> engine = {"render", "reconstruct", "plan"};
  const std::vector<Hostile> cases = {
      {engine, "--threshold", "-1"},
      {engine, "--threshold", "nan"},
      {engine, "--threshold", "inf"},
      {engine, "--threshold", "1e39"},  // finite as a double, not as a float
      {engine, "--block", "0"},
      {engine, "--block", "3"},
      {engine, "--block", "-8"},
      {engine, "--block", "512"},
      {engine, "--min-block", "0"},
      {engine, "--directions", "0"},
      {engine, "--directions", "7"},
      {engine, "--tile-size", "0"},
      {engine, "--threads", "10000000"},
      {engine, "--threads", "-1"},
      {engine, "--threads", "2.5"},
      {engine, "--crease-angle", "nan"},
      {engine, "--crease-angle", "181"},
      {engine, "--noise-significance", "-1"},
      {engine, "--probe-lc-share", "1.5"},
      {engine, "--neighbour-directions", "-1"},
      {engine, "--simple-surface-changes", "0"},
      {engine, "--fallback-shading-changes", "-2"},
      {engine, "--crossing-fill", "-1"},
      {engine, "--downsample", "0"},
      {engine, "--thin-test", "sometimes"},
      {engine, "--tile", "4/4"},
      {engine, "--tile", "0/99999999999"},
      {engine, "--region", "0,0,0,8"},
      {{"render", "reconstruct", "plan", "merge"}, "--frames", "5-3"},
      // Checked once the other flags or the input are known.
      {{"reconstruct", "plan"}, "--block", "2"},       // below the default --min-block 4
      {{"reconstruct", "plan"}, "--min-block", "32"},  // above the default --block 16
      {{"reconstruct", "plan"}, "--downsample", "3"},
      {{"reconstruct", "plan"}, "--highlight-level", "nan"},
      {{"reconstruct", "plan"}, "--highlight-level", "-1"},
      {{"render"}, "--scale", "nan"},
      {{"render"}, "--supersampling", "0"},
      {{"render"}, "--spp", "0"},
      {{"render"}, "--seed", "-1"},
      {{"render"}, "--size", "0x10"},
  };
  const std::vector<std::string> before = dir.Files();
  for (const Hostile& c : cases) {
    for (const std::string& command : c.commands) {
      std::vector<std::string> args = base.at(command);
      args.insert(args.end(), {c.flag, c.value});
      const RunResult r = RunDcm(args, dir);
      const std::string what = command + " " + c.flag + " " + c.value;
      EXPECT_EQ(r.exitCode, 2) << what << "\nstderr: " << r.err;
      EXPECT_NE(r.err.find("dcm " + command + ": "), std::string::npos) << what << ": " << r.err;
      EXPECT_NE(r.err.find(c.flag), std::string::npos) << what << ": " << r.err;
      EXPECT_NE(r.err.find(c.value), std::string::npos) << what << ": " << r.err;
      EXPECT_EQ(dir.Files(), before) << what << ": a file was written";
    }
  }
}

// The edge values the old "0 or negative: the default" rules swallowed are
// used as typed.
TEST(HostileFlags, EdgeValuesAreUsedAsGiven) {
  ScratchDir dir;
  Scene s;
  WriteExr(dir / "in.exr", s.width, s.height, s.GenericChannels(true));
  const RunResult r = RunDcm({"reconstruct", dir / "in.exr", "-o", dir / "out.exr", "--stats", dir / "s.json", "-q",
                              "--threshold", "0", "--threads", "1", "--tile-size", "1", "--crease-angle", "0",
                              "--noise-significance", "0", "--probe-lc-share", "0", "--neighbour-directions", "0",
                              "--crossing-fill", "0", "--fallback-shading-changes", "-1", "--simple-surface-changes",
                              "2", "--block", "4", "--min-block", "2", "--directions", "4"},
                             dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(r.out, "") << "-q: no summary";
  EXPECT_EQ(r.err, "") << "-q: no progress";
  const nlohmann::json o = ReadJson(dir / "s.json")["options"];
  EXPECT_EQ(o["contrast_threshold"], 0.0);
  EXPECT_EQ(o["threads"], 1);
  EXPECT_EQ(o["tile_size"], 1);
  EXPECT_EQ(o["crease_angle"], 0.0);
  EXPECT_EQ(o["noise_significance"], 0.0);
  EXPECT_EQ(o["probe_lc_share"], 0.0);
  EXPECT_EQ(o["neighbour_directions"], 0);
  EXPECT_EQ(o["crossing_fill_reach"], 0);
  EXPECT_EQ(o["fallback_shading_changes"], -1);
  EXPECT_EQ(o["simple_surface_changes"], 2);
  EXPECT_EQ(o["elementary_block"], 4);
  EXPECT_EQ(o["min_block"], 2);
  EXPECT_EQ(o["directions"], 4);
}

// --help: the groups in order, the defaults the parser shows, -q and the exit
// codes; the summary of a run on stdout, not stderr.
TEST(HostileFlags, HelpGroupsQuietAndSummaryOnStdout) {
  ScratchDir dir;
  const ReconstructionOptions d;
  for (const std::string command : {"render", "reconstruct", "plan"}) {
    const RunResult r = RunDcm({command, "--help"}, dir);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    size_t at = 0;
    for (const char* group :
         {"Inputs and outputs:", "Quality:", "Guides:", "Tiles and frames:", "Noise:", "Engine internals:"}) {
      const size_t next = r.out.find(std::string("\n") + group + "\n");
      ASSERT_NE(next, std::string::npos) << command << ": no group " << group << "\n" << r.out;
      EXPECT_GT(next, at) << command << ": " << group << " out of order";
      at = next;
    }
    // Expert switches come after the input and output flags, with the internals.
    EXPECT_GT(r.out.find("--probe-lc-share"), r.out.find("Engine internals:")) << r.out;
    const size_t minBlock = r.out.find("--min-block");
    ASSERT_NE(minBlock, std::string::npos);
    // The parser shows the engine's default at the end of the flag's entry.
    std::string shown("(default: ");
    shown.append(std::to_string(d.minBlock)).append(")");
    EXPECT_LT(r.out.find(shown, minBlock), r.out.find("--directions", minBlock)) << r.out;
    EXPECT_NE(r.out.find("-q,--quiet"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("Exit codes: 0"), std::string::npos) << r.out;
  }
  const RunResult merge = RunDcm({"merge", "--help"}, dir);
  EXPECT_NE(merge.out.find("-q,--quiet"), std::string::npos) << merge.out;

  Scene s;
  WriteExr(dir / "in.exr", s.width, s.height, s.GenericChannels(true));
  RunResult r = RunDcm({"reconstruct", dir / "in.exr", "-o", dir / "out.exr"}, dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("exact pixels"), std::string::npos) << r.out;
  EXPECT_EQ(r.err.find("exact pixels"), std::string::npos) << r.err;
  r = RunDcm({"reconstruct", dir / "in.exr", "--tile", "0/2", "-o", dir / "t0.exr"}, dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("tile 0/2"), std::string::npos) << r.out;
  r = RunDcm({"reconstruct", dir / "in.exr", "--tile", "1/2", "-o", dir / "t1.exr", "-q"}, dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  r = RunDcm({"merge", dir / "t0.exr", dir / "t1.exr", "-o", dir / "merged.exr"}, dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("2 parts -> "), std::string::npos) << r.out;
  EXPECT_EQ(r.err, "");
  // -q means the same in every command: no summary on stdout, no progress on stderr.
  for (const bool quiet : {false, true}) {
    for (const std::string tile : {"", "0/2"}) {
      std::vector<std::string> a = {"render", kRoom, "--size", "48x32", "-o", dir / "r.exr"};
      if (!tile.empty()) a.insert(a.end(), {"--tile", tile});
      if (quiet) a.push_back("-q");
      r = RunDcm(a, dir);
      ASSERT_EQ(r.exitCode, 0) << r.err;
      EXPECT_EQ(r.out.find("exact pixels") == std::string::npos, quiet) << "render " << tile << ": " << r.out;
      if (quiet) {
        EXPECT_EQ(r.out + r.err, "") << "render -q " << tile;
      }
    }
  }
}

}  // namespace
}  // namespace dcm::aov::test
