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

/// The display-weighted metric's unit: SrgbRelativeSlope at mid-grey.
const float kMidGreySlope = SrgbRelativeSlope(0.18f);

/// The range of one luminance over a set, with the variances of its extremes.
struct Range {
  float lo = std::numeric_limits<float>::infinity(), hi = -std::numeric_limits<float>::infinity();
  float varLo = 0.f, varHi = 0.f;
  void Add(float v, float var) {
    if (v < lo) lo = v, varLo = var;
    if (v > hi) hi = v, varHi = var;
  }
  /// Shrinks the range by k standard deviations of hi - lo.
  void Discount(float k) {
    if (k <= 0.f || !(varLo + varHi > 0.f)) return;
    const float d = 0.5f * k * std::sqrt(varLo + varHi);
    if (hi - lo <= 2.f * d) {
      lo = hi = 0.5f * (lo + hi);
    } else {
      lo += d, hi -= d;
    }
  }
};

}  // namespace

float ContrastTest::Contrast(std::span<const Value> values) const {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  Range A, B, T;
  for (const Value& v : values) {
    if (!IsFinite(v.a) || !IsFinite(v.b)) return kInf;
    const float la = Luminance(v.a);
    const float lb = split_ ? Luminance(v.b) : 0.f;
    A.Add(la, v.varA);
    B.Add(lb, split_ ? v.varB : 0.f);
    T.Add(la * v.tau + lb, v.varA * v.tau * v.tau + (split_ ? v.varB : 0.f));
  }
  if (values.empty()) return 0.f;
  A.Discount(k_), B.Discount(k_), T.Discount(k_);
  if (metric_ == ContrastMetric::kDisplay) {
    float c = SrgbEncode(A.hi) - SrgbEncode(A.lo);
    if (split_) c = std::max(c, SrgbEncode(B.hi) - SrgbEncode(B.lo));
    return c;
  }
  float c = Mitchell(A.lo, A.hi);
  if (split_) {
    const float total = std::fabs(T.hi) + std::fabs(T.lo);
    if (total > 1e-12f) c = std::max(c, (B.hi - B.lo) / total);
  }
  if (metric_ == ContrastMetric::kDisplayWeighted) {
    c *= SrgbRelativeSlope(0.5f * (std::fabs(T.hi) + std::fabs(T.lo))) / kMidGreySlope;
  }
  return c;
}

bool ContrastTest::WithinNoise(const Value& p, const Value& q, float k) const {
  const float varA = p.varA + q.varA, varB = split_ ? p.varB + q.varB : 0.f;
  if (k_ <= 0.f || !(varA > 0.f || varB > 0.f)) return false;
  if (std::fabs(Luminance(p.a) - Luminance(q.a)) > k * std::sqrt(varA)) return false;
  return !split_ || std::fabs(Luminance(p.b) - Luminance(q.b)) <= k * std::sqrt(varB);
}

}  // namespace dcm::detail
