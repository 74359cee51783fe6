// Supersampling: the working image is box-filtered down by s per axis.
#pragma once

#include <span>
#include <vector>

#include "dcm/color.h"

namespace dcm {

/// Averages s x s boxes of `in` (w x h, row-major); partial boxes at the right
/// and bottom border average the pixels they have (s < 1 counts as 1). Output
/// size ceil(w/s) x ceil(h/s); all zero when `in` holds fewer than w*h pixels.
std::vector<RGB> BoxDownsample(std::span<const RGB> in, int w, int h, int s, int* outW, int* outH);

/// Output pixel (ox, oy) of BoxDownsample(in, w, h, s, ...), bit for bit:
/// the mean of the pixels of its s x s box that lie in the w x h image.
/// `in` holds w*h pixels; the box holds at least one (ox < ceil(w/s), oy <
/// ceil(h/s)).
RGB BoxMean(std::span<const RGB> in, int w, int h, int s, int ox, int oy);

}  // namespace dcm
