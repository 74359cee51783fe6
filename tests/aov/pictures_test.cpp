// The PNGs of `dcm reconstruct` explain themselves: the sample map's legend,
// the error map's colour bar; the preview's display transform is the one
// asked for (--colorconfig, --display, --view, --look) and said.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <fstream>

#include "common/sample_map.h"
#include "test_util.h"

namespace dcm::aov::test {
namespace {

using ::testing::HasSubstr;

struct Png {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;
  std::array<uint8_t, 3> At(int x, int y) const {
    const size_t i = (size_t(y) * size_t(width) + size_t(x)) * 3;
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
};

Png ReadPng(const std::string& path) {
  Png p;
  auto in = OIIO::ImageInput::open(path);
  EXPECT_TRUE(in) << path;
  if (!in) return p;
  p.width = in->spec().width;
  p.height = in->spec().height;
  p.rgb.resize(size_t(p.width) * size_t(p.height) * 3);
  EXPECT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, p.rgb.data()));
  return p;
}

/// Whether the rows from y0 on hold a pixel of colour c.
bool HasColourBelow(const Png& p, int y0, std::array<uint8_t, 3> c) {
  for (int y = y0; y < p.height; ++y)
    for (int x = 0; x < p.width; ++x)
      if (p.At(x, y) == c) return true;
  return false;
}

TEST(Pictures, SampleMapHasALegendAndErrorMapAColourBar) {
  ScratchDir dir;
  Scene sc{64, 48};
  WriteExr(dir / "in.exr", sc.width, sc.height, sc.GenericChannels(false));
  auto r = RunDcm({"reconstruct", dir / "in.exr", "-o", dir / "out.exr", "--sample-map", dir / "map.png",
                   "--error-map", dir / "err.png", "--quiet"},
                  dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;

  const Png map = ReadPng(dir / "map.png");
  EXPECT_GE(map.width, toolkit::kLegendEntryWidth);
  EXPECT_GT(map.height, sc.height);
  // Every reason's swatch is in the legend, below the map.
  for (int i = 0; i < kSampleReasonCount; ++i)
    EXPECT_TRUE(HasColourBelow(map, sc.height, toolkit::ReasonColor(SampleReason(i))))
        << ToString(SampleReason(i));
  // The legend's text: light pixels neither a swatch nor its frame.
  EXPECT_TRUE(HasColourBelow(map, sc.height, {230, 230, 230}));

  const Png err = ReadPng(dir / "err.png");
  EXPECT_GE(err.width, toolkit::kErrorMapMinWidth);
  EXPECT_GT(err.height, sc.height);
  // The colour bar runs from black (no error) to white (full scale) on one row.
  const int barRow = sc.height + 4 + 6;
  EXPECT_EQ(err.At(4, barRow), (std::array<uint8_t, 3>{0, 0, 0}));
  EXPECT_EQ(err.At(err.width - 5, barRow), (std::array<uint8_t, 3>{255, 255, 255}));
  int distinct = 0;
  for (int x = 5; x < err.width - 4; ++x) distinct += err.At(x, barRow) != err.At(x - 1, barRow);
  EXPECT_GT(distinct, 100);  // a ramp, not a few flat patches
  EXPECT_TRUE(HasColourBelow(err, barRow + 8, {230, 230, 230}));  // its labels
}

/// A config of two views: Standard (the sRGB curve) and Raw (no transform),
/// and one look that halves the values.
std::string WriteConfig(const ScratchDir& dir) {
  const std::string path = dir / "config.ocio";
  std::ofstream(path) << R"(ocio_profile_version: 2
roles:
  default: linear
  scene_linear: linear
file_rules:
  - !<Rule> {name: Default, colorspace: default}
displays:
  sRGB:
    - !<View> {name: Standard, colorspace: srgb}
    - !<View> {name: Raw, colorspace: linear}
active_displays: []
active_views: []
looks:
  - !<Look>
    name: Half
    process_space: linear
    transform: !<MatrixTransform> {matrix: [0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 0.5, 0, 0, 0, 0, 1]}
colorspaces:
  - !<ColorSpace>
    name: linear
  - !<ColorSpace>
    name: srgb
    from_scene_reference: !<ExponentWithLinearTransform> {gamma: 2.4, offset: 0.055, direction: inverse}
)";
  return path;
}

TEST(Pictures, PreviewTransformIsCheckedUsedAndSaid) {
  ScratchDir dir;
  ::unsetenv("OCIO");  // the built-in curve unless a config is given
  Scene sc{32, 16};
  WriteExr(dir / "in.exr", sc.width, sc.height, sc.GenericChannels(false));
  const std::string config = WriteConfig(dir);
  auto run = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = {"reconstruct", dir / "in.exr", "-o", dir / "out.exr", "--preview",
                                     dir / "p.png",  "--stats",     dir / "s.json", "--quiet"};
    args.insert(args.end(), extra.begin(), extra.end());
    return RunDcm(args, dir);
  };
  auto transform = [&] {
    std::ifstream in(dir / "s.json");
    return nlohmann::json::parse(in).value("preview_transform", std::string());
  };

  auto r = run({});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(transform(), "built-in sRGB");

  // A bad name: a usage error naming the flag and what there is; no output.
  std::filesystem::remove(dir / "out.exr");
  r = run({"--colorconfig", config, "--view", "Filmic"});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_THAT(r.err, HasSubstr("--view Filmic"));
  EXPECT_THAT(r.err, HasSubstr("views: Standard, Raw"));
  EXPECT_FALSE(std::filesystem::exists(dir / "out.exr"));
  r = run({"--colorconfig", config, "--display", "P3"});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_THAT(r.err, HasSubstr("--display P3"));
  r = run({"--colorconfig", config, "--look", "Punchy"});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_THAT(r.err, HasSubstr("--look Punchy"));
  r = run({"--view", "Raw"});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_THAT(r.err, HasSubstr("--view Raw: needs an OpenColorIO config"));

  // Raw: the preview is the output's values, clipped and quantised; the
  // look halves them.
  for (const bool half : {false, true}) {
    std::vector<std::string> extra = {"--colorconfig", config, "--view", "Raw"};
    if (half) extra.insert(extra.end(), {"--look", "Half"});
    r = run(extra);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(transform(), "ocio: config " + config + ", display sRGB, view Raw" + (half ? ", look Half" : ""));
    const auto out = ReadRgbExr(dir / "out.exr");
    const Png p = ReadPng(dir / "p.png");
    ASSERT_EQ(size_t(p.width * p.height), out.size());
    for (size_t i = 0; i < out.size(); ++i)
      for (int c = 0; c < 3; ++c) {
        const float v = std::clamp(out[i][c] * (half ? 0.5f : 1.f), 0.f, 1.f);
        // One code value: OCIO's float arithmetic against this one.
        ASSERT_NEAR(double(p.rgb[i * 3 + size_t(c)]), double(std::lround(v * 255.f)), 1.0) << i;
      }
  }
}

}  // namespace
}  // namespace dcm::aov::test
