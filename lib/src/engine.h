// The state of one reconstruction, shared by its stages. Each stage's member
// functions live in the file named after it; reconstructor.cpp holds the
// level loop that calls them in order.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <span>
#include <string_view>
#include <tuple>
#include <utility>
#include <vector>

#include "block.h"
#include "contrast_test.h"
#include "dcm/reconstructor.h"
#include "elapsed.h"
#include "interpolation_recorder.h"
#include "least_discrepancy_direction.h"
#include "oriented_interpolation.h"
#include "sample_store.h"
#include "settings.h"

namespace dcm::detail {

/// A block whose reconstruction is settled.
struct Leaf {
  Block block;
  BlockType type = BlockType::kSmooth;
  int8_t direction = -1;
  // Lazy leaves: the exact centre corrects the parent's interpolation.
  Point2i centre;
  Value delta;
  Value lo, hi;  // range of the samples the leaf interpolates
};

inline Leaf MakeLeaf(const Block& b, BlockType type, int dir = -1) {
  Leaf l;
  l.block = b;
  l.type = type;
  l.direction = int8_t(dir);
  return l;
}

/// An edge block with its border known.
struct EdgeBlock {
  Block block;
  std::vector<Point2i> border;
  DirectionChoice direction;
  std::vector<int> crossings;
  bool simple = false;
  bool probe = false;  ///< the finest level probes its centre
};

class Engine {
 public:
  Engine(SampleProvider& provider, const ReconstructionOptions& opt, const ProviderCapabilities& caps,
         const Settings& settings);

  /// The level loop (reconstructor.cpp).
  Status Run(Reconstruction* out, std::vector<Point2i>* pending);

