// Recording the beauty's interpolation steps (InterpolationRecorder) and
// replaying them on another channel (InterpolationRecord::Apply). The replay
// repeats each stage's own arithmetic (float or double, in its order), so
// that a channel equal to an interpolated component of the beauty gives the
// beauty's bits.
#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>

#include "interpolation_recorder.h"

namespace dcm {

namespace {
/// Marks a term read while its pixel was exact: the channel's exact value,
/// not what an earlier step wrote there (a pixel filled, then evaluated).
/// Pixel indices fit the other 31 bits: images hold at most 2^30 pixels.
constexpr uint32_t kExactBit = 0x80000000u;
constexpr uint32_t kPixelMask = 0x7fffffffu;
}  // namespace

InterpolationRecord::InterpolationRecord() = default;
InterpolationRecord::~InterpolationRecord() = default;

size_t InterpolationRecord::MemoryBytes() const {
  return exact_.capacity() + ops_.capacity() * sizeof(Op) + index_.capacity() * sizeof(uint32_t) +
         weight_.capacity() * sizeof(double);
}

Status InterpolationRecord::Apply(std::span<const float> exact, ChannelKind kind, std::vector<float>* out) const {
  const int W = window_.width(), H = window_.height();
  const size_t n = size_t(W) * size_t(H);
  if (exact.size() != n)
    return Status::Error("interpolation record: a channel of " + std::to_string(exact.size()) +
                         " values for a window of " + std::to_string(W) + "x" + std::to_string(H) + " pixels");
  const bool id = kind == ChannelKind::kId;
  std::vector<float> value(n, 0.f);
  std::vector<uint8_t> filled(n, 0);
  struct Range {
    float delta = 0, lo = 0, hi = 0;
  };
  std::vector<Range> lazy(lazyLeaves_);
  auto at = [&](uint32_t t) { return (t & kExactBit) ? exact[t & kPixelMask] : value[t & kPixelMask]; };
  // The ID rule: the term of the largest weight, the first of equal ones.
  auto most = [&](const Op& op) {
    uint32_t best = op.first;
    for (uint32_t k = op.first + 1; k < op.first + op.count; ++k)
      if (weight_[k] > weight_[best]) best = k;
    return at(index_[best]);
  };
  // WeightedSum's arithmetic (lib/src/oriented_interpolation.h).
  auto sum = [&](const Op& op) {
    double a = 0;
    for (uint32_t k = op.first; k < op.first + op.count; ++k) a += weight_[k] * at(index_[k]);
    return float(a);
  };
  for (const Op& op : ops_) {
    switch (op.kind) {
      case Op::kFill: {
        const float t = float(weight_[op.first]);
        const float p = at(index_[op.first]), q = at(index_[op.first + 1]);
        // Lerp (sample_store.h) in float.
        value[op.target] = id ? (1 - t >= t ? p : q) : p * (1 - t) + q * t;
        filled[op.target] = 1;
        break;
      }
      case Op::kSmooth: {
        // Engine::WriteSmooth (hierarchical_refinement.cpp), step for step.
        const uint32_t c0 = index_[op.first] & kPixelMask, c3 = index_[op.first + 3] & kPixelMask;
        const int x0 = int(c0 % uint32_t(W)), y0 = int(c0 / uint32_t(W));
        const int x1 = int(c3 % uint32_t(W)), y1 = int(c3 / uint32_t(W));
        const int xe = (x1 == W - 1 || x1 == x0) ? x1 : x1 - 1;
        const int ye = (y1 == H - 1 || y1 == y0) ? y1 : y1 - 1;
        // IDs are copied as they are (a uint ID's bits travel in a float).
        float corner[4];
        double c[4];
        for (int k = 0; k < 4; ++k) corner[k] = at(index_[op.first + uint32_t(k)]), c[k] = corner[k];
        const double sx = x1 > x0 ? 1.0 / (x1 - x0) : 0.0, sy = y1 > y0 ? 1.0 / (y1 - y0) : 0.0;
        for (int y = y0; y <= ye; ++y) {
          const double v = (y - y0) * sy;
          const double left = v == 0 ? c[0] : (1 - v) * c[0] + v * c[2];
          const double right = v == 0 ? c[1] : (1 - v) * c[1] + v * c[3];
          for (int x = x0; x <= xe; ++x) {
            const size_t i = size_t(y) * size_t(W) + size_t(x);
            if (exact_[i] || filled[i]) continue;
            const double u = (x - x0) * sx;
            if (id) {
              const double w[4] = {(1 - u) * (1 - v), u * (1 - v), (1 - u) * v, u * v};
              int best = 0;
              for (int k = 1; k < 4; ++k)
                if (w[k] > w[best]) best = k;
              value[i] = corner[best];
            } else {
              value[i] = float(u == 0 ? left : (1 - u) * left + u * right);
            }
          }
        }
        break;
      }
      case Op::kWeighted:
        value[op.target] = id ? most(op) : sum(op);
        break;
      case Op::kLazyLeaf: {
        if (id) break;
        // Engine::EvaluateLazily (lazy_boundary_evaluation.cpp): the exact
        // centre minus its prediction, and the range of the centre and the
        // finite border pixels.
        Range& r = lazy[op.leaf];
        const float centre = exact[op.target];
        if (!op.zeroDelta) r.delta = centre - sum(op);
        r.lo = r.hi = centre;
        for (uint32_t k = op.first + op.count; k < op.first + op.count + op.extra; ++k) {
          const float v = at(index_[k]);
          r.lo = std::min(r.lo, v), r.hi = std::max(r.hi, v);
        }
        break;
      }
      case Op::kLazy: {
        if (id) {
          value[op.target] = most(op);
          break;
        }
        // Engine::InterpolateOriented's correction of a lazy leaf.
        const Range& r = lazy[op.leaf];
        const double tent = weight_[op.first + op.count];
        value[op.target] = std::clamp(float(sum(op) + tent * r.delta), r.lo, r.hi);
        break;
      }
    }
  }
  out->resize(n);
  for (size_t i = 0; i < n; ++i) (*out)[i] = exact_[i] ? exact[i] : value[i];
  return Status::Ok();
}

namespace detail {

void InterpolationRecorder::Term(Local& l, int64_t i, double w) const {
  l.index.push_back(uint32_t(i) | (store_.IsExact(i) ? kExactBit : 0u));
  l.weight.push_back(w);
}

InterpolationRecord::Op& InterpolationRecorder::Begin(Local& l, InterpolationRecord::Op::Kind kind,
                                                      int64_t target) const {
  InterpolationRecord::Op& op = l.ops.emplace_back();
  op.phase = phase_;
  op.kind = kind;
  op.target = uint32_t(target);
  op.first = uint32_t(l.index.size());
  return op;
}

void InterpolationRecorder::Fill(int64_t i, int64_t p, int64_t q, float t) {
  if (store_.IsExact(i)) return;  // SetFilled leaves it
  Local& l = local_.local();
  Begin(l, InterpolationRecord::Op::kFill, i).count = 2;
  Term(l, p, double(t));
  Term(l, q, 0.0);
}

void InterpolationRecorder::Smooth(const Block& b) {
  Local& l = local_.local();
  Begin(l, InterpolationRecord::Op::kSmooth, store_.Index(b.x0, b.y0)).count = 4;
  for (Point2i c : {Point2i{b.x0, b.y0}, Point2i{b.x1, b.y0}, Point2i{b.x0, b.y1}, Point2i{b.x1, b.y1}})
    Term(l, store_.Index(c.x, c.y), 0.0);
}

void InterpolationRecorder::Weighted(int64_t i, const Interpolant& in) {
  Local& l = local_.local();
  Begin(l, InterpolationRecord::Op::kWeighted, i).count = uint16_t(in.count);
  for (int k = 0; k < in.count; ++k) Term(l, in.index[size_t(k)], in.weight[size_t(k)]);
}

void InterpolationRecorder::Weighted(int64_t i, const NeighbourTerms& t) {
  Local& l = local_.local();
  Begin(l, InterpolationRecord::Op::kWeighted, i).count = uint16_t(t.count);
  for (int k = 0; k < t.count; ++k) Term(l, t.index[k], t.weight[k]);
}

void InterpolationRecorder::LazyLeaf(Point2i centre, const Interpolant& predicted, std::span<const Point2i> border,
                                     bool zeroDelta) {
  Local& l = local_.local();
  const size_t op = l.ops.size();
  Begin(l, InterpolationRecord::Op::kLazyLeaf, store_.Index(centre.x, centre.y)).count = uint16_t(predicted.count);
  for (int k = 0; k < predicted.count; ++k) Term(l, predicted.index[size_t(k)], predicted.weight[size_t(k)]);
  uint32_t finite = 0;
  for (Point2i p : border) {
    const int64_t i = store_.Index(p.x, p.y);
    if (!store_.IsFinite(i)) continue;  // as EvaluateLazily bounds the range
    Term(l, i, 0.0);
    ++finite;
  }
  l.ops[op].extra = finite;
  l.ops[op].zeroDelta = zeroDelta ? 1 : 0;
}

void InterpolationRecorder::Lazy(int64_t i, const Interpolant& in, Point2i centre, double tent) {
  Local& l = local_.local();
  InterpolationRecord::Op& op = Begin(l, InterpolationRecord::Op::kLazy, i);
  op.count = uint16_t(in.count);
  op.extra = uint32_t(store_.Index(centre.x, centre.y));
  for (int k = 0; k < in.count; ++k) Term(l, in.index[size_t(k)], in.weight[size_t(k)]);
  l.index.push_back(0);
  l.weight.push_back(tent);
}

std::shared_ptr<InterpolationRecord> InterpolationRecorder::Finish(int width, int height,
                                                                   const std::vector<SampleReason>& reasons) {
  auto record = std::make_shared<InterpolationRecord>();
  record->window_ = {{0, 0}, {width, height}};
  record->exact_.resize(reasons.size());
  for (size_t i = 0; i < reasons.size(); ++i) record->exact_[i] = reasons[i] != SampleReason::kInterpolated;
  size_t ops = 0, terms = 0;
  for (const Local& l : local_) ops += l.ops.size(), terms += l.index.size();
  record->ops_.reserve(ops);
  record->index_.reserve(terms);
  record->weight_.reserve(terms);
  for (Local& l : local_) {
    const uint32_t base = uint32_t(record->index_.size());
    for (InterpolationRecord::Op op : l.ops) {
      op.first += base;
      record->ops_.push_back(op);
    }
    record->index_.insert(record->index_.end(), l.index.begin(), l.index.end());
    record->weight_.insert(record->weight_.end(), l.weight.begin(), l.weight.end());
    l = Local{};
  }
  // Phase by phase; within a phase no step reads another's pixel.
  std::stable_sort(record->ops_.begin(), record->ops_.end(),
                   [](const auto& a, const auto& b) { return a.phase < b.phase; });
  // Lazy leaves by number: their pixels find the correction by it.
  std::unordered_map<uint32_t, uint32_t> leaves;
  for (auto& op : record->ops_)
    if (op.kind == InterpolationRecord::Op::kLazyLeaf) op.leaf = leaves.try_emplace(op.target, uint32_t(leaves.size())).first->second;
  for (auto& op : record->ops_)
    if (op.kind == InterpolationRecord::Op::kLazy) op.leaf = leaves.at(op.extra);
  record->lazyLeaves_ = uint32_t(leaves.size());
  return record;
}

}  // namespace detail
}  // namespace dcm
