// Supersampling: the working image is box-filtered down by s per axis.
#pragma once

#include <vector>

#include "dcm/color.h"

namespace dcm::detail {

/// Averages s x s boxes of `in` (w x h); partial boxes at the right and bottom
/// border average the pixels they have. Output size ceil(w/s) x ceil(h/s).
std::vector<RGB> BoxDownsample(const std::vector<RGB>& in, int w, int h, int s, int* outW, int* outH);

}  // namespace dcm::detail
