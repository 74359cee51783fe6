// The least-discrepancy direction of an edge block (paper 2.1, Figure 2).
#pragma once

#include <span>
#include <vector>

#include "block.h"
#include "oriented_interpolation.h"
#include "sample_store.h"

namespace dcm::detail {

struct DirectionChoice {
  int index = 0;             ///< k of theta_k = k*pi/K
  double discrepancy = 0;    ///< mean squared difference over valid pairs
};

/// The border pairs of one block shape: for each candidate direction, each
/// border pixel p (an index into BorderLoop) and where the line through p
/// along the direction leaves the block again (two border pixels and the
/// weight between them, ExitPoint). Block-local, so all blocks of one shape
/// share one table: the search then reads samples and does no geometry.
class BorderPairs {
 public:
  struct Pair {
    int p;       ///< border index of the pixel
    int e0, e1;  ///< border indices of the exit point's two pixels
    double w1;   ///< weight of e1
  };
  /// `width`, `height` in pixel steps (Block::width()).
  BorderPairs(int width, int height, int directions);
  int directions() const { return directions_; }
  /// The pairs of direction k, in border order.
  std::span<const Pair> Of(int k) const {
    return std::span(pairs_).subspan(start_[size_t(k)], start_[size_t(k) + 1] - start_[size_t(k)]);
  }

 private:
  int directions_;
  std::vector<Pair> pairs_;
  std::vector<size_t> start_;
};

/// For each candidate direction, the mean over border pixels p of
/// |L(p) - L(p')|^2 (all interpolated channels), where p' is where the line
/// through p along the direction leaves the block. The mean, not the sum: the
/// number of valid pairs depends on the direction. Pairs with a non-finite
/// sample are left out. Ties go to the smaller k. `border` is the block's
/// border loop; all its pixels must be known. `pairs` is the table of the
/// block's shape.
DirectionChoice LeastDiscrepancyDirection(const SampleStore& store, std::span<const Point2i> border,
                                          const BorderPairs& pairs);

}  // namespace dcm::detail
