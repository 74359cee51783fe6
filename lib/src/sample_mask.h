// What an exact sample holds, as bits of a SampleRequest: the caches of the
// quality search (quality_target.cpp, round_keeper.h) keep it per pixel, so
// that a pixel is rendered again only for what it lacks.
#pragma once

#include <cstdint>

#include "dcm/sample_provider.h"

namespace dcm::detail {

/// 1 (L) | 2 (the split) | 4 (the variance).
inline uint8_t RequestMask(const SampleRequest& w) { return uint8_t(1 | (w.split ? 2 : 0) | (w.variance ? 4 : 0)); }

}  // namespace dcm::detail
