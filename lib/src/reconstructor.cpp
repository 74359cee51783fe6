// The DCM driver: level by level, phase by phase (collect requests, evaluate
// the batch, classify, next requests). Every decision about a block depends
// only on samples at its own pixels, and requests are deduplicated per phase,
// so the result is the same for any thread count and tile size.
#include "dcm/reconstructor.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <tuple>

#include "block.h"
#include "checkerboard_fill.h"
#include "contrast_test.h"
#include "dcm/downsample.h"
#include "edge_classification.h"
#include "least_discrepancy_direction.h"
#include "oriented_interpolation.h"
#include "sample_denoising.h"
#include "sample_store.h"

namespace dcm {

std::string_view ToString(SampleReason r) {
  switch (r) {
    case SampleReason::kInterpolated: return "interpolated";
    case SampleReason::kCorner: return "corner";
    case SampleReason::kBorder: return "border";
    case SampleReason::kFirstOrderProbe: return "first_order_probe";
    case SampleReason::kLazyCentre: return "lazy_centre";
    case SampleReason::kCentreProbe: return "centre_probe";
    case SampleReason::kThinObject: return "thin_object";
    case SampleReason::kFallback: return "fallback";
    case SampleReason::kFull: return "full";
    case SampleReason::kCount: break;
  }
  return "?";
}

std::string_view ToString(BlockType t) {
  switch (t) {
    case BlockType::kSmooth: return "smooth";
    case BlockType::kSimpleEdge: return "simple_edge";
    case BlockType::kComplexEdge: return "complex_edge";
    case BlockType::kLazy: return "lazy";
    case BlockType::kFallback: return "fallback";
  }
  return "?";
}

namespace detail {
namespace {

using Clock = std::chrono::steady_clock;

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

Leaf MakeLeaf(const Block& b, BlockType type, int dir = -1) {
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
         bool split)
      : provider_(provider),
        opt_(opt),
        caps_(caps),
        split_(split),
        noisy_(NoisySamples(opt, caps)),
        block_(ElementaryBlock(opt, caps)),
        supersampledRules_(opt.SupersampledRules(noisy_)),
        directions_(opt.DirectionsFor(supersampledRules_)),
        thinTest_(opt.ThinObjectsFor(supersampledRules_)),
        crossingFillReach_(opt.CrossingFillReachFor(supersampledRules_)),
        smoothRefinement_(UsedSmoothRefinement(opt, caps)),
        store_(caps.width, caps.height, split, noisy_),
        contrast_(opt.ContrastMetricFor(supersampledRules_), opt.ContrastThresholdFor(supersampledRules_), split, noisy_ ? opt.noiseSignificance : 0.f) {
    const int blocksPerTile = std::max(1, opt.tileSize / std::max(1, block_));
    grain_ = size_t(blocksPerTile) * size_t(blocksPerTile);
    request_.split = split;
    request_.variance = noisy_;
  }

  Status Run(Reconstruction* out, std::vector<Point2i>* pending);

