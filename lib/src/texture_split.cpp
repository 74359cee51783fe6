// The texture split (paper 3.3): where tau lets L_i = L_t / tau be recovered.
#include "texture_split.h"

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
  for (int64_t i = 0; i < int64_t(tau.size()); ++i)
    if (!IsFinite(tau[size_t(i)]))
      store.Request(int(i % store.width()), int(i / store.width()), SampleReason::kFallback);
}

}  // namespace dcm::detail
