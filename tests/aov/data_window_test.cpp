// EXR data windows: a render region (data window inside the display window)
// or overscan (around it). dcm reconstructs the pixels that exist, keeps both
// windows in its outputs, and `dcm plan` names pixels in the frame's
// coordinates.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imageio.h>

#include <cstring>
#include <set>
#include <sstream>
#include <utility>

#include "dcm/geometry.h"
#include "test_util.h"

namespace dcm::aov::test {
namespace {

using ::testing::HasSubstr;

/// Rewrites `in` as `out` with the data window's origin at `origin` and the
/// display window `display`: the same pixels, placed elsewhere in a frame.
void Reframe(const std::string& in, const std::string& out, Point2i origin, const OIIO::ROI& display) {
  OIIO::ImageBuf buf(in);
  ASSERT_TRUE(buf.read(0, 0, true, OIIO::TypeDesc::FLOAT)) << buf.geterror();
  buf.set_origin(origin.x, origin.y);
  buf.set_full(display.xbegin, display.xend, display.ybegin, display.yend, 0, 1);
  ASSERT_TRUE(buf.write(out)) << buf.geterror();
}

OIIO::ImageSpec SpecOf(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  EXPECT_TRUE(in) << path;
  return in ? in->spec() : OIIO::ImageSpec();
}

/// The "x y" lines of a plan list.
std::set<std::pair<int, int>> ListedPixels(const std::string& path) {
  std::set<std::pair<int, int>> pixels;
  std::istringstream in(ReadText(path));
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    int x = 0, y = 0;
    std::istringstream(line) >> x >> y;
    pixels.insert({x, y});
  }
  return pixels;
}

struct Placement {
  const char* name;
  Point2i origin;   ///< of the data window
  OIIO::ROI display;
};

class DataWindow : public ::testing::TestWithParam<Placement> {};

// The engine sees the data window's pixels only, so a placed image gives the
// placed result of the same pixels at the origin, bit for bit.
TEST_P(DataWindow, ReconstructKeepsBothWindowsAndThePixels) {
  const Placement& p = GetParam();
  ScratchDir dir;
  Scene sc{48, 40};
  WriteExr(dir / "whole.exr", sc.width, sc.height, sc.GenericChannels(true));
  Reframe(dir / "whole.exr", dir / "placed.exr", p.origin, p.display);
  for (const char* name : {"whole", "placed"}) {
    const std::string n = name;
    auto r = RunDcm({"reconstruct", dir / (n + ".exr"), "-o", dir / (n + "_out.exr"), "--stats",
                     dir / (n + ".json"), "--sample-map", dir / (n + "_map.png"), "--quiet"},
                    dir);
    ASSERT_EQ(r.exitCode, 0) << r.err;
  }
  const OIIO::ImageSpec s = SpecOf(dir / "placed_out.exr");
  EXPECT_EQ(s.x, p.origin.x);
  EXPECT_EQ(s.y, p.origin.y);
  EXPECT_EQ(s.width, sc.width);
  EXPECT_EQ(s.height, sc.height);
  EXPECT_EQ(s.full_x, p.display.xbegin);
  EXPECT_EQ(s.full_y, p.display.ybegin);
  EXPECT_EQ(s.full_width, p.display.width());
  EXPECT_EQ(s.full_height, p.display.height());
  const auto a = ReadRgbExr(dir / "whole_out.exr"), b = ReadRgbExr(dir / "placed_out.exr");
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(RGB)), 0) << "not bit-identical";
  // The sample map shows the data window (a PNG has no windows), its legend below.
  const OIIO::ImageSpec m = SpecOf(dir / "placed_map.png");
  EXPECT_THAT(m.get_string_attribute("ImageDescription"), ::testing::HasSubstr("top left 48x40 pixels"));
  EXPECT_GT(m.height, sc.height);
}

