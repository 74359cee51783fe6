// Blocks on the shared-corner lattice: a block of nominal size S at level l
// covers pixels [x0, x1] x [y0, y1] (corners inclusive) with x0 = i*S and
// x1 = min(x0 + S, width - 1); neighbours share their border pixels.
#pragma once

#include <cstdint>
#include <vector>

#include "dcm/geometry.h"

namespace dcm::detail {

struct Block {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  ///< inclusive corners
  uint8_t level = 0;

  int width() const { return x1 - x0; }   ///< in pixel steps (pixels - 1)
  int height() const { return y1 - y0; }
  bool HasInterior() const { return x1 - x0 >= 2 && y1 - y0 >= 2; }
  Point2i Centre() const { return {(x0 + x1) / 2, (y0 + y1) / 2}; }
};

/// The level-0 blocks of a width x height image with elementary size `size`,
/// row-major.
std::vector<Block> LatticeBlocks(int width, int height, int size);

/// The (up to four) children of `b` at the next level, whose nominal size is
/// `childSize`, clipped to the image; appended to `out`.
void ChildBlocks(const Block& b, int childSize, int width, int height, std::vector<Block>* out);

/// The border pixels of `b` as a closed loop (clockwise from (x0, y0)), each
/// once. Degenerate blocks (width or height 0) give their pixels in order.
void BorderLoop(const Block& b, std::vector<Point2i>* loop);

}  // namespace dcm::detail
