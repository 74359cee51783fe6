#include "block.h"

#include <algorithm>

namespace dcm::detail {

namespace {
// Nominal lattice starts along one axis: every multiple of `size` below
// `extent - 1`, or just 0 for an extent of one pixel.
std::vector<int> Starts(int extent, int size) {
  std::vector<int> s;
  for (int v = 0; v < extent - 1 || (v == 0 && extent == 1); v += size) s.push_back(v);
  return s;
}
}  // namespace

std::vector<Block> LatticeBlocks(int width, int height, int size) {
  std::vector<Block> blocks;
  const auto xs = Starts(width, size), ys = Starts(height, size);
  blocks.reserve(xs.size() * ys.size());
  for (int y : ys)
    for (int x : xs)
      blocks.push_back({x, y, std::min(x + size, width - 1), std::min(y + size, height - 1), 0});
  return blocks;
}

void ChildBlocks(const Block& b, int childSize, int width, int height, std::vector<Block>* out) {
  for (int cy = b.y0; cy < b.y1 || cy == b.y0; cy += childSize) {
    if (cy > b.y0 && cy >= height - 1) break;
    for (int cx = b.x0; cx < b.x1 || cx == b.x0; cx += childSize) {
      if (cx > b.x0 && cx >= width - 1) break;
      out->push_back({cx, cy, std::min(cx + childSize, b.x1), std::min(cy + childSize, b.y1),
                      uint8_t(b.level + 1)});
      if (b.x1 == b.x0) break;
    }
    if (b.y1 == b.y0) break;
  }
}

void BorderLoop(const Block& b, std::vector<Point2i>* loop) {
  loop->clear();
  if (b.x1 == b.x0 || b.y1 == b.y0) {
    for (int y = b.y0; y <= b.y1; ++y)
      for (int x = b.x0; x <= b.x1; ++x) loop->push_back({x, y});
    return;
  }
  for (int x = b.x0; x < b.x1; ++x) loop->push_back({x, b.y0});
  for (int y = b.y0; y < b.y1; ++y) loop->push_back({b.x1, y});
  for (int x = b.x1; x > b.x0; --x) loop->push_back({x, b.y1});
  for (int y = b.y1; y > b.y0; --y) loop->push_back({b.x0, y});
}

}  // namespace dcm::detail