// A plan's list and mask speak the renderer's frame: list coordinates carry
// the data window's origin; the mask keeps both windows.
TEST_P(DataWindow, PlanNamesFramePixels) {
  const Placement& p = GetParam();
  ScratchDir dir;
  Scene sc{48, 40};
  WriteExr(dir / "whole.exr", sc.width, sc.height, sc.GenericChannels(true, /*guidesOnly=*/true));
  Reframe(dir / "whole.exr", dir / "placed.exr", p.origin, p.display);
  for (const char* name : {"whole", "placed"}) {
    const std::string n = name;
    auto r = RunDcm({"plan", dir / (n + ".exr"), "--list", dir / (n + ".txt"), "--mask", dir / (n + "_mask.exr"),
                     "--quiet"},
                    dir);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    ASSERT_THAT(r.out, HasSubstr("pending "));
  }
  const auto whole = ListedPixels(dir / "whole.txt"), placed = ListedPixels(dir / "placed.txt");
  ASSERT_FALSE(whole.empty());
  std::set<std::pair<int, int>> shifted;
  for (const auto& [x, y] : whole) shifted.insert({x + p.origin.x, y + p.origin.y});
  EXPECT_EQ(placed, shifted);
  const OIIO::ImageSpec s = SpecOf(dir / "placed_mask.exr");
  EXPECT_EQ(s.x, p.origin.x);
  EXPECT_EQ(s.y, p.origin.y);
  EXPECT_EQ(s.full_width, p.display.width());
  EXPECT_EQ(s.full_height, p.display.height());
}

INSTANTIATE_TEST_SUITE_P(
    Placements, DataWindow,
    ::testing::Values(Placement{"RenderRegion", {16, 8}, OIIO::ROI(0, 96, 0, 64)},
                      Placement{"Overscan", {-8, -6}, OIIO::ROI(0, 32, 0, 28)}),
    [](const auto& param) { return std::string(param.param.name); });

TEST(DataWindow, InputsWithDifferentWindowsFail) {
  ScratchDir dir;
  Scene sc{32, 32};
  auto ch = sc.GenericChannels(false);
  WriteExr(dir / "beauty.exr", 32, 32, {ch.back()});  // one channel is enough to place
  ch.pop_back();
  WriteExr(dir / "rest.exr", 32, 32, ch);
  Reframe(dir / "beauty.exr", dir / "placed.exr", {8, 8}, OIIO::ROI(0, 64, 0, 64));
  auto r = RunDcm({"reconstruct", dir / "rest.exr", dir / "placed.exr", "-o", dir / "out.exr"}, dir);
  EXPECT_EQ(r.exitCode, 1);
  EXPECT_THAT(r.err, HasSubstr("placed.exr' is data window 32x32 at 8,8 of display window 64x64 at 0,0"));
  EXPECT_THAT(r.err, HasSubstr("rest.exr' is 32x32"));
  EXPECT_FALSE(std::filesystem::exists(dir / "out.exr"));
}

/// A 32x32 image placed at `origin` of a 64x64 frame, reconstructed with
/// `flags`: a usage error (exit 2) with `message`, and no output.
void ExpectUsageError(const ScratchDir& dir, Point2i origin, const std::vector<std::string>& flags,
                      const std::string& message) {
  Scene sc{32, 32};
  WriteExr(dir / "whole.exr", 32, 32, sc.GenericChannels(false));
  Reframe(dir / "whole.exr", dir / "placed.exr", origin, OIIO::ROI(0, 64, 0, 64));
  std::vector<std::string> args = {"reconstruct", dir / "placed.exr", "-o", dir / "out.exr"};
  args.insert(args.end(), flags.begin(), flags.end());
  auto r = RunDcm(args, dir);
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_THAT(r.err, HasSubstr(message));
  EXPECT_FALSE(std::filesystem::exists(dir / "out.exr"));
}

TEST(DataWindow, DownsampleNeedsTheLattice) {
  ScratchDir dir;
  ExpectUsageError(dir, {3, 8}, {"--downsample", "2"}, "--downsample 2: the inputs' data window (3,8,32,32)");
  // On the lattice, the output is the region of the half-size frame.
  Reframe(dir / "whole.exr", dir / "placed.exr", {4, 8}, OIIO::ROI(0, 64, 0, 64));
  auto r = RunDcm({"reconstruct", dir / "placed.exr", "--downsample", "2", "-o", dir / "out.exr", "--quiet"}, dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const OIIO::ImageSpec s = SpecOf(dir / "out.exr");
  EXPECT_EQ(s.x, 2);
  EXPECT_EQ(s.y, 4);
  EXPECT_EQ(s.width, 16);
  EXPECT_EQ(s.full_width, 32);
}

TEST(DataWindow, TilesNeedTheWholeFrame) {
  ScratchDir dir;
  ExpectUsageError(dir, {8, 8}, {"--tile", "1/2"},
                   "--tile and --region need inputs whose data window is their display window");
}

}  // namespace
}  // namespace dcm::aov::test