 private:
  template <typename T, typename F>
  void ForEach(std::vector<T>& items, F&& f) {
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

  Status LoadGuides();
  Status EvaluateBordersAdaptively(const std::vector<Block>& edges, bool belowElementary);
  void RequestCorners(const Block& b) {
    for (Point2i p : {Point2i{b.x0, b.y0}, Point2i{b.x1, b.y0}, Point2i{b.x0, b.y1}, Point2i{b.x1, b.y1}})
      store_.Request(p.x, p.y, SampleReason::kCorner);
  }
  Value At(Point2i p) const { return store_.ValueAt(store_.Index(p.x, p.y)); }
  bool IsSmooth(const Block& b) const;
  bool HasSurfaceChange(const Block& b) const;

  /// Resolves the interpolant of interior pixel q against the surfaces and the
  /// finite samples. Returns the reason q must be exact, or kInterpolated.
  SampleReason Resolve(Point2i q, Interpolant* in) const;
  /// With the split: L_c is at most probeLcShare of L at every finite pixel
  /// of the border, which the centre probe then need not search for a
  /// highlight or a reflection.
  bool LooksDiffuse(std::span<const Point2i> border) const {
    if (!split_ || !(opt_.probeLcShare > 0)) return false;
    for (Point2i p : border) {
      if (!store_.IsFinite(store_.Index(p.x, p.y))) continue;
      const Value v = At(p);
      const double lc = Luminance(v.b), l = Luminance(v.a) * v.tau + lc;
      if (!(lc <= opt_.probeLcShare * l)) return false;
    }
    return true;
  }
  /// The finest edge block's centre is probed: its border shows
  /// `shadingChanges` > 0 significant changes that no surface change
  /// explains (a shading edge of unknown shape), or glossy light that may
  /// hide a highlight or a reflection (not LooksDiffuse).
  bool ProbeWanted(const EdgeBlock& e, int shadingChanges) const {
    return shadingChanges > 0 || !LooksDiffuse(e.border);
  }
  /// For interior pixel q of an oriented leaf that the thin-object test
  /// rejects along the leaf's direction: the interpolant along the nearest
  /// neighbouring direction that passes it and whose ends agree
  /// (neighbourDirections each side), or kThinObject.
  SampleReason ResolveAlongNeighbours(const Leaf& leaf, Point2i q, Interpolant* in) const;
  /// The interpolant's two border points, each on its own, do not differ
  /// significantly (false when one has no sample).
  bool EndsAgree(const Interpolant& in) const;
  /// For interior pixel q of an oriented leaf whose interpolant serves one
  /// border point only (OneEnded): the interpolant along the direction, of
  /// all K, whose two border points lie on q's surface and differ least.
  /// False when no direction has both on q's surface.
  bool LeastDifferentTwoEnded(const Leaf& leaf, Point2i q, Interpolant* in) const;
  void WriteSmooth(const Leaf& leaf);
  /// The image as this level knows it, for progressive output: settled leaves,
  /// blocks split further interpolated bilinearly, edge blocks along their
  /// direction. Later passes overwrite every preview value.
  void WritePreview(int level, std::vector<Block>& splitSmooth, std::vector<EdgeBlock>& edges);
  /// What InterpolateOriented does with the interior pixels of a leaf.
  enum class OrientedPass {
    kPreview,     ///< write what it can interpolate, leave the rest as it is
    kThinObjects, ///< only request (with Resolve's reason) what it cannot
    kFinal,       ///< write what it can, request the rest
  };
  /// Interpolates the pixels of an oriented leaf that are not exact along
  /// the leaf's direction (2.3), the thin-object test (3.1) deciding which
  /// ones must be exact instead.
  void InterpolateOriented(const Leaf& leaf, OrientedPass pass);
  void RecordLeaves(Reconstruction* out);

  SampleProvider& provider_;
  const ReconstructionOptions& opt_;
  ProviderCapabilities caps_;
  bool split_;
  bool noisy_;  ///< samples carry their variance and the tests weigh it
  int block_;   ///< the elementary block (ReconstructionOptions::ElementaryBlockFor)
  bool supersampledRules_;   ///< ReconstructionOptions::SupersampledRules
  int directions_;           ///< ReconstructionOptions::DirectionsFor the rules
  ThinObjectTest thinTest_;  ///< ReconstructionOptions::ThinObjectsFor the rules
  int crossingFillReach_;    ///< ReconstructionOptions::CrossingFillReachFor the rules
  SmoothRefinement smoothRefinement_;  ///< UsedSmoothRefinement: kNever where the guides show the hard shadows
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
  /// Asks for (x, y) exactly, or defers it to ResolveDeferred when the
  /// checkerboard refinement holds it back.
  void RequestOrDefer(int x, int y, SampleReason reason) {
    const int64_t i = store_.Index(x, y);
    if (store_.IsExact(i)) return;  // a probe inside a fallback block, say
    if (opt_.checkerboard && !EvaluatedFirst(x, y)) deferred_[size_t(i)] = reason;
    else store_.Request(x, y, reason);
  }
  bool IsDeferred(int64_t i) const { return !deferred_.empty() && deferred_[size_t(i)] != SampleReason::kInterpolated; }
  /// Each deferred pixel is filled from its exact neighbours when they agree
  /// (written now when `write`), or evaluated.
  Status ResolveDeferred(bool write);
  /// Writes the deferred pixels ResolveDeferred filled, from the exact
  /// neighbours as they are now (denoised).
  void WriteFilledDeferred();
  /// The direction search's geometry per block shape (width, height), built
  /// by PrepareBorderPairs before each search; read-only while the blocks run
  /// in parallel.
  std::map<std::pair<int, int>, BorderPairs> borderPairs_;
  void PrepareBorderPairs(const std::vector<EdgeBlock>& blocks) {
    for (const EdgeBlock& e : blocks) {
      const auto shape = std::pair(e.block.width(), e.block.height());
      if (!borderPairs_.contains(shape)) borderPairs_.try_emplace(shape, shape.first, shape.second, directions_);
    }
  }
  /// The interpolants of interior pixels per (width, height, direction) of
  /// the oriented leaves and their neighbouring directions, built by
  /// PrepareElements before the passes that read them in parallel.
  std::map<std::tuple<int, int, int>, OrientedElements> elements_;
  void PrepareElements(const std::vector<Leaf>& leaves) {
    for (const Leaf& l : leaves)
      for (int step = -NeighbourSteps(); step <= NeighbourSteps(); ++step) {
        const int k = Turned(l.direction, step);
        const auto key = std::tuple(l.block.width(), l.block.height(), k);
        if (!elements_.contains(key))
          elements_.try_emplace(key, l.block.width(), l.block.height(), Direction::Of(k, directions_));
      }
  }
  /// The neighbouring directions tried each side: neighbourDirections, at
  /// most K/2 (every direction).
  int NeighbourSteps() const { return std::min(opt_.neighbourDirections, directions_ / 2); }
  /// Direction k turned by `step` directions (modulo the K directions).
  int Turned(int k, int step) const {
    const int K = directions_;
    return ((k + step) % K + K) % K;
  }
  /// The prepared oriented elements of b's shape along direction k, or null.
  const OrientedElements* ElementsOf(const Block& b, int k) const {
    const auto table = elements_.find(std::tuple(b.width(), b.height(), k));
    return table == elements_.end() ? nullptr : &table->second;
  }
  /// The interpolant of q in b along direction k: from `elements`
  /// (ElementsOf(b, k), looked up once per leaf) when prepared.
  bool InterpolantAlong(const OrientedElements* elements, const Block& b, Point2i q, int k, Interpolant* in) const {
    return elements ? elements->At(store_, b, q, in)
                    : OrientedInterpolant(store_, b, q, Direction::Of(k, directions_), in);
  }
};

Status Engine::LoadGuides() {
  GuideRequest want;
  want.objectId = caps_.objectId && opt_.objectTest != ObjectTest::kNone;
  want.shaderId = want.objectId && caps_.shaderId &&
                  (opt_.objectTest == ObjectTest::kObjectAndShader || opt_.objectTest == ObjectTest::kObjectOrShader);
  want.texture = split_;
  want.normal = caps_.normal && opt_.creaseAngle > 0.f;
  stats_.usedObjectId = want.objectId;
  stats_.usedShaderId = want.shaderId;
  stats_.usedSplit = split_;
  stats_.usedSupersampledRules = supersampledRules_;
  stats_.usedNormals = want.normal;
  if (!want.objectId && !want.texture && !want.normal) {
    store_.SetGuides({}, ObjectTest::kNone);
    return Status::Ok();
  }
  const Bounds2i all{{0, 0}, {caps_.width, caps_.height}};
  GuideImage g;
  const auto t0 = Clock::now();
  DCM_RETURN_IF_ERROR(provider_.Guides(all, want, &g));
  stats_.timeGuidesS += std::chrono::duration<double>(Clock::now() - t0).count();
  const size_t n = size_t(all.area());
  auto check = [&](bool wanted, size_t size, const char* name) {
    if (wanted && size != n)
      return Status::Error(std::string("provider '") + caps_.name + "' returned " + std::to_string(size) + " " +
                           name + " guide values for " + std::to_string(n) + " pixels");
    return Status::Ok();
  };
  DCM_RETURN_IF_ERROR(check(want.objectId, g.objectId.size(), "object ID"));
  DCM_RETURN_IF_ERROR(check(want.shaderId, g.shaderId.size(), "shader ID"));
  DCM_RETURN_IF_ERROR(check(want.texture, g.texture.size(), "texture"));
  DCM_RETURN_IF_ERROR(check(want.normal, g.normal.size(), "normal"));
  // A pixel whose tau is not finite cannot be reconstructed as L_i*tau + L_c:
  // it is evaluated exactly.
  if (want.texture)
    for (int64_t i = 0; i < int64_t(n); ++i)
      if (!IsFinite(g.texture[size_t(i)]))
        store_.Request(int(i % caps_.width), int(i / caps_.width), SampleReason::kFallback);
  store_.SetGuides(std::move(g), want.objectId ? opt_.objectTest : ObjectTest::kNone,
                   want.normal ? opt_.WorkCreaseAngle() : 0.f, block_);
  return Status::Ok();
}

bool Engine::HasSurfaceChange(const Block& b) const {
  const SurfaceTest& s = store_.surfaces();
  if (!s.enabled()) return false;
  for (int y = b.y0; y <= b.y1; ++y)
    for (int x = b.x0; x <= b.x1; ++x) {
      const int64_t i = store_.Index(x, y);
      if (x < b.x1 && !s.SameAdjacent(i, i + 1)) return true;
      if (y < b.y1 && !s.SameAdjacent(i, i + store_.width())) return true;
    }
  return false;
}

bool Engine::IsSmooth(const Block& b) const {
  const Point2i p[4] = {{b.x0, b.y0}, {b.x1, b.y0}, {b.x0, b.y1}, {b.x1, b.y1}};
  for (Point2i c : p)
    if (!store_.IsFinite(store_.Index(c.x, c.y))) return false;  // never interpolate from it
  const Value corners[4] = {At(p[0]), At(p[1]), At(p[2]), At(p[3])};
  return !contrast_.IsEdge(corners) && !HasSurfaceChange(b);
}

SampleReason Engine::Resolve(Point2i q, Interpolant* in) const {
  const int64_t iq = store_.Index(q.x, q.y);
  const SurfaceTest& s = store_.surfaces();
  // The common case: every interpolant is finite and on q's surface, so it is
  // used as it is (what the general case below would keep, in its order).
  bool allUsable = in->count > 0;
  for (int k = 0; k < in->count && allUsable; ++k) {
    const int64_t i = in->index[k];
    allUsable = store_.IsFinite(i) && store_.LiKnownFor(i, iq) && s.Same(iq, i);
  }
  if (allUsable) {
    double sum = 0;
    for (int k = 0; k < in->count; ++k) sum += in->weight[k];
    for (int k = 0; k < in->count; ++k) in->weight[k] /= sum;
    return SampleReason::kInterpolated;
  }
  // The finite weight per border point on q's surface and off it (weights
  // are > 0: an interpolant leaves zero weights out).
  double sameAt[2] = {0, 0}, otherAt[2] = {0, 0};
  Interpolant kept;
  Interpolant finite;
  for (int k = 0; k < in->count; ++k) {
    const int64_t i = in->index[k];
    const uint8_t end = in->end[k];
    if (!store_.IsFinite(i)) continue;  // non-finite samples never spread
    if (!store_.LiKnownFor(i, iq)) {  // tau = 0 there: its L_i is unknown here
      otherAt[end] += in->weight[k];   // (and it is another surface)
      continue;
    }
    finite.index[finite.count] = i, finite.end[finite.count] = end, finite.weight[finite.count++] = in->weight[k];
    if (s.Same(iq, i)) {
      sameAt[end] += in->weight[k];
      kept.index[kept.count] = i, kept.end[kept.count] = end, kept.weight[kept.count++] = in->weight[k];
    } else {
      otherAt[end] += in->weight[k];
    }
  }
  const bool anySame = sameAt[0] + sameAt[1] > 0, anyOther = otherAt[0] + otherAt[1] > 0;
  switch (thinTest_) {
    case ThinObjectTest::kOff: break;
    case ThinObjectTest::kNoneMatches:
      if (!anySame && s.enabled()) return SampleReason::kThinObject;
      break;
    case ThinObjectTest::kAnyDiffers:
      if (anyOther) return SampleReason::kThinObject;
      break;
    case ThinObjectTest::kEndDiffers:
      for (int end = 0; end < 2; ++end)
        if (otherAt[end] > 0 && sameAt[end] == 0) return SampleReason::kThinObject;
      // A border point between a pixel on q's surface and one on another
      // snaps to the one on q's: the edge passes between them.
      for (int k = 0; k < kept.count; ++k) {
        const int end = kept.end[k];
        kept.weight[k] *= (sameAt[end] + otherAt[end]) / sameAt[end];
      }
      break;
  }
  Interpolant& use = (opt_.surfaceAware && kept.count > 0) ? kept : finite;
  if (use.count == 0) return SampleReason::kFallback;
  double sum = 0;
  for (int k = 0; k < use.count; ++k) sum += use.weight[k];
  for (int k = 0; k < use.count; ++k) use.weight[k] /= sum;
  *in = use;
  return SampleReason::kInterpolated;
}

/// True when every pixel of the interpolant serves one border point: the
/// other border point lay on another surface and was left out.
bool OneEnded(const Interpolant& in) {
  for (int k = 1; k < in.count; ++k)
    if (in.end[k] != in.end[0]) return false;
  return in.count > 0;
}

/// The values of the interpolant's two border points, each from its own
/// pixels; false when one has none.
bool EndValues(const SampleStore& store, const Interpolant& in, std::array<Value, 2>* values) {
  Interpolant end[2];
  for (int k = 0; k < in.count; ++k) {
    Interpolant& e = end[in.end[k]];
    e.index[e.count] = in.index[k], e.weight[e.count++] = in.weight[k];
  }
  if (end[0].count == 0 || end[1].count == 0) return false;
  for (int i = 0; i < 2; ++i) {
    Interpolant& e = end[i];
    double sum = 0;
    for (int k = 0; k < e.count; ++k) sum += e.weight[k];
    for (int k = 0; k < e.count; ++k) e.weight[k] /= sum;
    (*values)[size_t(i)] = Evaluate(store, e);
  }
  return true;
}

bool Engine::EndsAgree(const Interpolant& in) const {
  std::array<Value, 2> ends;
  return EndValues(store_, in, &ends) && !contrast_.Differ(ends[0], ends[1]);
}

bool Engine::LeastDifferentTwoEnded(const Leaf& leaf, Point2i q, Interpolant* in) const {
  float least = std::numeric_limits<float>::infinity();
  for (int k = 0; k < directions_; ++k) {
    Interpolant alt;
    std::array<Value, 2> ends;
    if (!InterpolantAlong(ElementsOf(leaf.block, k), leaf.block, q, k, &alt) ||
        Resolve(q, &alt) != SampleReason::kInterpolated || !EndValues(store_, alt, &ends))
      continue;
    const float c = contrast_.Contrast(ends);
    if (c < least) least = c, *in = alt;
  }
  return least < std::numeric_limits<float>::infinity();
}

SampleReason Engine::ResolveAlongNeighbours(const Leaf& leaf, Point2i q, Interpolant* in) const {
  const Block& b = leaf.block;
  for (int step = 1; step <= NeighbourSteps(); ++step)
    for (int sign : {1, -1}) {
      if (sign < 0 && 2 * step == directions_) continue;  // the perpendicular, tried once
      const int k = Turned(leaf.direction, sign * step);
      Interpolant alt;
      if (InterpolantAlong(ElementsOf(b, k), b, q, k, &alt) && Resolve(q, &alt) == SampleReason::kInterpolated &&
          EndsAgree(alt)) {
        *in = alt;
        return SampleReason::kInterpolated;
      }
    }
  return SampleReason::kThinObject;
}

void Engine::WriteSmooth(const Leaf& leaf) {
  const Block& b = leaf.block;
  // A smooth leaf owns [x0, x1) x [y0, y1), and its last column and row at the
  // image border: leaves partition the image, so no pixel is written twice.
  const int xe = (b.x1 == store_.width() - 1 || b.x1 == b.x0) ? b.x1 : b.x1 - 1;
  const int ye = (b.y1 == store_.height() - 1 || b.y1 == b.y0) ? b.y1 : b.y1 - 1;
  // Bilinear as two linear steps in double (exact for linear ramps up to the
  // final rounding to float); the six channels are (a, b) of Value.
  double c[4][6];
  const Point2i corners[4] = {{b.x0, b.y0}, {b.x1, b.y0}, {b.x0, b.y1}, {b.x1, b.y1}};
  for (int k = 0; k < 4; ++k) {
    const Value v = At(corners[k]);
    for (int ch = 0; ch < 3; ++ch) c[k][ch] = v.a[ch], c[k][3 + ch] = v.b[ch];
  }
  const double sx = b.x1 > b.x0 ? 1.0 / (b.x1 - b.x0) : 0.0, sy = b.y1 > b.y0 ? 1.0 / (b.y1 - b.y0) : 0.0;
  const int channels = split_ ? 6 : 3;  // (L_i, L_c) or L
  for (int y = b.y0; y <= ye; ++y) {
    const double v = (y - b.y0) * sy;
    double left[6], right[6];
    for (int ch = 0; ch < channels; ++ch) {
      left[ch] = v == 0 ? c[0][ch] : (1 - v) * c[0][ch] + v * c[2][ch];
      right[ch] = v == 0 ? c[1][ch] : (1 - v) * c[1][ch] + v * c[3][ch];
    }
    for (int x = b.x0; x <= xe; ++x) {
      const int64_t i = store_.Index(x, y);
      if (store_.IsExact(i) || store_.IsFilled(i)) continue;
      const double u = (x - b.x0) * sx;
      Value out;
      for (int ch = 0; ch < channels; ++ch) {
        const float f = float(u == 0 ? left[ch] : (1 - u) * left[ch] + u * right[ch]);
        if (ch < 3) out.a[ch] = f;
        else out.b[ch - 3] = f;
      }
      store_.SetInterpolated(i, out);
    }
  }
}

void Engine::InterpolateOriented(const Leaf& leaf, OrientedPass pass) {
  const Block& b = leaf.block;
  const OrientedElements* elements = ElementsOf(b, leaf.direction);
  const bool lazy = leaf.type == BlockType::kLazy;
  const double hx = 0.5 * (b.x1 - b.x0), hy = 0.5 * (b.y1 - b.y0);
  for (int y = b.y0 + 1; y < b.y1; ++y)
    for (int x = b.x0 + 1; x < b.x1; ++x) {
      const int64_t i = store_.Index(x, y);
      if (store_.IsExact(i) || IsDeferred(i)) continue;
      Interpolant in;
      const bool found = InterpolantAlong(elements, b, {x, y}, leaf.direction, &in);
      SampleReason r = found ? Resolve({x, y}, &in) : SampleReason::kFallback;
      if (r == SampleReason::kThinObject) {
        r = ResolveAlongNeighbours(leaf, {x, y}, &in);
      } else if (r == SampleReason::kInterpolated && NeighbourSteps() > 0 && OneEnded(in)) {
        // One border point on q's surface (the thin-object test lets it
        // pass): its value would reach across the block unchanged. A
        // direction with two ends on q's surface interpolates instead,
        // where there is one (dcm's: the published methods try no other
        // direction, neighbourDirections 0).
        LeastDifferentTwoEnded(leaf, {x, y}, &in);
      }
      if (r != SampleReason::kInterpolated) {
        if (pass != OrientedPass::kPreview) RequestOrDefer(x, y, r);
        continue;
      }
      if (pass == OrientedPass::kThinObjects) continue;
      Value v = Evaluate(store_, in);
      if (lazy) {
        // The centre sample corrects the parent's interpolation with a tent
        // that is 1 at the centre and 0 on the border; the result stays in
        // the range of the samples used.
        const double w = std::max(0.0, 1 - std::fabs(x - leaf.centre.x) / hx) *
                         std::max(0.0, 1 - std::fabs(y - leaf.centre.y) / hy);
        for (int c = 0; c < 3; ++c) {
          v.a[c] = std::clamp(float(v.a[c] + w * leaf.delta.a[c]), leaf.lo.a[c], leaf.hi.a[c]);
          v.b[c] = std::clamp(float(v.b[c] + w * leaf.delta.b[c]), leaf.lo.b[c], leaf.hi.b[c]);
        }
      }
      store_.SetInterpolated(i, v);
    }
}

void Engine::WritePreview(int level, std::vector<Block>& splitSmooth, std::vector<EdgeBlock>& edges) {
  ForEach(smoothLeaves_, [&](Leaf& l, size_t) { WriteSmooth(l); });
  ForEach(splitSmooth, [&](Block& b, size_t) { WriteSmooth(MakeLeaf(b, BlockType::kSmooth)); });
  ForEach(edges, [&](EdgeBlock& e, size_t) {
    WriteSmooth(MakeLeaf(e.block, BlockType::kSmooth));  // where the oriented pass skips a pixel
    InterpolateOriented(MakeLeaf(e.block, BlockType::kComplexEdge, e.direction.index), OrientedPass::kPreview);
  });
  ForEach(orientedLeaves_, [&](Leaf& l, size_t) { InterpolateOriented(l, OrientedPass::kPreview); });
  opt_.onLevel(level, store_.width(), store_.height(), store_.radiance());
}

Status Engine::EvaluateBordersAdaptively(const std::vector<Block>& edges, bool belowElementary) {
  // The sides of all edge blocks of this level, each once: blocks of one level
  // sit on one lattice, so two sides are equal or share at most an end. A side
  // is a pure function of its own samples, whichever block it borders.
  struct Side {
    Point2i a, step;
    int length;  // pixels - 1
    uint64_t key;  ///< (start pixel, vertical, length) in one integer
  };
  // Images have at most 2^30 pixels, sides at most 256 steps (Validate()).
  auto side = [&](Point2i a, Point2i step, int length) {
    return Side{a, step, length, (uint64_t(store_.Index(a.x, a.y)) << 10) | (uint64_t(step.y) << 9) | uint64_t(length)};
  };
  std::vector<Side> sides;
  for (const Block& b : edges) {
    if (b.x1 == b.x0 || b.y1 == b.y0) {
      for (int y = b.y0; y <= b.y1; ++y)
        for (int x = b.x0; x <= b.x1; ++x) store_.Request(x, y, SampleReason::kBorder);
      continue;
    }
    sides.push_back(side({b.x0, b.y0}, {1, 0}, b.x1 - b.x0));
    sides.push_back(side({b.x0, b.y1}, {1, 0}, b.x1 - b.x0));
    sides.push_back(side({b.x0, b.y0}, {0, 1}, b.y1 - b.y0));
    sides.push_back(side({b.x1, b.y0}, {0, 1}, b.y1 - b.y0));
  }
  tbb::parallel_sort(sides.begin(), sides.end(), [](const Side& l, const Side& r) { return l.key < r.key; });
  sides.erase(std::unique(sides.begin(), sides.end(), [](const Side& l, const Side& r) { return l.key == r.key; }),
              sides.end());
  auto index = [&](const Side& s, int k) { return store_.Index(s.a.x + k * s.step.x, s.a.y + k * s.step.y); };
  const SurfaceTest& surf = store_.surfaces();

  // Interleaved crossings (ReconstructionOptions::crossingFillReach): the
  // sides on the lattice lines this level adds, between two lines of the
  // level above, defer the pixels at their surface changes.
  const bool interleave = belowElementary && crossingFillReach_ > 0;
  auto interleaved = [&](const Side& s) {
    const int across = s.step.y ? s.a.x : s.a.y;
    return interleave && across % (2 * s.length) == s.length;
  };
  std::vector<std::vector<int>> deferred(interleave ? sides.size() : 0);  // positions along the side

  // Round 0: the ends, and both pixels of every surface change.
  ForEach(sides, [&](Side& s, size_t si) {
    for (int k = 0; k <= s.length; k += s.length) store_.Request(s.a.x + k * s.step.x, s.a.y + k * s.step.y, SampleReason::kBorder);
    const bool defer = interleaved(s);
    for (int k = 0; k < s.length; ++k)
      if (!surf.SameAdjacent(index(s, k), index(s, k + 1)))
        for (int j : {k, k + 1}) {
          if (defer && j > 0 && j < s.length) deferred[si].push_back(j);
          else store_.Request(s.a.x + j * s.step.x, s.a.y + j * s.step.y, SampleReason::kBorder);
        }
  });
  DCM_RETURN_IF_ERROR(Flush());
  // A deferred pixel on surface S takes the mean of the nearest exact pixels
  // of S on the two neighbouring lines when both exist and agree, and is
  // evaluated otherwise. Those lines are sides of the level above (exact at
  // their surface changes), and the search stays inside the two blocks the
  // side borders: both children of one parent, so a window of the frame on
  // the lattice decides as the whole frame does.
  std::vector<uint8_t> crossingFilled(interleave ? size_t(store_.width()) * size_t(store_.height()) : 0);
  if (interleave) {
    std::atomic<int64_t> filled{0};
    ForEach(sides, [&](Side& s, size_t si) {
      const Point2i across{s.step.y, s.step.x};
      for (int j : deferred[si]) {
        const int64_t ij = index(s, j);
        if (store_.IsExact(ij)) continue;
        int64_t nearest[2] = {-1, -1};
        for (int n = 0; n < 2; ++n) {
          const int sign = n ? 1 : -1;
          const Point2i line{s.a.x + sign * s.length * across.x, s.a.y + sign * s.length * across.y};
          // Beside the last, narrower blocks of a row or column the line
          // lies outside the image.
          if (line.x < 0 || line.y < 0 || line.x >= store_.width() || line.y >= store_.height()) continue;
          for (int d = 0; d <= crossingFillReach_ && nearest[n] < 0; ++d)
            for (int k : {j - d, j + d}) {
              if (k < 0 || k > s.length) continue;
              const int64_t ik = store_.Index(line.x + k * s.step.x, line.y + k * s.step.y);
              if (store_.IsExact(ik) && store_.IsFinite(ik) && surf.Same(ik, ij)) {
                nearest[n] = ik;
                break;
              }
            }
        }
        if (nearest[0] >= 0 && nearest[1] >= 0 &&
            !contrast_.Differ(store_.ValueAt(nearest[0]), store_.ValueAt(nearest[1]))) {
          store_.SetFilled(ij, Lerp(store_.ValueAt(nearest[0]), store_.ValueAt(nearest[1]), 0.5f));
          crossingFilled[size_t(ij)] = 1;
          ++filled;
        } else {
          store_.Request(s.a.x + j * s.step.x, s.a.y + j * s.step.y, SampleReason::kBorder);
        }
      }
    });
    stats_.crossingsFilled += filled;
    DCM_RETURN_IF_ERROR(Flush());
  }
  // The pixels bisection and the fill start from: exact, or filled crossings.
  auto known = [&](int64_t i) { return store_.IsExact(i) || (interleave && crossingFilled[size_t(i)]); };
  // Bisect every gap whose known ends differ, until none is left. A side
  // that asked for nothing in a round has nothing new in the next (sides
  // share only their ends, exact since round 0): only the others are read.
  std::vector<uint8_t> active(sides.size(), 1);
  for (;;) {
    ForEach(sides, [&](Side& s, size_t i) {
      if (!active[i]) return;
      active[i] = 0;
      int last = 0;
      for (int k = 1; k <= s.length; ++k) {
        if (!known(index(s, k))) continue;
        const bool usable = store_.IsFinite(index(s, last)) && store_.IsFinite(index(s, k));
        if (k > last + 1 &&
            (!usable || contrast_.Differ(store_.ValueAt(index(s, last)), store_.ValueAt(index(s, k))))) {
          const int mid = (last + k) / 2;
          store_.Request(s.a.x + mid * s.step.x, s.a.y + mid * s.step.y, SampleReason::kBorder);
          active[i] = 1;
        }
        last = k;
      }
    });
    if (std::find(active.begin(), active.end(), uint8_t(1)) == active.end()) break;
    DCM_RETURN_IF_ERROR(Flush());
  }
  // Fill the gaps along the side from known pixels of the same surface.
  ForEach(sides, [&](Side& s, size_t) {
    int last = 0;
    for (int k = 1; k <= s.length; ++k) {
      if (!known(index(s, k))) continue;
      const int64_t i0 = index(s, last), i1 = index(s, k);
      const Value v0 = store_.ValueAt(i0), v1 = store_.ValueAt(i1);
      for (int j = last + 1; j < k; ++j) {
        const int64_t ij = index(s, j);
        const bool same0 = surf.Same(ij, i0), same1 = surf.Same(ij, i1);
        const float t = (same0 == same1) ? float(j - last) / float(k - last) : (same0 ? 0.f : 1.f);
        store_.SetFilled(ij, Lerp(v0, v1, t));
      }
      last = k;
    }
  });
  return Status::Ok();
}

Status Engine::Run(Reconstruction* out, std::vector<Point2i>* pending) {
  pending_ = pending;
  const auto tStart = Clock::now();
  const int W = caps_.width, H = caps_.height;
  // The baseline needs no guides: it evaluates every pixel.
  if (!opt_.fullEvaluation) DCM_RETURN_IF_ERROR(LoadGuides());
  if (opt_.checkerboard && !opt_.fullEvaluation) deferred_.assign(size_t(W) * size_t(H), SampleReason::kInterpolated);

  if (opt_.fullEvaluation) {
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) store_.Request(x, y, SampleReason::kFull);
    Progress(0.f, "full evaluation");
    DCM_RETURN_IF_ERROR(Flush());
  } else {
    std::vector<Block> classify = LatticeBlocks(W, H, block_);
    std::vector<Block> edges;
    int levels = 1;
    while ((block_ >> (levels - 1)) > opt_.minBlock) ++levels;
    std::vector<Point2i> loopScratch;

    for (int level = 0; level < levels && !(classify.empty() && edges.empty()); ++level) {
      const int size = block_ >> level;
      const bool finest = level == levels - 1;
      const float f0 = float(level) / float(levels), df = 1.f / float(levels);
      std::vector<Block> nextClassify, nextEdges;

      // Corners, then smooth/edge classification (2.2).
      Progress(f0, "corners");
      ForEach(classify, [&](Block& b, size_t) { RequestCorners(b); });
      DCM_RETURN_IF_ERROR(Flush());
      std::vector<uint8_t> smooth(classify.size());
      ForEach(classify, [&](Block& b, size_t i) { smooth[i] = IsSmooth(b); });
      std::vector<Block> probe, splitSmooth;  // splitSmooth: for progressive previews
      for (size_t i = 0; i < classify.size(); ++i) {
        const Block& b = classify[i];
        if (!smooth[i]) {
          edges.push_back(b);
        } else if (finest || (b.width() <= 1 && b.height() <= 1) || smoothRefinement_ == SmoothRefinement::kNever) {
          smoothLeaves_.push_back(MakeLeaf(b, BlockType::kSmooth));
        } else if (smoothRefinement_ == SmoothRefinement::kAlways) {
          ChildBlocks(b, size / 2, W, H, &nextClassify);
          splitSmooth.push_back(b);
        } else {
          probe.push_back(b);
        }
      }
      // Smoothness by prediction: the centre (a corner of the children) must
      // match the bilinear interpolation of the corners.
      if (!probe.empty()) {
        ForEach(probe, [&](Block& b, size_t) { store_.Request(b.Centre().x, b.Centre().y, SampleReason::kCorner); });
        DCM_RETURN_IF_ERROR(Flush());
        std::vector<uint8_t> split(probe.size());
        ForEach(probe, [&](Block& b, size_t i) {
          split[i] = !store_.IsFinite(store_.Index(b.Centre().x, b.Centre().y)) ||
                     contrast_.Misses(At(b.Centre()), Bilinear(store_, b, b.Centre()));
        });
        for (size_t i = 0; i < probe.size(); ++i) {
          if (split[i]) {
            ChildBlocks(probe[i], size / 2, W, H, &nextClassify);
            splitSmooth.push_back(probe[i]);
          } else {
            smoothLeaves_.push_back(MakeLeaf(probe[i], BlockType::kSmooth));
          }
        }
      }

      // Edge blocks: full border and least-discrepancy direction (2.1).
      Progress(f0 + 0.4f * df, "edge borders");
      std::vector<EdgeBlock> eb(edges.size());
      ForEach(edges, [&](Block& b, size_t i) {
        eb[i].block = b;
        BorderLoop(b, &eb[i].border);
        if (!opt_.adaptiveBorders)
          for (Point2i p : eb[i].border) store_.Request(p.x, p.y, SampleReason::kBorder);
      });
      if (opt_.adaptiveBorders) DCM_RETURN_IF_ERROR(EvaluateBordersAdaptively(edges, size < block_));
      DCM_RETURN_IF_ERROR(Flush());
      PrepareBorderPairs(eb);
      ForEach(eb, [&](EdgeBlock& e, size_t) {
        e.direction = LeastDiscrepancyDirection(store_, e.border,
                                                borderPairs_.at(std::pair(e.block.width(), e.block.height())));
        e.crossings = SignificantChanges(store_, contrast_, e.border);
      });

      if (!finest) {
        // Simple vs complex (2.3).
        ForEach(eb, [&](EdgeBlock& e, size_t) {
          const size_t n = e.crossings.size();
          const bool zeroOrder = !opt_.zeroOrderTest || n == 2 || (n == 0 && opt_.gradientBlocksSimple);
          const int surfaceChanges = SurfaceChanges(store_, e.border);
          // Every significant change a surface change (crossings include them all).
          const bool onlySurfaces = int(n) == surfaceChanges;
          const bool small = std::max(e.block.width(), e.block.height()) <= 2 * opt_.minBlock;
          e.simple = e.block.HasInterior() &&
                     ((zeroOrder && surfaceChanges <= 2) ||
                      (small && onlySurfaces && n > 2 && int(n) <= opt_.simpleSurfaceChanges));
          if (e.simple && opt_.firstOrderTest && n == 2)
            for (Point2i p : FirstOrderProbes(store_, e.block, e.border, e.crossings, opt_.firstOrderFromGuides))
              store_.Request(p.x, p.y, SampleReason::kFirstOrderProbe);
        });
        if (opt_.firstOrderTest) {
          DCM_RETURN_IF_ERROR(Flush());
          ForEach(eb, [&](EdgeBlock& e, size_t) {
            if (e.simple && e.crossings.size() == 2)
              e.simple = FirstOrderConsistent(store_, contrast_, e.block, e.border, e.crossings, opt_.firstOrderFromGuides);
          });
        }
        // Lazy evaluation of simple blocks: the parent's centre only.
        if (opt_.lazyEvaluation) {
          ForEach(eb, [&](EdgeBlock& e, size_t) {
            if (e.simple) store_.Request(e.block.Centre().x, e.block.Centre().y, SampleReason::kLazyCentre);
          });
          DCM_RETURN_IF_ERROR(Flush());
        }
        std::vector<Leaf> lazy(eb.size());
        std::vector<uint8_t> accepted(eb.size(), 0);
        ForEach(eb, [&](EdgeBlock& e, size_t i) {
          if (!e.simple || !opt_.lazyEvaluation) return;
          const Block& b = e.block;
          const Point2i c = b.Centre();
          Interpolant in;
          if (!OrientedInterpolant(store_, b, c, Direction::Of(e.direction.index, directions_), &in) ||
              Resolve(c, &in) != SampleReason::kInterpolated)
            return;
          const Value predicted = Evaluate(store_, in), exact = At(c);
          if (!store_.IsFinite(store_.Index(c.x, c.y)) || contrast_.Misses(exact, predicted)) return;
          Leaf& leaf = lazy[i];
          leaf = MakeLeaf(b, BlockType::kLazy, e.direction.index);
          leaf.centre = c;
          // A correction the noise may explain is noise: spread over the
          // block by the tent, it would move both sides of the edge. One
          // sample moving a whole block needs stronger evidence than a
          // refinement (which costs samples, not error): 3 sd at least.
          if (!contrast_.WithinNoise(exact, predicted, std::max(opt_.noiseSignificance, 3.f)))
            leaf.delta = {exact.a - predicted.a, exact.b - predicted.b};
          leaf.lo = leaf.hi = exact;
          for (Point2i p : e.border) {
            const int64_t ip = store_.Index(p.x, p.y);
            if (!store_.IsFinite(ip)) continue;
            const Value v = store_.ValueAt(ip);
            for (int ch = 0; ch < 3; ++ch) {
              leaf.lo.a[ch] = std::min(leaf.lo.a[ch], v.a[ch]), leaf.hi.a[ch] = std::max(leaf.hi.a[ch], v.a[ch]);
              leaf.lo.b[ch] = std::min(leaf.lo.b[ch], v.b[ch]), leaf.hi.b[ch] = std::max(leaf.hi.b[ch], v.b[ch]);
            }
          }
          accepted[i] = 1;
        });
        for (size_t i = 0; i < eb.size(); ++i) {
          const EdgeBlock& e = eb[i];
          if (accepted[i]) {
            orientedLeaves_.push_back(lazy[i]);
            ++stats_.lazyAccepted;
          } else if (!e.block.HasInterior()) {
            orientedLeaves_.push_back(MakeLeaf(e.block, BlockType::kComplexEdge, e.direction.index));
          } else {
            if (e.simple && opt_.lazyEvaluation) ++stats_.lazyRejected;
            e.simple ? ++stats_.simpleEdgeBlocks : ++stats_.complexEdgeBlocks;
            ChildBlocks(e.block, size / 2, W, H, &nextEdges);
          }
        }
      } else {
        // More discontinuities than one direction can serve, or an
        // interpolation that misses the block's centre: evaluate it all.
        std::vector<uint8_t> fallback(eb.size(), 0);
        ForEach(eb, [&](EdgeBlock& e, size_t i) {
          // The changes no surface change explains: shading edges.
          const int shading = int(e.crossings.size()) - SurfaceChanges(store_, e.border);
          fallback[i] = opt_.fallback && int(e.crossings.size()) > opt_.fallbackMaxChanges &&
                        (opt_.fallbackShadingChanges < 0 || shading > opt_.fallbackShadingChanges);
          e.probe = !fallback[i] && opt_.fallback && opt_.finestCentreProbe && e.block.HasInterior() &&
                    ProbeWanted(e, shading);
          if (e.probe) store_.Request(e.block.Centre().x, e.block.Centre().y, SampleReason::kCentreProbe);
        });
        if (opt_.fallback && opt_.finestCentreProbe) {
          DCM_RETURN_IF_ERROR(Flush());
          ForEach(eb, [&](EdgeBlock& e, size_t i) {
            if (!e.probe) return;
            const Point2i c = e.block.Centre();
            Interpolant in;
            if (!OrientedInterpolant(store_, e.block, c, Direction::Of(e.direction.index, directions_), &in))
              return;
            // A centre on another surface than its interpolants is the thin
            // object test's business, not a miss.
            if (Resolve(c, &in) != SampleReason::kInterpolated) return;
            fallback[i] = !store_.IsFinite(store_.Index(c.x, c.y)) || contrast_.Misses(At(c), Evaluate(store_, in));
          });
        }
        for (size_t i = 0; i < eb.size(); ++i) {
          const EdgeBlock& e = eb[i];
          const BlockType type = fallback[i] ? BlockType::kFallback
                                 : e.crossings.size() <= 2 ? BlockType::kSimpleEdge : BlockType::kComplexEdge;
          (fallback[i] ? fallbackLeaves_ : orientedLeaves_).push_back(MakeLeaf(e.block, type, e.direction.index));
        }
      }
      if (opt_.onLevel && !finest) WritePreview(level, splitSmooth, eb);
      classify = std::move(nextClassify);
      edges = std::move(nextEdges);
    }

    // Fallback blocks: every interior pixel exactly, and the border pixels
    // not evaluated yet unless adaptive borders filled them (or the options
    // ask for those too).
    ForEach(fallbackLeaves_, [&](Leaf& l, size_t) {
      const Block& b = l.block;
      for (int y = b.y0; y <= b.y1; ++y)
        for (int x = b.x0; x <= b.x1; ++x) {
          const bool border = x == b.x0 || x == b.x1 || y == b.y0 || y == b.y1;
          if (border && !opt_.fallbackFilledBorders && store_.IsFilled(store_.Index(x, y))) continue;
          if (border) store_.Request(x, y, SampleReason::kFallback);
          else RequestOrDefer(x, y, SampleReason::kFallback);
        }
    });
    // Flushed before the thin-object pass: a fallback block's border is also
    // its neighbours' border, and what the pass decides depends on it.
    DCM_RETURN_IF_ERROR(Flush());
    // Thin objects (3.1): interior pixels whose interpolants lie on another
    // surface are evaluated exactly. The interpolation reads block borders
    // only, which are final now, unless the samples are to be denoised first:
    // then the pass only requests, and the interpolation follows denoising.
    const bool denoise = DenoisesSamples(opt_, caps_);
    Progress(0.9f, "thin objects and interpolation");
    PrepareElements(orientedLeaves_);
    if (!denoise) ForEach(smoothLeaves_, [&](Leaf& l, size_t) { WriteSmooth(l); });
    ForEach(orientedLeaves_, [&](Leaf& l, size_t) {
      InterpolateOriented(l, denoise ? OrientedPass::kThinObjects : OrientedPass::kFinal);
    });
    DCM_RETURN_IF_ERROR(Flush());
    if (opt_.checkerboard) DCM_RETURN_IF_ERROR(ResolveDeferred(!denoise));
    if (denoise) {
      Progress(0.93f, "denoising samples");
      // Averaging what the noise explains: the gate is wider than the
      // detection's significance (which errs towards refining), 2 sd at least.
      stats_.denoisedSamples =
          DenoiseExactSamples(store_, DenoiseRadius(opt_, caps_), contrast_, std::max(opt_.noiseSignificance, 2.f));
      Progress(0.95f, "interpolation");
      ForEach(smoothLeaves_, [&](Leaf& l, size_t) { WriteSmooth(l); });
      ForEach(orientedLeaves_, [&](Leaf& l, size_t) { InterpolateOriented(l, OrientedPass::kFinal); });
      // Nothing to evaluate unless the thin-object pass missed a pixel.
      DCM_RETURN_IF_ERROR(Flush());
      WriteFilledDeferred();
    }
    if (opt_.onLevel) opt_.onLevel(levels - 1, W, H, store_.radiance());
    stats_.smoothBlocks = int64_t(smoothLeaves_.size());
    stats_.fallbackBlocks = int64_t(fallbackLeaves_.size());
  }

