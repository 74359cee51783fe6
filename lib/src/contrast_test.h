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
  /// `significance` k: with noisy values, the range of a set is first reduced
  /// by k standard deviations of the difference of its extremes, so that only
  /// differences significant given the noise count. 0: the paper's test.
  ContrastTest(ContrastMetric metric, float threshold, bool split, float significance = 0.f)
      : metric_(metric), threshold_(threshold), split_(split), k_(significance) {}

  /// Contrast of a set of values; +infinity when any is not finite.
  /// Mitchell: (max-min)/(max+min) of luminance (0 for a black set). With the
  /// texture split, L_i is measured by its own Mitchell contrast and the
  /// change of L_c against the radiance L = L_i tau + L_c of the set
  /// (Value::tau), since L_c is near zero on diffuse surfaces and its own
  /// contrast would be noise: a highlight on a dark glossy surface is a large
  /// change of L though L_i, the light arriving, is bright.
  /// Display: the range of sRGB-encoded luminance clipped to [0,1].
  /// With noise, each range [lo, hi] shrinks to [lo + d/2, hi - d/2] with
  /// d = k sqrt(var(lo) + var(hi)) (no contrast when it closes).
  float Contrast(std::span<const Value> values) const;

  /// True when the contrast of the set exceeds the threshold.
  bool IsEdge(std::span<const Value> values) const { return !(Contrast(values) <= threshold_); }

  /// True when two values differ significantly (their pair is an edge).
  bool Differ(const Value& p, const Value& q) const {
    const Value pair[2] = {p, q};
    return IsEdge(pair);
  }

  /// True when the exact value of a pixel differs significantly from its
  /// prediction, both weighed at that pixel's tau (a prediction carries the
  /// tau of the samples it came from).
  bool Misses(const Value& exact, Value predicted) const {
    predicted.tau = exact.tau;
    return Differ(exact, predicted);
  }

  /// True when noise alone may explain the difference of p and q: it is
  /// within k standard deviations in the luminance of a and (with the split)
  /// of b. Always false for noiseless values or k = 0.
  bool WithinNoise(const Value& p, const Value& q) const { return WithinNoise(p, q, k_); }
  /// The same with k standard deviations instead of the test's own (still
  /// false for noiseless values, and when the test ignores noise).
  bool WithinNoise(const Value& p, const Value& q, float k) const;

  float threshold() const { return threshold_; }

 private:
  ContrastMetric metric_;
  float threshold_;
  bool split_;
  float k_;
};

}  // namespace dcm::detail
