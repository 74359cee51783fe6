// The interpolation record (dcm/interpolation_record.h): other channels
// reconstructed with the beauty's own steps.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ostream>
#include <string>

#include "dcm/window_provider.h"
#include "run_helpers.h"

namespace dcm::testing {
namespace {

/// One channel of the provider's exact L at every pixel (what a renderer's
/// pass equal to the beauty's component would hold).
std::vector<float> BeautyChannel(const AnalyticProvider& p, int w, int h, int c, Point2i origin = {0, 0}) {
  std::vector<float> v(size_t(w) * size_t(h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) v[size_t(y) * size_t(w) + size_t(x)] = p.Truth(origin.x + x, origin.y + y).L()[c];
  return v;
}

/// FurnishedScene with all its light in L_i and a texture of 1: with the
/// split, L = L_i * 1 + 0 is what the engine interpolates, to the bit.
SceneFunction UnitTexture(int n) {
  const SceneFunction scene = FurnishedScene(n, n);
  return [scene](int x, int y) {
    PixelTruth t = scene(x, y);
    t.Li = t.L();
    t.Lc = RGB{};
    t.tau = RGB::Gray(1.f);
    t.renderedL.reset();
    return t;
  };
}

struct Case {
  std::string name;
  ReconstructionOptions options;
  bool unitTexture = false;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

std::vector<Case> Cases() {
  std::vector<Case> cases;
  ReconstructionOptions o;
  o.textureSplit = false;
  cases.push_back({"Dcm", o});
  o.downsample = 2;  // the supersampled rules: crossings filled from the lines beside them
  cases.push_back({"Supersampled", o});
  cases.push_back({"SplitUnitTexture", ReconstructionOptions{}, true});
  // The published methods: every border pixel exact, no checkerboard, Guo's
  // interpolation blind to surfaces.
  for (auto [name, method] : {std::pair{"Paper", ReconstructionOptions::Paper()}, std::pair{"Guo", ReconstructionOptions::Guo()}}) {
    method.textureSplit = false;
    cases.push_back({name, method});
  }
  return cases;
}

class InterpolationRecordCase : public ::testing::TestWithParam<Case> {};

// (a) A channel equal to the beauty's component reconstructs to that
// component bit for bit at every pixel: each interpolated value is computed
// again from the channel with the recorded sources, weights and arithmetic,
// so a missing or different step shows as a differing pixel. With the
// record asked for, the beauty's own bits are those of a run without (d).
TEST_P(InterpolationRecordCase, ABeautyChannelReconstructsToTheBeautysBits) {
  const Case& c = GetParam();
  const int n = 128;
  AnalyticProvider provider(n, n, c.unitTexture ? UnitTexture(n) : FurnishedScene(n, n));
  ReconstructionOptions recorded = c.options;
  recorded.recordInterpolation = true;
  const Reconstruction plain = ReconstructOrFail(provider, c.options);
  const Reconstruction r = ReconstructOrFail(provider, recorded);
  EXPECT_FALSE(plain.interpolation);
  ASSERT_TRUE(r.interpolation);
  // (d) The beauty, its samples and its blocks do not change.
  ASSERT_EQ(r.workImage.size(), plain.workImage.size());
  EXPECT_EQ(std::memcmp(r.workImage.data(), plain.workImage.data(), r.workImage.size() * sizeof(RGB)), 0);
  EXPECT_EQ(r.sampleMap, plain.sampleMap);
  EXPECT_EQ(r.blocks.size(), plain.blocks.size());
  EXPECT_EQ(r.stats.exactPixels, plain.stats.exactPixels);

  // The steps this scene exercises (else the test would not show them).
  if (c.options.checkerboard) {
    EXPECT_GT(r.stats.checkerboardFilled, 0);
  }
  if (c.options.lazyEvaluation) {
    EXPECT_GT(r.stats.lazyAccepted, 0);
  }
  if (c.options.downsample > 1) {
    EXPECT_GT(r.stats.crossingsFilled, 0);
  }
  EXPECT_EQ(r.stats.usedSplit, c.unitTexture);

  const InterpolationRecord& record = *r.interpolation;
  std::printf("%s: record of %.1f bytes per working pixel\n", c.name.c_str(),
              double(record.MemoryBytes()) / double(r.workImage.size()));
  EXPECT_EQ(record.window(), (Bounds2i{{0, 0}, {r.workWidth, r.workHeight}}));
  for (int ch = 0; ch < 3; ++ch) {
    std::vector<float> out;
    const auto exact = BeautyChannel(provider, r.workWidth, r.workHeight, ch);
    ASSERT_TRUE(record.Apply(exact, ChannelKind::kContinuous, &out).ok());
    ASSERT_EQ(out.size(), r.workImage.size());
    int64_t differ = 0, interpolated = 0;
    for (size_t i = 0; i < out.size(); ++i) {
      const float beauty = r.workImage[i][ch];
      uint32_t a, b;
      std::memcpy(&a, &out[i], 4);
      std::memcpy(&b, &beauty, 4);
      differ += a != b;
      interpolated += !record.IsExact(int64_t(i));
    }
    EXPECT_EQ(differ, 0) << "channel " << ch << ": pixels whose bits differ from the beauty's";
    EXPECT_GT(interpolated, int64_t(out.size()) / 2);
  }
}

INSTANTIATE_TEST_SUITE_P(Configurations, InterpolationRecordCase, ::testing::ValuesIn(Cases()),
                         [](const auto& p) { return p.param.name; });

// (b) An ID channel never takes a value that no exact pixel has, never one of
// another surface, never one from beyond the block that interpolated it; and
// all ID channels of a pixel come from one source pixel (a Cryptomatte
// rank's ID and coverage stay a pair).
TEST(InterpolationRecord, IdsComeFromOneExactSourceOnTheSameSurface) {
  const int n = 128;
  AnalyticProvider provider(n, n, FurnishedScene(n, n));
  ReconstructionOptions o;
  o.recordInterpolation = true;
  const Reconstruction r = ReconstructOrFail(provider, o);
  ASSERT_TRUE(r.interpolation);
  const size_t count = size_t(n) * size_t(n);
  // Every pixel its own ID (integers are exact in float up to 2^24), and a
  // second channel a function of it.
  std::vector<float> id(count), second(count);
  for (size_t i = 0; i < count; ++i) {
    id[i] = float(i + 1);
    second[i] = float((i * 7919) % 1000) + 0.25f;
  }
  std::vector<float> outId, outSecond;
  ASSERT_TRUE(r.interpolation->Apply(id, ChannelKind::kId, &outId).ok());
  ASSERT_TRUE(r.interpolation->Apply(second, ChannelKind::kId, &outSecond).ok());
  const int reach = r.stats.settings.elementaryBlock;  // a leaf's border is at most one elementary block away
  int64_t interpolated = 0;
  for (size_t i = 0; i < count; ++i) {
    const int x = int(i % size_t(n)), y = int(i / size_t(n));
    const float v = outId[i];
    ASSERT_TRUE(v >= 1.f && v <= float(count) && v == std::floor(v)) << "(" << x << "," << y << "): " << v;
    const size_t s = size_t(v) - 1;
    if (r.interpolation->IsExact(int64_t(i))) {
      ASSERT_EQ(s, i);
      continue;
    }
    ++interpolated;
    const int sx = int(s % size_t(n)), sy = int(s / size_t(n));
    ASSERT_TRUE(r.interpolation->IsExact(int64_t(s))) << "(" << x << "," << y << ") took a non-exact pixel's ID";
    EXPECT_LE(std::max(std::abs(sx - x), std::abs(sy - y)), reach) << "(" << x << "," << y << ")";
    const PixelTruth a = provider.Truth(x, y), b = provider.Truth(sx, sy);
    EXPECT_TRUE(a.objectId == b.objectId && a.shaderId == b.shaderId)
        << "(" << x << "," << y << ") took the ID of (" << sx << "," << sy << "), another surface";
    ASSERT_EQ(outSecond[i], second[s]) << "(" << x << "," << y << "): the channels took different sources";
  }
  EXPECT_GT(interpolated, int64_t(count) / 2);
}

// A region's record covers its window: the region's pixels of the channel
// are the region's beauty, as the whole frame's are (tiles, docs/TILES.md).
TEST(InterpolationRecord, ARegionsRecordCoversItsWindow) {
  const int n = 128;
  AnalyticProvider provider(n, n, FurnishedScene(n, n));
  ReconstructionOptions o;
  o.textureSplit = false;
  o.recordInterpolation = true;
  const Bounds2i region{{40, 24}, {90, 70}};
  Reconstruction r;
  RegionInfo info;
  ASSERT_TRUE(ReconstructRegion(provider, o, region, &r, &info).ok());
  ASSERT_TRUE(r.interpolation);
  const Bounds2i w = r.interpolation->window();
  EXPECT_EQ(w, info.window);
  std::vector<float> out;
  ASSERT_TRUE(r.interpolation->Apply(BeautyChannel(provider, w.width(), w.height(), 1, w.min), ChannelKind::kContinuous,
                                     &out)
                  .ok());
  for (int y = 0; y < r.workHeight; ++y)
    for (int x = 0; x < r.workWidth; ++x) {
      const float v = out[size_t(y + info.work.min.y - w.min.y) * size_t(w.width()) + size_t(x + info.work.min.x - w.min.x)];
      ASSERT_EQ(v, r.workImage[size_t(y) * size_t(r.workWidth) + size_t(x)].g) << x << "," << y;
    }
  // A channel of another size is refused with a message.
  const Status st = r.interpolation->Apply(std::vector<float>(3), ChannelKind::kContinuous, &out);
  EXPECT_FALSE(st.ok());
  EXPECT_NE(st.message().find("window"), std::string::npos) << st.message();
}

}  // namespace
}  // namespace dcm::testing