  // Outputs.
  out->workWidth = W;
  out->workHeight = H;
  out->workImage = store_.TakeRadiance();
  out->sampleMap = store_.TakeReasons();
  out->image = BoxDownsample(out->workImage, W, H, opt_.downsample, &out->width, &out->height);
  RecordLeaves(out);
  stats_.totalPixels = int64_t(W) * H;
  // Flush() counted the exact pixels by reason as it made them exact.
  stats_.exactPixels = 0;
  for (size_t r = 0; r < stats_.byReason.size(); ++r)
    if (r != size_t(SampleReason::kInterpolated)) stats_.exactPixels += stats_.byReason[r];
  stats_.byReason[size_t(SampleReason::kInterpolated)] = stats_.totalPixels - stats_.exactPixels;
  const double total = std::chrono::duration<double>(Clock::now() - tStart).count();
  stats_.timeEngineS = std::max(0.0, total - stats_.timeProviderS - stats_.timeGuidesS);
  out->stats = stats_;
  Progress(1.f, "done");
  return Status::Ok();
}

Status Engine::ResolveDeferred(bool write) {
  std::vector<int64_t> deferred;
  for (size_t i = 0; i < deferred_.size(); ++i)
    if (deferred_[i] != SampleReason::kInterpolated) deferred.push_back(int64_t(i));
  std::vector<uint8_t> filled(deferred.size(), 0);
  // The decisions read the exact samples of the first colour only (requests
  // take effect at the flush), so they do not depend on the order.
  ForEach(deferred, [&](int64_t& i, size_t k) {
    const int x = int(i % store_.width()), y = int(i / store_.width());
    Value v;
    if (NeighbourEstimate(store_, contrast_, {x, y}, true, &v)) {
      filled[k] = 1;
      if (write) store_.SetInterpolated(i, v);
    } else {
      store_.Request(x, y, deferred_[size_t(i)]);
    }
  });
  filledDeferred_.clear();
  for (size_t k = 0; k < deferred.size(); ++k)
    if (filled[k]) filledDeferred_.push_back(deferred[k]);
  stats_.checkerboardFilled = int64_t(filledDeferred_.size());
  return Flush();
}

void Engine::WriteFilledDeferred() {
  ForEach(filledDeferred_, [&](int64_t& i, size_t) {
    Value v;
    if (NeighbourEstimate(store_, contrast_, {int(i % store_.width()), int(i / store_.width())}, false, &v))
      store_.SetInterpolated(i, v);
  });
}

void Engine::RecordLeaves(Reconstruction* out) {
  out->blocks.clear();
  auto record = [&](const Leaf& l) {
    const Block& b = l.block;
    out->blocks.push_back({b.x0, b.y0, b.x1, b.y1, b.level, l.type, l.direction});
  };
  for (const Leaf& l : smoothLeaves_) record(l);
  for (const Leaf& l : orientedLeaves_) record(l);
  for (const Leaf& l : fallbackLeaves_) record(l);
}

}  // namespace
}  // namespace detail

