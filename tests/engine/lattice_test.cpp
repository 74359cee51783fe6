// The shared-corner lattice and the geometry of oriented finite elements.
#include <gtest/gtest.h>

#include <set>

#include "../../lib/src/block.h"
#include "../../lib/src/oriented_interpolation.h"

namespace dcm::detail {
namespace {

TEST(Lattice, BlocksShareCornersAndCoverTheImage) {
  const int W = 21, H = 13;
  const auto blocks = LatticeBlocks(W, H, 8);
  // Starts at 0, 8, 16 in x (16 < 20) and 0, 8 in y (8 < 12).
  ASSERT_EQ(blocks.size(), 6u);
  EXPECT_EQ(blocks[2].x0, 16);
  EXPECT_EQ(blocks[2].x1, 20);  // clipped by the image border
  EXPECT_EQ(blocks[5].y1, 12);
  // Every pixel lies in the closed region of at least one block.
  std::set<std::pair<int, int>> covered;
  for (const Block& b : blocks)
    for (int y = b.y0; y <= b.y1; ++y)
      for (int x = b.x0; x <= b.x1; ++x) covered.insert({x, y});
  EXPECT_EQ(covered.size(), size_t(W * H));
}

TEST(Lattice, OnePixelImagesHaveOneDegenerateBlock) {
  const auto blocks = LatticeBlocks(1, 1, 8);
  ASSERT_EQ(blocks.size(), 1u);
  EXPECT_EQ(blocks[0].x1, 0);
  EXPECT_FALSE(blocks[0].HasInterior());
  std::vector<Point2i> loop;
  BorderLoop(blocks[0], &loop);
  EXPECT_EQ(loop.size(), 1u);
}

TEST(Lattice, ChildrenTileTheParent) {
  Block parent{8, 0, 16, 8, 0};
  std::vector<Block> children;
  ChildBlocks(parent, 4, 100, 100, &children);
  ASSERT_EQ(children.size(), 4u);
  EXPECT_EQ(children[3].x0, 12);
  EXPECT_EQ(children[3].y1, 8);
  EXPECT_EQ(children[3].level, 1);
}

TEST(Lattice, BorderLoopVisitsEachBorderPixelOnce) {
  Block b{0, 0, 8, 8, 0};
  std::vector<Point2i> loop;
  BorderLoop(b, &loop);
  EXPECT_EQ(loop.size(), 32u);  // 4 * 8 for a 9x9 closed region
  std::set<std::pair<int, int>> unique;
  for (Point2i p : loop) unique.insert({p.x, p.y});
  EXPECT_EQ(unique.size(), loop.size());
}

TEST(OrientedElements, DiagonalLineThroughTheCentreEndsInOppositeCorners) {
  Block b{0, 0, 8, 8, 0};
  BorderPoint e;
  const Direction diag = Direction::Of(2, 8);  // 45 degrees
  ASSERT_TRUE(ExitPoint(b, 4, 4, diag, &e));
  EXPECT_NEAR(e.p0.x + e.w1 * (e.p1.x - e.p0.x), 8, 1e-12);
  EXPECT_NEAR(e.p0.y + e.w1 * (e.p1.y - e.p0.y), 8, 1e-12);
  EXPECT_NEAR(e.t, 4 * std::sqrt(2.0), 1e-12);
}

TEST(OrientedElements, LinesAlongTheBorderDoNotCount) {
  Block b{0, 0, 8, 8, 0};
  BorderPoint e;
  // From a pixel of the top side, a horizontal line runs along the border.
  EXPECT_FALSE(ExitPoint(b, 3, 0, Direction::Of(0, 8), &e));
  EXPECT_FALSE(ExitPoint(b, 3, 0, Direction{-1, 0}, &e));
  // A vertical one crosses to the bottom side.
  ASSERT_TRUE(ExitPoint(b, 3, 0, Direction::Of(4, 8), &e));
  EXPECT_EQ(e.p0.x, 3);
  EXPECT_EQ(e.p0.y, 8);
  EXPECT_EQ(e.w1, 0);
}

TEST(OrientedElements, ZeroWidthBlocksHaveNoElements) {
  Block b{5, 0, 5, 8, 0};
  BorderPoint e;
  EXPECT_FALSE(ExitPoint(b, 5, 4, Direction::Of(0, 8), &e));
  EXPECT_FALSE(ExitPoint(b, 5, 4, Direction::Of(4, 8), &e));
}

}  // namespace
}  // namespace dcm::detail
