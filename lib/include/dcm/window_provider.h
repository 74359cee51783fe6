// Reconstructing a region of a frame in its own process (tiles on a cluster):
// a provider adapter that presents a window of the working image, the window
// a region needs for its pixels to be bit-identical to a whole-frame run, and
// a deterministic split of a frame into N tiles.
//
// Why a window with a halo: blocks lie on a lattice of `elementaryBlock`
// working pixels that starts at (0, 0), and every decision about a block
// depends on samples at its own pixels; but a pixel on a block side may be
// made exact (or filled along the side) by the refinement of the neighbouring
// block, and that block's refinement depends on its own neighbours' borders.
// So a region is reconstructed in a window grown outward to the lattice and
// then by RegionHaloBlocks() elementary blocks on each side (clamped to the
// frame), and cropped back. docs/TILES.md has the argument and the tests.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "dcm/geometry.h"
#include "dcm/options.h"
#include "dcm/reconstructor.h"
#include "dcm/sample_provider.h"
#include "dcm/status.h"

namespace dcm {

/// Elementary blocks of halo a region's lattice-aligned window needs for
/// bit-identity with the whole frame: 1 — a block's pixels depend on its
/// neighbours' refinement, not on blocks further away — and 2 when noisy
/// samples are denoised (a provider that reports variance, noiseSignificance
/// > 0 and denoiseSamples): each exact sample then becomes a fit over the exact
/// samples within one elementary block, which reach into the neighbours'
/// neighbours. tests/tiles checks both, and that one less is not enough.
int RegionHaloBlocks(const ReconstructionOptions& options, const ProviderCapabilities& caps);

/// Presents the working-pixel window `window` of `inner` as a whole image:
/// Capabilities() reports the window's size, Guides() and Evaluate() shift
/// their coordinates into the full image. `inner` must outlive the adapter.
class WindowProvider : public SampleProvider {
 public:
  /// Wraps `inner`; `window` must lie inside `inner`'s working image (see
  /// Validate()).
  WindowProvider(SampleProvider& inner, const Bounds2i& window);

  /// Checks that the window is non-empty and inside the inner provider's
  /// working image; the message gives both.
  Status Validate() const;

  /// The inner provider's capabilities with width and height of the window.
  ProviderCapabilities Capabilities() const override;

  /// Guides of `region` (window coordinates): the inner provider's guides of
  /// the same pixels, with `out->region` in window coordinates.
  Status Guides(const Bounds2i& region, const GuideRequest& what, GuideImage* out) override;

  /// Evaluates `pixels` (window coordinates) with the inner provider at the
  /// same pixels of the full image.
  Status Evaluate(std::span<const Point2i> pixels, const SampleRequest& what,
                  std::span<ExactSample> out) override;

  /// The window, in working pixels of the full image.
  const Bounds2i& window() const { return window_; }

 private:
  SampleProvider& inner_;
  Bounds2i window_;
  ProviderCapabilities innerCaps_;
};

/// Output size of a working image of workWidth x workHeight supersampled
/// `downsample` times per axis: ceil(work / downsample) per axis.
Point2i OutputSize(int workWidth, int workHeight, int downsample);

/// The working pixels whose box filter gives the output pixels of
/// `outputRegion`: outputRegion * downsample, clipped to the working image.
Bounds2i WorkRegion(const Bounds2i& outputRegion, int workWidth, int workHeight, int downsample);

/// The window (working pixels) in which `outputRegion` is reconstructed:
/// WorkRegion() grown outward to the lattice of `elementaryBlock` (the last
/// pixel of the window lies on a lattice line, so that the window's blocks are
/// the frame's), then by `haloBlocks` elementary blocks per side, clamped to
/// the working image.
Bounds2i RegionWindow(const Bounds2i& outputRegion, int workWidth, int workHeight, int downsample,
                      int elementaryBlock, int haloBlocks);

/// What ReconstructRegion() did besides the region's result.
struct RegionInfo {
  Bounds2i output;  ///< the region, output pixels
  int haloBlocks = 0;  ///< the halo used, in elementary blocks
  Bounds2i work;    ///< its working pixels (WorkRegion)
  Bounds2i window;  ///< the window reconstructed (RegionWindow)
  int frameWidth = 0, frameHeight = 0;          ///< output size of the whole frame
  int frameWorkWidth = 0, frameWorkHeight = 0;  ///< working size of the whole frame
  ReconstructionStats windowStats;  ///< the engine's statistics of the whole window (halo included)
};

/// Reconstructs the output pixels of `outputRegion` of `provider`'s frame,
/// bit-identical to the same pixels of Reconstruct() on the whole frame.
/// `out` then describes the region: width x height and `image` are the
/// region's output pixels; workWidth x workHeight, `workImage` and
/// `sampleMap` its working pixels (`info->work`); `blocks` the leaf blocks
/// that touch them, in full-frame coordinates; `stats` counts (total, exact,
/// by reason) over the region's working pixels, times and block counts over
/// the window. Pending pixels (sparse providers) are in full-frame
/// coordinates; `info` then describes the region and window already (its
/// windowStats only on success). The region must be a non-empty part of the
/// output frame.
/// `haloBlocks` < 0 takes RegionHaloBlocks(); other values are for tests.
Status ReconstructRegion(SampleProvider& provider, const ReconstructionOptions& options,
                         const Bounds2i& outputRegion, Reconstruction* out, RegionInfo* info = nullptr,
                         std::vector<Point2i>* pending = nullptr, int haloBlocks = -1);

/// How a frame of width x height output pixels is split into `count` tiles:
/// rows x columns with rows * columns == count, the factorisation whose tiles
/// are closest to square (ties: fewer rows).
Point2i TileGridShape(int width, int height, int count);

/// Tile `index` (0-based, row-major) of `count` tiles of a width x height
/// output frame. Tile boundaries are multiples of `align` output pixels
/// (e.g. elementaryBlock / downsample) where the frame is large enough,
/// otherwise as even as possible; every tile is non-empty and the tiles
/// cover the frame exactly once. The message names the offending value.
Status TileRegion(int width, int height, int index, int count, int align, Bounds2i* region);

}  // namespace dcm
