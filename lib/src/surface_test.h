// The object/shader surface test (paper 2.2 and 3.2, with dcm's creases):
// which pairs of pixels lie on the same surface, from the guides.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

namespace dcm::detail {

/// Regions of one object that creases cut off, found inside each cell of
/// `size` x `size` pixels of the lattice, its far border included (the
/// elementary block: every leaf block and its border lie in one cell). Local
/// to the cell, so that a window of the frame on the lattice decides as the
/// whole frame does (docs/TILES.md), and a crease that closes only far away
/// does not cut.
struct CellRegions {
  int size = 0;    ///< cell side, in pixels (its far border is size + 1)
  int cellsX = 0;  ///< cells per row
  /// Per cell, (size + 1)^2 labels, row-major from the cell's origin: equal
  /// labels are one region.
  std::vector<uint32_t> labels;
};

/// Per row of the frame, bit x set where SameAdjacent fails between (x, y)
/// and its right neighbour (`right`), or its neighbour below (`below`).
/// SameAdjacent of 4-neighbours depends on no cell: two of them on one object
/// and tau = 0 class with no crease between them are joined in every cell
/// that holds both (CellRegions).
struct AdjacentChanges {
  int words = 0;  ///< 64-bit words per row
  std::vector<uint64_t> right, below;
};

/// Which pairs of pixels lie on the same surface (paper 2.2 and 3.2).
class SurfaceTest {
 public:
  SurfaceTest() = default;
  /// `crease`: per pixel, bit 1 when a crease separates it from its right
  /// neighbour, bit 2 from the one below (from normal guides); may be null.
  /// `tauZero`: per pixel, 1 where tau is exactly zero (with the texture
  /// split); such pixels are another surface than those with tau != 0, since
  /// their L_i is unknown. May be null.
  /// `regions`: the regions of each cell (from normal guides; may be null):
  /// two pixels of one object that share a cell are one surface only when a
  /// path inside the cell joins them without crossing a crease.
  /// `changes`: AdjacentChanges built by BuildChanges for these guides (may
  /// be null: ChangeIn then tests each pair).
  SurfaceTest(const uint32_t* objectId, const uint32_t* shaderId, const uint8_t* crease = nullptr, int width = 0,
              const uint8_t* tauZero = nullptr, const CellRegions* regions = nullptr,
              const AdjacentChanges* changes = nullptr)
      : objectId_(objectId), shaderId_(shaderId), crease_(crease), tauZero_(tauZero), width_(width) {
    if (regions && !regions->labels.empty())
      regionLabels_ = regions->labels.data(), regionSize_ = regions->size, regionCellsX_ = regions->cellsX;
    if (changes && !changes->right.empty())
      changesRight_ = changes->right.data(), changesBelow_ = changes->below.data(), changesWords_ = changes->words;
  }
  bool enabled() const { return objectId_ != nullptr || crease_ != nullptr || tauZero_ != nullptr; }
  /// Without IDs everything is one surface; with object IDs only, equal IDs;
  /// with object and shader IDs, a surface changes where both differ.
  bool Same(int64_t i, int64_t j) const {
    if (tauZero_ && tauZero_[i] != tauZero_[j]) return false;
    if (!objectId_ || objectId_[i] == objectId_[j]) return !regionLabels_ || SameRegion(i, j);
    return shaderId_ && shaderId_[i] == shaderId_[j];
  }
  /// For 4-neighbours i and j: Same(), and no crease between them. A crease
  /// that does not close a region (a fold that fades out) still marks where
  /// a block has a surface change and where its border needs samples.
  bool SameAdjacent(int64_t i, int64_t j) const {
    if (!Same(i, j)) return false;
    if (!crease_) return true;
    const int64_t lo = std::min(i, j), hi = std::max(i, j);
    if (hi - lo == width_) return !(crease_[lo] & 2);
    if (hi - lo == 1) return !(crease_[lo] & 1);
    return true;  // not neighbours (the wrap of a degenerate block's loop)
  }

  /// Whether SameAdjacent fails for some pair of 4-neighbours inside
  /// [x0, x1] x [y0, y1]: a few words per row with AdjacentChanges, each pair
  /// tested without.
  bool ChangeIn(int x0, int y0, int x1, int y1) const;
  /// The AdjacentChanges of a width x height frame under this test (in
  /// parallel over rows).
  AdjacentChanges BuildChanges(int width, int height) const;

 private:
  bool SameRegion(int64_t i, int64_t j) const;

  const uint32_t* objectId_ = nullptr;
  const uint32_t* shaderId_ = nullptr;
  const uint8_t* crease_ = nullptr;
  const uint8_t* tauZero_ = nullptr;
  const uint32_t* regionLabels_ = nullptr;  ///< CellRegions::labels (its buffer outlives moves)
  int regionSize_ = 0, regionCellsX_ = 0;
  int width_ = 0;
  /// AdjacentChanges' rows (their buffers outlive moves), or null.
  const uint64_t* changesRight_ = nullptr;
  const uint64_t* changesBelow_ = nullptr;
  int changesWords_ = 0;
};

inline bool SurfaceTest::SameRegion(int64_t i, int64_t j) const {
  const int64_t w = width_, e = regionSize_;
  const int64_t xi = i % w, yi = i / w, xj = j % w, yj = j / w;
  const int64_t cx = std::min(xi, xj) / e, cy = std::min(yi, yj) / e;
  // No cell holds both: the IDs alone decide.
  if (std::max(xi, xj) > cx * e + e || std::max(yi, yj) > cy * e + e) return true;
  const uint32_t* cell = regionLabels_ + size_t(cy * regionCellsX_ + cx) * size_t((e + 1) * (e + 1));
  return cell[(yi - cy * e) * (e + 1) + (xi - cx * e)] == cell[(yj - cy * e) * (e + 1) + (xj - cx * e)];
}

}  // namespace dcm::detail
