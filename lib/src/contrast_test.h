// The contrast test of the smooth/edge classification (paper 2.2) and the
// "significant change" between two samples used by the simple/complex tests
// (2.3) and the lazy evaluation.
#pragma once

#include <span>

#include "dcm/options.h"
#include "sample_store.h"

namespace dcm::detail {

class ContrastTest {
 public:
  ContrastTest(ContrastMetric metric, float threshold, bool split)
      : metric_(metric), threshold_(threshold), split_(split) {}

  /// Contrast of a set of values; +infinity when any is not finite.
  /// Mitchell: (max-min)/(max+min) of luminance (0 for a black set). With the
  /// texture split, L_i is measured by its own Mitchell contrast and the
  /// change of L_c against the total L_i + L_c of the set, since L_c is near
  /// zero on diffuse surfaces and its own contrast would be noise.
  /// Display: the range of sRGB-encoded luminance clipped to [0,1].
  float Contrast(std::span<const Value> values) const;

  /// True when the contrast of the set exceeds the threshold.
  bool IsEdge(std::span<const Value> values) const { return !(Contrast(values) <= threshold_); }

  /// True when two values differ significantly (their pair is an edge).
  bool Differ(const Value& p, const Value& q) const {
    const Value pair[2] = {p, q};
    return IsEdge(pair);
  }

  float threshold() const { return threshold_; }

 private:
  ContrastMetric metric_;
  float threshold_;
  bool split_;
};

}  // namespace dcm::detail
