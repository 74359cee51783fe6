// The input's passes at the output resolution of --downsample N: a film
// filter's box mean for radiance-like passes, the majority for IDs, the
// Cryptomatte ranks merged by coverage.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <bit>
#include <cmath>

#include "pass_downsample.h"
#include "test_util.h"

namespace dcm::cli {
namespace {

TEST(PassDownsample, BoxMeanAveragesEachBox) {
  // 4x2 -> 2x1 with N = 2: each output pixel is the mean of its 2x2 box.
  const std::vector<float> in{1, 2, 10, 20, 3, 4, 30, 40};
  EXPECT_EQ(BoxMeanPlane(in, 4, 2, 2), (std::vector<float>{2.5f, 25.f}));
}

TEST(PassDownsample, MajorityKeepsAnIdThatIsThere) {
  // Box 1: 7 7 7 9 -> 7 (never the mean 7.5, an ID no object has).
  // Box 2: 5 6 6 5 -> a tie: the first in scan order, 5.
  const std::vector<uint32_t> ids{7, 7, 5, 6, 7, 9, 6, 5};
  EXPECT_EQ(MajorityPlane(ids, 4, 2, 2), (std::vector<uint32_t>{7, 5}));
  // Float IDs are compared by their bits: -0 and +0 are two IDs.
  const std::vector<float> f{-0.f, 0.f, 0.f, 3.f};
  const auto out = MajorityPlane(f, 2, 2, 2);
  EXPECT_EQ(std::bit_cast<uint32_t>(out[0]), std::bit_cast<uint32_t>(0.f));
}

TEST(PassDownsample, CryptomatteRanksMergeByCoverage) {
  const float A = std::bit_cast<float>(0x3f8ccccdu), B = std::bit_cast<float>(0x40133333u),
              C = std::bit_cast<float>(0x4059999au);
  // 2x2 -> 1x1, two ranks per pixel: (id0, cov0, id1, cov1).
  //   A 1.0 | A 0.5 + B 0.5
  //   B 1.0 | C 0.6 + A 0.4
  std::vector<float> id0{A, A, B, C}, cov0{1.f, 0.5f, 1.f, 0.6f}, id1{0, B, 0, A}, cov1{0, 0.5f, 0, 0.4f};
  ASSERT_TRUE(DownsampleCryptomatte({&id0, &cov0, &id1, &cov1}, 2, 2, 2).ok());
  // Coverage over the box: A 1.9, B 1.5, C 0.6, divided by 4; two ranks hold A and B.
  EXPECT_EQ(std::bit_cast<uint32_t>(id0[0]), std::bit_cast<uint32_t>(A));
  EXPECT_FLOAT_EQ(cov0[0], 1.9f / 4);
  EXPECT_EQ(std::bit_cast<uint32_t>(id1[0]), std::bit_cast<uint32_t>(B));
  EXPECT_FLOAT_EQ(cov1[0], 1.5f / 4);
  std::vector<float> odd{0.f};
  EXPECT_FALSE(DownsampleCryptomatte({&odd}, 1, 1, 1).ok());
}

TEST(PassDownsample, PassesAreFilteredByKind) {
  // 2x2 -> 1x1: a Cryptomatte layer named by the metadata (rank 0 only), a
  // float ID (raw) and a colour.
  const float A = std::bit_cast<float>(0x3f8ccccdu), B = std::bit_cast<float>(0x40133333u);
  auto channel = [](std::string name, std::vector<float> v, bool raw) {
    toolkit::OutputChannel c;
    c.name = std::move(name);
    c.values = std::move(v);
    c.raw = raw;
    return c;
  };
  std::vector<toolkit::OutputChannel> chans{
      channel("ViewLayer.Combined.R", {0.5f}, false),  // not a pass: left alone
      channel("ViewLayer.CryptoObject00.R", {A, B, B, B}, true),
      channel("ViewLayer.CryptoObject00.G", {1.f, 1.f, 1.f, 1.f}, true),
      channel("ViewLayer.CryptoObject00.B", {0.f, 0.f, 0.f, 0.f}, true),
      channel("ViewLayer.CryptoObject00.A", {0.f, 0.f, 0.f, 0.f}, true),
      channel("ViewLayer.IndexOB.X", {3.f, 4.f, 4.f, 3.f}, true),
      channel("ViewLayer.DiffCol.R", {0.2f, 0.4f, 0.4f, 0.2f}, false)};
  ASSERT_TRUE(DownsamplePasses(&chans, {1, 2, 3, 4, 5, 6}, {"ViewLayer.CryptoObject"}, 2, 2, 2).ok());
  EXPECT_EQ(chans[0].values, std::vector<float>{0.5f});
  // Cryptomatte: B covers 3/4, A 1/4; rank 1 holds A.
  EXPECT_EQ(std::bit_cast<uint32_t>(chans[1].values.at(0)), std::bit_cast<uint32_t>(B));
  EXPECT_FLOAT_EQ(chans[2].values.at(0), 0.75f);
  EXPECT_EQ(std::bit_cast<uint32_t>(chans[3].values.at(0)), std::bit_cast<uint32_t>(A));
  EXPECT_FLOAT_EQ(chans[4].values.at(0), 0.25f);
  EXPECT_EQ(chans[5].values, std::vector<float>{3.f}) << "a tie: the first in scan order";
  EXPECT_FLOAT_EQ(chans[6].values.at(0), 0.3f);
  // A layer missing a channel cannot be merged.
  std::vector<toolkit::OutputChannel> broken{channel("L00.R", {A, A, A, A}, true), channel("L00.B", {0, 0, 0, 0}, true)};
  EXPECT_FALSE(DownsamplePasses(&broken, {0, 1}, {"L"}, 2, 2, 2).ok());
}

TEST(PassDownsample, ReconstructWritesEveryPassAtTheOutputSize) {
  using namespace dcm::aov::test;
  ScratchDir dir;
  const int w = 32, h = 16;
  Scene sc{w, h};
  std::vector<TestChannel> ch;
  ch.push_back(Fill("ViewLayer.IndexOB.X", w, h, [&](int x, int y) { return float(sc.ObjectId(x, y)); }));
  const char* comp[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) {
    ch.push_back(Fill(std::string("ViewLayer.DiffCol.") + comp[c], w, h, [&](int x, int y) { return sc.Tau(x, y)[c]; }));
    ch.push_back(Fill(std::string("ViewLayer.DiffDir.") + comp[c], w, h, [&](int x, int y) { return sc.Li(x, y)[c]; }));
    ch.push_back(Fill(std::string("ViewLayer.Combined.") + comp[c], w, h, [&](int x, int y) { return sc.L(x, y)[c]; }));
  }
  ch.push_back(Fill("ViewLayer.Depth.Z", w, h, [](int x, int y) { return 1.f + 0.25f * float(x) + float(y % 3); }));
  TestChannel ids{"ViewLayer.Custom.id", {}, {}, false};
  for (int i = 0; i < w * h; ++i) ids.ids.push_back(uint32_t((i % w) / 3) * 2654435761u);
  ch.push_back(ids);
  WriteExr(dir / "in.exr", w, h, ch, {});
  auto r = RunDcm({"reconstruct", dir / "in.exr", "--preset", "blender", "--downsample", "2", "-o", dir / "out.exr",
                   "-v"}, dir);
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.err.find("passes box-filtered, IDs by majority"), std::string::npos) << r.err;
  auto in = OIIO::ImageInput::open(dir / "in.exr");
  auto out = OIIO::ImageInput::open(dir / "out.exr");
  ASSERT_TRUE(in && out);
  ASSERT_EQ(out->spec().width, w / 2);
  ASSERT_EQ(out->spec().height, h / 2);
  ASSERT_EQ(out->spec().channelnames, in->spec().channelnames);
  auto plane = [](OIIO::ImageInput& f, const std::string& name, OIIO::TypeDesc t, auto* v) {
    const int c = f.spec().channelindex(name);
    v->resize(size_t(f.spec().width) * size_t(f.spec().height));
    EXPECT_TRUE(f.read_image(0, 0, c, c + 1, t, v->data())) << name;
  };
  std::vector<float> zi, zo, oi, oo;
  plane(*in, "ViewLayer.Depth.Z", OIIO::TypeDesc::FLOAT, &zi);
  plane(*out, "ViewLayer.Depth.Z", OIIO::TypeDesc::FLOAT, &zo);
  plane(*in, "ViewLayer.IndexOB.X", OIIO::TypeDesc::FLOAT, &oi);
  plane(*out, "ViewLayer.IndexOB.X", OIIO::TypeDesc::FLOAT, &oo);
  std::vector<uint32_t> ci, co;
  plane(*in, "ViewLayer.Custom.id", OIIO::TypeDesc::UINT, &ci);
  plane(*out, "ViewLayer.Custom.id", OIIO::TypeDesc::UINT, &co);
  for (int y = 0; y < h / 2; ++y)
    for (int x = 0; x < w / 2; ++x) {
      const size_t o = size_t(y * (w / 2) + x);
      float mean = 0;
      bool idThere = false, objectThere = false;
      for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
          const size_t k = size_t((2 * y + j) * w + 2 * x + i);
          mean += zi[k] / 4;
          idThere |= ci[k] == co[o];
          objectThere |= oi[k] == oo[o];
        }
      // Depth is a float pass: its box mean (float sums, 1e-6 relative).
      ASSERT_NEAR(zo[o], mean, 1e-6f * mean) << x << "," << y;
      // IDs: a value of the box, never a blend of two.
      ASSERT_TRUE(idThere) << x << "," << y;
      ASSERT_TRUE(objectThere) << x << "," << y;
    }
}

}  // namespace
}  // namespace dcm::cli
