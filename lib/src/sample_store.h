// Per-pixel state of a reconstruction: guides, exact samples, interpolated
// values and why each pixel is exact. Exact samples are requested once each:
// requests are collected per phase, deduplicated and evaluated in batches.
#pragma once

#include <tbb/enumerable_thread_specific.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "dcm/options.h"
#include "dcm/reconstructor.h"
#include "dcm/sample_provider.h"
#include "surface_test.h"

namespace dcm::detail {

/// A value in the interpolation domain: (L_i, L_c) with the texture split, or
/// (L, 0) without. The displayed radiance is a*tau + b. With noisy samples,
/// `varA` and `varB` are the variances of the luminance of a and b (0 for
/// noiseless samples); an interpolated value carries sum(w^2 var) of its
/// interpolants.
struct Value {
  RGB a;
  RGB b;
  float varA = 0.f;
  float varB = 0.f;
  /// With the split, the luminance of tau at the pixel the value belongs
  /// to: the contrast test weighs a change of L_c against L = L_i tau + L_c.
  float tau = 1.f;
};

/// (1-t) p + t q, with the variance of independent p and q.
inline Value Lerp(const Value& p, const Value& q, float t) {
  return {p.a * (1 - t) + q.a * t, p.b * (1 - t) + q.b * t,
          (1 - t) * (1 - t) * p.varA + t * t * q.varA, (1 - t) * (1 - t) * p.varB + t * t * q.varB};
}

/// Allocates without initialising the elements (default construction does
/// nothing): SampleStore fills its own per-pixel arrays in parallel, so that
/// their pages are first touched, and zeroed, by every worker instead of one.
template <typename T>
struct UninitialisedAllocator : std::allocator<T> {
  template <typename U>
  struct rebind {
    using other = UninitialisedAllocator<U>;
  };
  UninitialisedAllocator() = default;
  template <typename U>
  UninitialisedAllocator(const UninitialisedAllocator<U>&) noexcept {}
  template <typename U>
  void construct(U*) noexcept {}
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
template <typename T>
using PixelArray = std::vector<T, UninitialisedAllocator<T>>;

class SampleStore {
 public:
  /// `variance`: exact samples carry the variance of their estimate.
  SampleStore(int width, int height, bool split, bool variance = false);

  int width() const { return width_; }
  int height() const { return height_; }
  bool split() const { return split_; }
  int64_t Index(int x, int y) const { return int64_t(y) * width_ + x; }

  bool IsExact(int64_t i) const { return reason_[i] != SampleReason::kInterpolated; }
  /// The exact sample at i may serve to interpolate others: its values are
  /// finite and, with the split, its tau is neither zero, denormal nor
  /// non-finite (L_i = L_t / tau is meaningless there).
  bool IsFinite(int64_t i) const { return finite_[i] != 0; }
  /// Exact sample i can give L_i to pixel q: not when i has tau = 0 (its L_i
  /// is unknown) and q has not. Holds whatever the surface-aware switch.
  bool LiKnownFor(int64_t i, int64_t q) const { return tauZero_.empty() || !tauZero_[i] || tauZero_[q]; }
  /// Clamps the finite values of L, L_i and L_c beyond kMaxSampleMagnitude to
  /// it (NaN and infinity stay); true when one was.
  static bool ClampSample(ExactSample* s);
  /// (varA, varB) of a sample whose L has per-channel variance `varL`.
  static std::array<float, 2> LuminanceVariances(RGB varL, RGB tau);
  /// Without the split the interpolated quantity is L itself, stored once.
  Value ValueAt(int64_t i) const {
    Value v = split_ ? Value{a_[i], b_[i]} : Value{out_[i], RGB{}};
    if (split_) v.tau = Luminance(tau_[size_t(i)]);
    if (!var_.empty()) v.varA = var_[i][0], v.varB = var_[i][1];
    return v;
  }
  bool hasVariance() const { return !var_.empty(); }
  RGB Tau(int64_t i) const { return tau_.empty() ? RGB::Gray(1.f) : tau_[i]; }

  /// Writes an interpolated pixel's radiance (never over an exact pixel).
  /// Its (L_i, L_c) and variance are not kept: only exact and filled pixels
  /// serve as interpolants, and the outputs read the radiance alone.
  void SetInterpolated(int64_t i, const Value& v) {
    if (!IsExact(i)) out_[i] = split_ ? v.a * tau_[size_t(i)] + v.b : v.a;
  }
  /// Writes a value filled along an edge-block border; block interiors then
  /// interpolate it, and smooth blocks leave it in place.
  void SetFilled(int64_t i, const Value& v) {
    if (IsExact(i)) return;
    Write(i, v);
    filled_[i] = 1;
  }
  bool IsFilled(int64_t i) const { return filled_[i] != 0; }
  /// Replaces the value of exact pixel i (a denoised estimate); it stays exact.
  void ReplaceExact(int64_t i, const Value& v);

  /// Asks for pixel (x, y) to be evaluated exactly in the next Flush(). Safe
  /// to call concurrently. When several reasons ask for one pixel, the one
  /// listed first in SampleReason is recorded, so the record is independent of
  /// the order of requests.
  void Request(int x, int y, SampleReason reason) {
    requests_.local().push_back((uint64_t(Index(x, y)) << 8) | uint64_t(reason));
  }

  /// Evaluates every pixel requested since the last flush that is not exact
  /// yet, counting them by reason in stats->byReason. On Status::Pending,
  /// `pending` receives those pixels.
  Status Flush(SampleProvider& provider, const SampleRequest& what, int batchSize, bool parallel,
               ReconstructionStats* stats, std::vector<Point2i>* pending);

  const SurfaceTest& surfaces() const { return surfaces_; }
  /// `creaseAngle` (degrees, 0: off) turns the normal guides, if any, into
  /// crease marks between neighbouring pixels, and into the regions of each
  /// `regionCell` cell (the elementary block). Defined in surface_test.cpp.
  void SetGuides(GuideImage guides, ObjectTest test, float creaseAngle = 0.f, int regionCell = 16);

  /// The radiance of every pixel: exact L where exact, a*tau+b elsewhere.
  const std::vector<RGB>& radiance() const { return out_; }
  std::vector<RGB> TakeRadiance() { return std::move(out_); }
  const std::vector<SampleReason>& reasons() const { return reason_; }
  std::vector<SampleReason> TakeReasons() { return std::move(reason_); }

 private:
  void Write(int64_t i, const Value& v);
  int width_, height_;
  bool split_;
  PixelArray<RGB> a_, b_;  // (L_i, L_c) with the split only
  std::vector<RGB> out_, tau_;
  PixelArray<std::array<float, 2>> var_;  // (varA, varB) with variance only
  std::vector<SampleReason> reason_;
  PixelArray<uint8_t> finite_, filled_;
  std::vector<uint8_t> crease_, tauZero_;
  CellRegions regions_;
  AdjacentChanges changes_;
  GuideImage guides_;
  SurfaceTest surfaces_;
  tbb::enumerable_thread_specific<std::vector<uint64_t>> requests_;
};

}  // namespace dcm::detail
