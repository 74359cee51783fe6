// The least-discrepancy direction of an edge block (paper 2.1, Figure 2).
#pragma once

#include <span>

#include "block.h"
#include "oriented_interpolation.h"
#include "sample_store.h"

namespace dcm::detail {

struct DirectionChoice {
  int index = 0;             ///< k of theta_k = k*pi/K
  double discrepancy = 0;    ///< mean squared difference over valid pairs
};

/// For each candidate direction, the mean over border pixels p of
/// |L(p) - L(p')|^2 (all interpolated channels), where p' is where the line
/// through p along the direction leaves the block. The mean, not the sum: the
/// number of valid pairs depends on the direction. Pairs with a non-finite
/// sample are left out. Ties go to the smaller k. `border` is the block's
/// border loop; all its pixels must be known.
DirectionChoice LeastDiscrepancyDirection(const SampleStore& store, const Block& b,
                                          std::span<const Point2i> border, int directions);

}  // namespace dcm::detail