 private:
  template <typename T, typename F>
  void ForEach(std::vector<T>& items, F&& f) {
    if (record_) record_->NextPhase();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, items.size(), grain_),
                      [&](const tbb::blocked_range<size_t>& r) {
                        for (size_t i = r.begin(); i != r.end(); ++i) f(items[i], i);
                      });
  }
  Status Flush() {
    return store_.Flush(provider_, request_, opt_.batchSize, caps_.threadSafe, &stats_, pending_);
  }
  void Progress(float f, std::string_view stage) {
    if (opt_.progress) opt_.progress(f, stage);
  }
  Value At(Point2i p) const { return store_.ValueAt(store_.Index(p.x, p.y)); }
  /// Runs stage `f` (returning Status or nothing) and adds its wall time,
  /// the provider's excluded, to `*slot` (ReconstructionStats::stageTimes).
  template <typename F>
  auto Timed(double* slot, F&& f) {
    const auto t0 = std::chrono::steady_clock::now();
    const double provider0 = stats_.timeProviderS + stats_.timeGuidesS;
    struct Add {
      double* slot;
      std::chrono::steady_clock::time_point t0;
      double provider0;
      const ReconstructionStats& stats;
      ~Add() {
        const double wall = SecondsSince(t0);
        *slot += std::max(0.0, wall - (stats.timeProviderS + stats.timeGuidesS - provider0));
      }
    } add{slot, t0, provider0, stats_};
    return f();
  }

  // Object/shader surface test (surface_test.cpp, paper 2.2, 3.2).
  Status LoadGuides();
  bool HasSurfaceChange(const Block& b) const;

  // Hierarchical refinement (hierarchical_refinement.cpp, paper 2.1, 2.2).
  /// Classifies the blocks of one level as smooth or edge: the edge blocks
  /// are appended to `edges`; a smooth block is a leaf, or its children go
  /// to `nextClassify` (and the block to `splitSmooth`) where the smooth
  /// refinement splits it.
  Status ClassifySmoothOrEdge(std::vector<Block>& classify, int size, bool finest, std::vector<Block>* edges,
                              std::vector<Block>* nextClassify, std::vector<Block>* splitSmooth);
  void RequestCorners(const Block& b) {
    for (Point2i p : {Point2i{b.x0, b.y0}, Point2i{b.x1, b.y0}, Point2i{b.x0, b.y1}, Point2i{b.x1, b.y1}})
      store_.Request(p.x, p.y, SampleReason::kCorner);
  }
  bool IsSmooth(const Block& b) const;
  /// Writes a smooth leaf's interior bilinearly from its corners.
  void WriteSmooth(const Leaf& leaf);
  /// The image as this level knows it, for progressive output: settled leaves,
  /// blocks split further interpolated bilinearly, edge blocks along their
  /// direction. Later passes overwrite every preview value.
  void WritePreview(int level, std::vector<Block>& splitSmooth, std::vector<EdgeBlock>& edges);

  // Edge-block borders: all of them (the paper) or adaptive (adaptive_borders.cpp).
  /// The border of every edge block of this level, known (exact or filled)
  /// when it returns.
  Status EvaluateBorders(std::vector<Block>& edges, bool belowElementary, std::vector<EdgeBlock>* eb);
  Status EvaluateBordersAdaptively(const std::vector<Block>& edges, bool belowElementary);

  // Least-discrepancy direction (paper 2.1; least_discrepancy_direction.cpp).
  /// Each block's direction and the significant changes along its border.
  void OrientEdgeBlocks(std::vector<EdgeBlock>& eb);

  // Simple/complex classification (simple_complex_classification.cpp, paper 2.3).
  Status ClassifySimpleOrComplex(std::vector<EdgeBlock>& eb);

  // Lazy boundary evaluation (lazy_boundary_evaluation.cpp, paper 2.1).
  /// Settles the simple blocks whose parent's interpolation predicts their
  /// centre; the others' children go to `nextEdges`.
  Status EvaluateLazily(std::vector<EdgeBlock>& eb, int size, std::vector<Block>* nextEdges);

  // Finest level: fallback (finest_fallback.cpp) and centre probes (centre_probes.cpp).
  /// Settles the finest edge blocks: oriented leaves, or fallback leaves
  /// whose interior is evaluated.
  Status SettleFinest(std::vector<EdgeBlock>& eb);
  /// Probes the centres of the finest blocks that want it and marks those
  /// whose interpolation misses it in `fallback`.
  Status ProbeCentres(std::vector<EdgeBlock>& eb, std::vector<uint8_t>& fallback);
  /// Requests the interior (and the border pixels still unknown) of every
  /// fallback leaf.
  void RequestFallbackInteriors();
  /// With the split: L_c is at most probeLcShare of L at every finite pixel
  /// of the border, which the centre probe then need not search for a
  /// highlight or a reflection.
  bool LooksDiffuse(std::span<const Point2i> border) const;
  /// The finest edge block's centre is probed: its border shows
  /// `shadingChanges` > 0 significant changes that no surface change
  /// explains (a shading edge of unknown shape), or glossy light that may
  /// hide a highlight or a reflection (not LooksDiffuse).
  bool ProbeWanted(const EdgeBlock& e, int shadingChanges) const {
    return shadingChanges > 0 || !LooksDiffuse(e.border);
  }

  // Thin-object test (thin_object_test.cpp, paper 3.1).
  /// Resolves the interpolant of interior pixel q against the surfaces and the
  /// finite samples. Returns the reason q must be exact, or kInterpolated.
  SampleReason ResolveInterpolant(Point2i q, Interpolant* in) const;
  /// For interior pixel q of an oriented leaf that the thin-object test
  /// rejects along the leaf's direction: the interpolant along the nearest
  /// neighbouring direction that passes it and whose ends agree
  /// (neighbourDirections each side), or kThinObject. With `anyEnds`, where
  /// no such direction's ends agree, the nearest that passes the test.
  SampleReason ResolveAlongNeighbours(const Leaf& leaf, Point2i q, Interpolant* in, bool anyEnds = false) const;
  /// The interpolant's two border points, each on its own, do not differ
  /// significantly (false when one has no sample).
  bool EndsAgree(const Interpolant& in) const;
  /// For interior pixel q of an oriented leaf whose interpolant serves one
  /// border point only (OneEnded): the interpolant along the direction, of
  /// all K, whose two border points lie on q's surface and differ least.
  /// False when no direction has both on q's surface.
  bool LeastDifferentTwoEnded(const Leaf& leaf, Point2i q, Interpolant* in) const;

  // Oriented elements (interpolation_pass.cpp, paper 2.1).
  /// What InterpolateOriented does with the interior pixels of a leaf.
  enum class OrientedPass {
    kPreview,     ///< write what it can interpolate, leave the rest as it is
    kThinObjects, ///< only request (with ResolveInterpolant's reason) what it cannot
    kFinal,       ///< write what it can, request the rest
    /// after kThinObjects and denoising: write every pixel that pass let
    /// through (its decisions were on the raw samples; denoised ends may no
    /// longer agree), request what it could not have
    kDenoised,
  };
  /// Interpolates the pixels of an oriented leaf that are not exact along
  /// the leaf's direction (2.1), the thin-object test (3.1) deciding which
  /// ones must be exact instead.
  void InterpolateOriented(const Leaf& leaf, OrientedPass pass);
  /// The final interpolation of every leaf: thin objects first, then (after
  /// denoising the samples, where they are noisy) the values.
  Status InterpolateLeaves();
  /// The prepared oriented elements of b's shape along direction k, or null.
  const OrientedElements* ElementsOf(const Block& b, int k) const {
    const auto table = elements_.find(std::tuple(b.width(), b.height(), k));
    return table == elements_.end() ? nullptr : &table->second;
  }
  /// The interpolant of q in b along direction k: from `elements`
  /// (ElementsOf(b, k), looked up once per leaf) when prepared.
  bool InterpolantAlong(const OrientedElements* elements, const Block& b, Point2i q, int k, Interpolant* in) const {
    return elements ? elements->At(store_, b, q, in)
                    : OrientedInterpolant(store_, b, q, Direction::Of(k, settings_.directions), in);
  }
  /// Builds the oriented elements of the leaves' shapes and directions and
  /// their neighbouring directions, before the passes that read them in
  /// parallel.
  void PrepareElements(const std::vector<Leaf>& leaves);
  /// The neighbouring directions tried each side: neighbourDirections, at
  /// most K/2 (every direction).
  int NeighbourSteps() const { return std::min(opt_.neighbourDirections, settings_.directions / 2); }
  /// Direction k turned by `step` directions (modulo the K directions).
  int Turned(int k, int step) const {
    const int K = settings_.directions;
    return ((k + step) % K + K) % K;
  }

  // Checkerboard refinement (checkerboard_fill.cpp, dcm's own).
  /// Asks for (x, y) exactly, or defers it to ResolveDeferred when the
  /// checkerboard refinement holds it back.
  void RequestOrDefer(int x, int y, SampleReason reason);
  bool IsDeferred(int64_t i) const { return !deferred_.empty() && deferred_[size_t(i)] != SampleReason::kInterpolated; }
  /// Each deferred pixel is filled from its exact neighbours when they agree
  /// (written now when `write`), or evaluated.
  Status ResolveDeferred(bool write);
  /// Writes the deferred pixels ResolveDeferred filled, from the exact
  /// neighbours as they are now (denoised).
  void WriteFilledDeferred();

  void RecordLeaves(Reconstruction* out);

  SampleProvider& provider_;
  const ReconstructionOptions& opt_;
  ProviderCapabilities caps_;
  const Settings settings_;
  int block_;  ///< the elementary block (Settings::elementaryBlock)
  SampleStore store_;
  ContrastTest contrast_;
  SampleRequest request_;
  size_t grain_ = 1;
  ReconstructionStats stats_;
  std::vector<Point2i>* pending_ = nullptr;
  std::vector<Leaf> smoothLeaves_, orientedLeaves_, fallbackLeaves_;
  /// Checkerboard refinement: per pixel, the reason a pixel of the colour
  /// evaluated second is wanted exact (kInterpolated: none), until
  /// ResolveDeferred decides; `filledDeferred_` then lists those filled.
  std::vector<SampleReason> deferred_;
  std::vector<int64_t> filledDeferred_;
  /// The direction search's geometry per block shape (width, height), built
  /// before each search; read-only while the blocks run in parallel.
  std::map<std::pair<int, int>, BorderPairs> borderPairs_;
  /// The interpolants of interior pixels per (width, height, direction) of
  /// the oriented leaves and their neighbouring directions (PrepareElements).
  std::map<std::tuple<int, int, int>, OrientedElements> elements_;
  /// ReconstructionOptions::recordInterpolation: the steps that write
  /// pixels record themselves here (interpolation_recorder.h); null otherwise.
  std::unique_ptr<InterpolationRecorder> record_;
};

}  // namespace dcm::detail
