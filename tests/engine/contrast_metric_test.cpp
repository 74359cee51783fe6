// The contrast metrics of the smooth/edge test: Mitchell's (max-min)/(max+min)
// and the display-weighted one, which scales it by how far a relative change
// at the set's luminance moves the sRGB-encoded value.
#include <gtest/gtest.h>

#include <array>

#include "../../lib/src/contrast_test.h"
#include "run_helpers.h"

namespace dcm::testing {
namespace {

using detail::ContrastTest;
using detail::Value;

Value Gray(float l) { return Value{RGB::Gray(l), RGB{}}; }

float Contrast(ContrastMetric m, float lo, float hi) {
  return ContrastTest(m, 0.14f, /*split=*/false).Contrast(std::array{Gray(lo), Gray(hi)});
}

TEST(DisplayWeightedContrast, IsMitchellsAtMidGrey) {
  // A pair whose mean is 0.18: the weight is 1 (float rounding of the slope).
  const float mitchell = Contrast(ContrastMetric::kMitchell, 0.16f, 0.20f);
  EXPECT_NEAR(mitchell, 0.04f / 0.36f, 1e-6f);
  EXPECT_NEAR(Contrast(ContrastMetric::kDisplayWeighted, 0.16f, 0.20f), mitchell, 1e-6f);
}

TEST(DisplayWeightedContrast, ScalesWithTheSlopeOfTheEncoding) {
  // The same relative change (Mitchell 1/2) at three levels: in the linear
  // toe of sRGB (mean 0.002) the weight is 12.92 L / slope(0.18); on the
  // power segment (mean 0.6) 1.055/2.4 L^(1/2.4) / slope(0.18); above white
  // (mean 4) the slope at 1, the brightest a display shows.
  const double mid = 1.055 / 2.4 * std::pow(0.18, 1 / 2.4);
  const double half = 0.5;
  EXPECT_NEAR(Contrast(ContrastMetric::kDisplayWeighted, 0.001f, 0.003f), half * 12.92 * 0.002 / mid, 1e-5);
  EXPECT_NEAR(Contrast(ContrastMetric::kDisplayWeighted, 0.3f, 0.9f),
              half * 1.055 / 2.4 * std::pow(0.6, 1 / 2.4) / mid, 1e-5);
  EXPECT_NEAR(Contrast(ContrastMetric::kDisplayWeighted, 2.f, 6.f), half * 1.055 / 2.4 / mid, 1e-5);
  // Mitchell's is the same at every level: it is invariant under exposure.
  EXPECT_NEAR(Contrast(ContrastMetric::kMitchell, 0.001f, 0.003f), half, 1e-6);
  EXPECT_NEAR(Contrast(ContrastMetric::kMitchell, 2.f, 6.f), half, 1e-6);
}

TEST(DisplayWeightedContrast, ADarkEdgeIsNoEdgeAndABrightGradientIs) {
  // At threshold 0.14: a step of Mitchell contrast 0.30 in the dark (0.002
  // to 0.0037, weight 0.17: 0.05) is not an edge; one of 0.098 on a bright
  // wall (0.55 to 0.67, weight 1.66: 0.16) is, where Mitchell's test calls
  // it smooth.
  const ContrastTest dw(ContrastMetric::kDisplayWeighted, 0.14f, false), m(ContrastMetric::kMitchell, 0.14f, false);
  EXPECT_TRUE(m.Differ(Gray(0.002f), Gray(0.0037f)));
  EXPECT_FALSE(dw.Differ(Gray(0.002f), Gray(0.0037f)));
  EXPECT_FALSE(m.Differ(Gray(0.55f), Gray(0.67f)));
  EXPECT_TRUE(dw.Differ(Gray(0.55f), Gray(0.67f)));
}

TEST(DisplayWeightedContrast, WeighsTheRadianceSeenWithTheSplit) {
  // With the texture split the weight is of L = L_i tau + L_c: light of 2
  // on a black-ish surface (tau 0.01) is dark on a display, so a 20 %
  // change of L_i there weighs little; on a white surface it weighs more
  // than at mid-grey.
  const ContrastTest dw(ContrastMetric::kDisplayWeighted, 0.14f, /*split=*/true);
  Value p{RGB::Gray(2.f), RGB{}}, q{RGB::Gray(2.5f), RGB{}};
  p.tau = q.tau = 0.01f;
  const float dark = dw.Contrast(std::array{p, q});
  p.tau = q.tau = 0.3f;
  const float bright = dw.Contrast(std::array{p, q});
  const float mitchell = 0.5f / 4.5f;
  EXPECT_LT(dark, 0.5f * mitchell);
  EXPECT_GT(bright, 1.5f * mitchell);
}

}  // namespace
}  // namespace dcm::testing
