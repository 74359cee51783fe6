// Normal guides: a crease inside one object with one material (a room's wall
// meeting its ceiling) is a surface change, though no ID marks it.
#include <gtest/gtest.h>

#include <cmath>

#include "run_helpers.h"

namespace dcm::testing {
namespace {

constexpr int kSize = 128;
constexpr int kCrease = 70;  ///< the fold, off the block lattice

/// One object, one shader, folded along x = kCrease: the light falls off on
/// both sides at different slopes (continuous at the fold, so its contrast is
/// small, yet bilinear interpolation across it bends the wrong way). The
/// normals turn by 90 degrees at the fold.
PixelTruth Folded(int x, int) {
  PixelTruth t;
  const float l = x < kCrease ? 0.2f + 0.006f * float(x) : 0.2f + 0.006f * float(kCrease) - 0.009f * float(x - kCrease);
  t.Li = RGB(l, l, l);
  t.normal = x < kCrease ? Vec3f{1.f, 0.f, 0.f} : Vec3f{0.f, 1.f, 0.f};
  return t;
}

double ErrorNearTheFold(const ReconstructionOptions& o, bool normals, double* exactFraction = nullptr) {
  AnalyticChannels ch;
  ch.normals = normals;
  AnalyticProvider p(kSize, kSize, Folded, ch);
  const Reconstruction r = ReconstructOrFail(p, o);
  if (exactFraction) *exactFraction = r.stats.exactFraction();
  EXPECT_EQ(r.stats.usedNormals, normals && o.creaseAngle > 0.f);
  const std::vector<RGB> truth = p.FullRender();
  return MeanLuminanceError(r, truth, [](int x, int) { return std::abs(x - kCrease) <= 8; });
}

TEST(Crease, NormalsMarkTheFold) {
  // Without normals the fold sits inside smooth blocks and is interpolated
  // across; with them its blocks are edge blocks with samples at the fold.
  // Measured: the mean error near the fold falls from 0.026 to float
  // rounding (the light is linear along the fold), for 1.2 -> 1.5 % exact
  // pixels; 3x is asked.
  const double blind = ErrorNearTheFold({}, false), seeing = ErrorNearTheFold({}, true);
  EXPECT_LT(seeing * 3, blind) << "with normals " << seeing << ", without " << blind;
}

TEST(Crease, CreaseAngleZeroIgnoresNormals) {
  // Bit for bit the result without normal guides.
  ReconstructionOptions off;
  off.creaseAngle = 0.f;
  AnalyticChannels ch;
  ch.normals = true;
  AnalyticProvider withNormals(kSize, kSize, Folded, ch), without(kSize, kSize, Folded);
  const Reconstruction a = ReconstructOrFail(withNormals, off), b = ReconstructOrFail(without, {});
  ASSERT_EQ(a.workImage.size(), b.workImage.size());
  for (size_t i = 0; i < a.workImage.size(); ++i) ASSERT_EQ(a.workImage[i], b.workImage[i]) << "pixel " << i;
}

TEST(Crease, SmoothlyCurvedSurfacesAreNotCreases) {
  // A cylinder-like surface whose normal turns by 2 degrees per pixel: no two
  // neighbours differ by 30 degrees, so no crease and no extra samples.
  const SceneFunction curved = [](int x, int) {
    PixelTruth t;
    const float a = 0.035f * float(x);
    t.Li = RGB::Gray(0.3f + 0.2f * std::cos(a));
    t.normal = {std::sin(a), 0.f, std::cos(a)};
    return t;
  };
  AnalyticChannels ch;
  ch.normals = true;
  AnalyticProvider withNormals(kSize, kSize, curved, ch), without(kSize, kSize, curved);
  EXPECT_EQ(ReconstructOrFail(withNormals, {}).stats.exactPixels, ReconstructOrFail(without, {}).stats.exactPixels);
}

}  // namespace
}  // namespace dcm::testing
