// Small helpers shared by the engine tests.
#pragma once

#include <gtest/gtest.h>

#include "analytic_provider.h"
#include "dcm/reconstructor.h"

namespace dcm::testing {

/// Reconstructs and fails the test on an error.
inline Reconstruction ReconstructOrFail(SampleProvider& provider, const ReconstructionOptions& options) {
  Reconstruction r;
  const Status s = Reconstruct(provider, options, &r);
  EXPECT_TRUE(s.ok()) << s.message();
  return r;
}

/// Mean absolute luminance error over the pixels selected by `where`.
template <typename Pred>
double MeanLuminanceError(const Reconstruction& r, const std::vector<RGB>& ref, Pred where) {
  double sum = 0;
  int n = 0;
  for (int y = 0; y < r.workHeight; ++y)
    for (int x = 0; x < r.workWidth; ++x)
      if (where(x, y)) {
        const size_t i = size_t(y) * size_t(r.workWidth) + size_t(x);
        sum += std::fabs(Luminance(r.workImage[i]) - Luminance(ref[i]));
        ++n;
      }
  return n ? sum / n : 0;
}

}  // namespace dcm::testing