bool UsesSupersampledRules(const ReconstructionOptions& options, const ProviderCapabilities& caps) {
  return options.SupersampledRules(detail::NoisySamples(options, caps));
}

SmoothRefinement UsedSmoothRefinement(const ReconstructionOptions& options, const ProviderCapabilities& caps) {
  const SmoothRefinement r = options.smoothRefinement;
  return r == SmoothRefinement::kCentreProbe && caps.hardShadowsGuided && !detail::NoisySamples(options, caps)
             ? SmoothRefinement::kNever
             : r;
}

Status Reconstruct(SampleProvider& provider, const ReconstructionOptions& options, Reconstruction* out,
                   std::vector<Point2i>* pending) {
  DCM_RETURN_IF_ERROR(options.Validate());
  const ProviderCapabilities caps = provider.Capabilities();
  constexpr int64_t kMaxPixels = int64_t(1) << 30;
  if (caps.width <= 0 || caps.height <= 0 || int64_t(caps.width) * caps.height > kMaxPixels)
    return Status::Error("provider '" + caps.name + "' reports an unusable size " + std::to_string(caps.width) +
                         "x" + std::to_string(caps.height));
  const bool split = options.textureSplit && caps.texture && caps.splitRadiance && !options.fullEvaluation;
  Status status;
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  arena.execute([&] {
    detail::Engine engine(provider, options, caps, split);
    status = engine.Run(out, pending);
  });
  return status;
}

}  // namespace dcm
