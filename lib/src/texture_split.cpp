// The texture split (paper 3.3): where tau lets L_i = L_t / tau be recovered.
#include "texture_split.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <cstdint>
#include <limits>

namespace dcm::detail {

bool TauRecoverable(RGB tau) {
  for (int c = 0; c < 3; ++c)
    if (!std::isfinite(tau[c]) || std::fabs(tau[c]) < std::numeric_limits<float>::min()) return false;
  return true;
}

void RequestNonFiniteTau(const std::vector<RGB>& tau, SampleStore& store) {
  // In parallel: the requests are sorted before they are evaluated.
  tbb::parallel_for(0, store.height(), [&](int y) {
    const RGB* row = tau.data() + store.Index(0, y);
    const int width = store.width();
    // Nearly every row is finite throughout: one pass without branches
    // tells, and only the others look for their pixels.
    unsigned finite = 1;
    for (int x = 0; x < width; ++x) finite &= unsigned(IsFinite(row[x]));
    if (finite) return;
    for (int x = 0; x < width; ++x)
      if (!IsFinite(row[x])) store.Request(x, y, SampleReason::kFallback);
  });
}

}  // namespace dcm::detail
