// The engine's side of dcm::InterpolationRecord: each stage that writes a
// non-exact pixel's value also records its sources and weights here, when a
// record was asked for (the Engine holds no recorder otherwise). Stages run
// as parallel phases (Engine::ForEach) whose pixels do not read each other's
// writes; a record keeps each step's phase, and replays phase by phase.
#pragma once

#include <tbb/enumerable_thread_specific.h>

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "block.h"
#include "dcm/interpolation_record.h"
#include "oriented_interpolation.h"
#include "sample_store.h"

namespace dcm {

/// One recorded step (lib/src/interpolation_record.cpp replays them).
struct InterpolationRecord::Op {
  enum Kind : uint8_t {
    kFill,      ///< SampleStore::SetFilled of Lerp(term 0, term 1, t = weight 0)
    kSmooth,    ///< Engine::WriteSmooth of the block whose corners are terms 0..3
    kWeighted,  ///< WeightedSum of the terms (oriented elements, checkerboard fills)
    kLazyLeaf,  ///< a lazy leaf's correction: the prediction at its centre (`count` terms), then its border
    kLazy,      ///< a lazy leaf's pixel: WeightedSum, plus the tent (weight after the terms) times the correction
  };
  uint32_t phase = 0;
  uint32_t target = 0;  ///< the pixel written; kLazyLeaf: the leaf's centre
  uint32_t first = 0;   ///< the first term
  uint32_t extra = 0;   ///< kLazyLeaf: border pixels after the terms; kLazy: the leaf's centre
  uint32_t leaf = 0;    ///< kLazyLeaf, kLazy: the leaf's number (InterpolationRecorder::Finish)
  uint16_t count = 0;   ///< terms
  uint8_t kind = kWeighted;
  uint8_t zeroDelta = 0;  ///< kLazyLeaf: the noise explained the centre's miss: no correction
};

namespace detail {

/// Up to the eight exact neighbours of a checkerboard fill, with their weights.
struct NeighbourTerms {
  int64_t index[8] = {};
  double weight[8] = {};
  int count = 0;
};

class InterpolationRecorder {
 public:
  explicit InterpolationRecorder(const SampleStore& store) : store_(store) {}

  /// A parallel phase begins (Engine::ForEach).
  void NextPhase() { ++phase_; }

  /// Pixel i filled with Lerp(value(p), value(q), t) (SampleStore::SetFilled).
  void Fill(int64_t i, int64_t p, int64_t q, float t);
  /// A smooth leaf written bilinearly from its corners (Engine::WriteSmooth).
  void Smooth(const Block& b);
  /// Pixel i written with WeightedSum of the interpolant.
  void Weighted(int64_t i, const Interpolant& in);
  /// Pixel i written with WeightedSum of a checkerboard fill's neighbours.
  void Weighted(int64_t i, const NeighbourTerms& t);
  /// A lazy leaf accepted: `predicted` interpolated its centre, its finite
  /// border pixels bound its range; `zeroDelta` when it is not corrected.
  void LazyLeaf(Point2i centre, const Interpolant& predicted, std::span<const Point2i> border, bool zeroDelta);
  /// Pixel i of the lazy leaf with centre `centre`: the interpolant plus
  /// `tent` times the leaf's correction, clamped to its range.
  void Lazy(int64_t i, const Interpolant& in, Point2i centre, double tent);

  /// The record, the exact pixels as `reasons` (the final sample map) say.
  std::shared_ptr<InterpolationRecord> Finish(int width, int height, const std::vector<SampleReason>& reasons);

 private:
  struct Local {
    std::vector<InterpolationRecord::Op> ops;
    std::vector<uint32_t> index;
    std::vector<double> weight;
  };
  /// Appends term pixel i (marked when it is exact now) with weight w.
  void Term(Local& l, int64_t i, double w) const;
  InterpolationRecord::Op& Begin(Local& l, InterpolationRecord::Op::Kind kind, int64_t target) const;

  const SampleStore& store_;
  uint32_t phase_ = 0;
  tbb::enumerable_thread_specific<Local> local_;
};

}  // namespace detail
}  // namespace dcm
