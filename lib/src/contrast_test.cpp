#include "contrast_test.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dcm::detail {

namespace {

float Mitchell(float lo, float hi) {
  const float sum = hi + lo;
  // A black (or cancelling) set has no contrast: guard 0/0.
  if (!(std::fabs(sum) > 1e-12f)) return 0.f;
  return (hi - lo) / std::fabs(sum);
}

}  // namespace

float ContrastTest::Contrast(std::span<const Value> values) const {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  float loA = kInf, hiA = -kInf, loB = kInf, hiB = -kInf, loT = kInf, hiT = -kInf;
  for (const Value& v : values) {
    if (!IsFinite(v.a) || !IsFinite(v.b)) return kInf;
    const float la = Luminance(v.a);
    const float lb = split_ ? Luminance(v.b) : 0.f;
    loA = std::min(loA, la), hiA = std::max(hiA, la);
    loB = std::min(loB, lb), hiB = std::max(hiB, lb);
    loT = std::min(loT, la + lb), hiT = std::max(hiT, la + lb);
  }
  if (values.empty()) return 0.f;
  if (metric_ == ContrastMetric::kDisplay) {
    float c = SrgbEncode(hiA) - SrgbEncode(loA);
    if (split_) c = std::max(c, SrgbEncode(hiB) - SrgbEncode(loB));
    return c;
  }
  float c = Mitchell(loA, hiA);
  if (split_) {
    const float total = std::fabs(hiT) + std::fabs(loT);
    if (total > 1e-12f) c = std::max(c, (hiB - loB) / total);
  }
  return c;
}

}  // namespace dcm::detail
