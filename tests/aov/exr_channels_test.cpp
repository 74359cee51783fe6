// ChannelSet: a part of a scanline file is read in one pass at its first
// float read; every value equals what reading one channel at a time gives.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cstring>
#include <vector>

#include "../../plugins/aov/src/exr_channels.h"
#include "test_util.h"

namespace dcm::aov::test {
namespace {

using detail::ChannelSet;

/// The plane OpenImageIO reads for channel `c` alone, as float.
std::vector<float> ReadAlone(const std::string& path, int c, size_t pixels) {
  auto in = OIIO::ImageInput::open(path);
  EXPECT_TRUE(in) << path;
  std::vector<float> plane(pixels);
  if (in) {
    EXPECT_TRUE(in->read_image(0, 0, c, c + 1, OIIO::TypeDesc::FLOAT, plane.data())) << in->geterror();
  }
  return plane;
}

/// Writes the test file of the one-pass tests: 53x70, half, float and
/// integer channels interleaved.
TestChannel WriteMixed(const std::string& path) {
  // 70 rows: not a multiple of an EXR scanline block (16 with zip) nor of the
  // pass's 32-row reads.
  const int w = 53, h = 70;
  std::vector<TestChannel> ch = {
      Fill("A", w, h, [](int x, int y) { return 0.1f * float(x) - 0.37f * float(y); }),
      Fill("B", w, h, [](int x, int y) { return float(x * y) / 7.f; }),
      Fill("C", w, h, [](int x, int y) { return x == 3 && y == 5 ? 1e30f : float(x - y); }),
  };
  ch[0].half = true;
  TestChannel id{"id", {}, std::vector<uint32_t>(size_t(w * h))};
  for (size_t i = 0; i < id.ids.size(); ++i) id.ids[i] = uint32_t(i * 2654435761u);
  ch.insert(ch.begin() + 1, id);
  WriteExr(path, w, h, ch);
  return id;
}

/// Every float channel read through `set` equals OpenImageIO's read of that
/// channel alone; the IDs are read as integers.
void ExpectSameAsAlone(const ChannelSet& set, const std::string& path, const TestChannel& id) {
  for (const char* name : {"A", "B", "C"}) {
    std::vector<float> plane;
    ASSERT_TRUE(set.ReadFloat(name, &plane).ok());
    const std::vector<float> alone = ReadAlone(path, set.Find(name)->index, set.pixels());
    ASSERT_EQ(plane.size(), alone.size());
    EXPECT_EQ(std::memcmp(plane.data(), alone.data(), plane.size() * sizeof(float)), 0) << name;
  }
  std::vector<uint32_t> ids;
  ASSERT_TRUE(set.ReadId("id", &ids).ok());
  EXPECT_EQ(ids, id.ids);
}

TEST(ChannelSet, OnePassReadsWhatOneChannelAtATimeReads) {
  ScratchDir dir;
  const TestChannel id = WriteMixed(dir / "in.exr");
  ChannelSet set;
  ASSERT_TRUE(set.Add(dir / "in.exr").ok());
  ExpectSameAsAlone(set, dir / "in.exr", id);
}

// With wanted channels named, the pass decodes those alone; a channel not
// named is read by itself, and a second read of a channel reads the file
// again: the values are the same either way.
TEST(ChannelSet, WantedChannelsAndTheRest) {
  ScratchDir dir;
  const TestChannel id = WriteMixed(dir / "in.exr");
  ChannelSet set;
  ASSERT_TRUE(set.Add(dir / "in.exr").ok());
  set.Want({"A", "C", "no such channel"});
  ExpectSameAsAlone(set, dir / "in.exr", id);
  ExpectSameAsAlone(set, dir / "in.exr", id);
}

TEST(ChannelSet, TiledFilesAreReadOneChannelAtATime) {
  ScratchDir dir;
  const int w = 40, h = 24;
  OIIO::ImageSpec spec(w, h, 3, OIIO::TypeDesc::FLOAT);
  spec.channelnames = {"R", "G", "B"};
  spec.tile_width = spec.tile_height = 16;
  std::vector<float> pixels(size_t(w * h * 3));
  for (size_t i = 0; i < pixels.size(); ++i) pixels[i] = float(i) * 0.25f;
  auto out = OIIO::ImageOutput::create(dir / "tiled.exr");
  ASSERT_TRUE(out && out->open(dir / "tiled.exr", spec));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()));
  out->close();
  ChannelSet set;
  ASSERT_TRUE(set.Add(dir / "tiled.exr").ok());
  std::vector<float> g;
  ASSERT_TRUE(set.ReadFloat("G", &g).ok());
  for (size_t i = 0; i < g.size(); ++i) ASSERT_EQ(g[i], pixels[i * 3 + 1]) << i;
}

}  // namespace
}  // namespace dcm::aov::test
