#include "sample_store.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "elapsed.h"
#include "texture_split.h"

namespace dcm::detail {

SampleStore::SampleStore(int width, int height, bool split, bool variance)
    : width_(width), height_(height), split_(split) {
  const size_t n = size_t(width) * size_t(height);
  out_.assign(n, RGB{});
  reason_.assign(n, SampleReason::kInterpolated);
  // The store's own arrays are allocated uninitialised and filled in
  // parallel (PixelArray); the outputs' (out_, reason_) are std::vectors.
  if (split_) {
    a_.resize(n);
    b_.resize(n);
  }
  finite_.resize(n);
  filled_.resize(n);
  if (variance) var_.resize(n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, size_t(1) << 16), [&](const tbb::blocked_range<size_t>& r) {
    const size_t begin = r.begin(), count = r.size();
    if (split_) {
      std::fill_n(a_.data() + begin, count, RGB{});
      std::fill_n(b_.data() + begin, count, RGB{});
    }
    std::fill_n(finite_.data() + begin, count, uint8_t(1));
    std::fill_n(filled_.data() + begin, count, uint8_t(0));
    if (variance) std::fill_n(var_.data() + begin, count, std::array<float, 2>{0.f, 0.f});
  });
}

std::array<float, 2> SampleStore::LuminanceVariances(RGB varL, RGB tau) {
  // The noise of the three channels is taken as fully correlated (one path
  // carries all three), so their standard deviations add with the luminance
  // weights: sd(lum) = Luminance(sd). L_i = (L - L_c)/tau carries the noise
  // of L divided by tau; L_c may carry all of it.
  RGB sd, sdA;
  for (int c = 0; c < 3; ++c) {
    // An unknown (non-finite or negative) variance counts as none: the
    // sample's differences are then judged as the paper judges them.
    sd[c] = (std::isfinite(varL[c]) && varL[c] > 0.f) ? std::sqrt(varL[c]) : 0.f;
    sdA[c] = sd[c] / std::max(std::fabs(tau[c]), 1e-6f);
  }
  const float a = Luminance(sdA), b = Luminance(sd);
  return {a * a, b * b};
}

bool SampleStore::ClampSample(ExactSample* s) {
  bool clamped = false;
  for (RGB* v : {&s->L, &s->Li, &s->Lc})
    for (int c = 0; c < 3; ++c) {
      float& x = (*v)[c];
      // NaN and infinity stay: they are counted apart and kept to their pixel.
      if (std::isfinite(x) && std::fabs(x) > kMaxSampleMagnitude) {
        x = std::copysign(kMaxSampleMagnitude, x);
        clamped = true;
      }
    }
  return clamped;
}

void SampleStore::ReplaceExact(int64_t i, const Value& v) { Write(i, v); }

void SampleStore::Write(int64_t i, const Value& v) {
  if (split_) {
    a_[i] = v.a;
    b_[i] = v.b;
    out_[i] = v.a * tau_[i] + v.b;
  } else {
    out_[i] = v.a;
  }
  if (!var_.empty()) var_[i] = {v.varA, v.varB};
}

Status SampleStore::Flush(SampleProvider& provider, const SampleRequest& what, int batchSize,
                          bool parallel, ReconstructionStats* stats, std::vector<Point2i>* pending) {
  std::vector<uint64_t> keys;
  for (auto& local : requests_) {
    keys.insert(keys.end(), local.begin(), local.end());
    local.clear();
  }
  if (keys.empty()) return Status::Ok();
  // Sorted by pixel, then by reason: the first key of each pixel carries the
  // reason of highest priority, whatever order the requests came in.
  tbb::parallel_sort(keys.begin(), keys.end());
  std::vector<Point2i> pixels;
  std::vector<SampleReason> reasons;
  pixels.reserve(keys.size());
  for (size_t k = 0; k < keys.size(); ++k) {
    const int64_t i = int64_t(keys[k] >> 8);
    if (k > 0 && (keys[k - 1] >> 8) == (keys[k] >> 8)) continue;
    if (IsExact(i)) continue;
    pixels.push_back({int(i % width_), int(i / width_)});
    reasons.push_back(SampleReason(keys[k] & 0xff));
  }
  if (pixels.empty()) return Status::Ok();

  // All or none: a budget refuses the whole request before any batch runs.
  DCM_RETURN_IF_ERROR(provider.Admit(pixels, what));
  std::vector<ExactSample> samples(pixels.size());
  // Batches of at most batchSize, and small enough that a short phase still
  // keeps every worker busy (results do not depend on the batching).
  size_t batch = size_t(std::max(1, batchSize));
  if (parallel) {
    const size_t workers = size_t(std::max(1, tbb::this_task_arena::max_concurrency()));
    batch = std::min(batch, std::max<size_t>(16, (pixels.size() + 4 * workers - 1) / (4 * workers)));
  }
  const size_t nbatches = (pixels.size() + batch - 1) / batch;
  std::vector<Status> results(nbatches);
  auto run = [&](size_t bi) {
    const size_t begin = bi * batch, end = std::min(pixels.size(), begin + batch);
    results[bi] = provider.Evaluate(std::span(pixels).subspan(begin, end - begin), what,
                                    std::span(samples).subspan(begin, end - begin));
  };
  const auto t0 = std::chrono::steady_clock::now();
  if (parallel && nbatches > 1) {
    tbb::parallel_for(size_t(0), nbatches, run);
  } else {
    for (size_t bi = 0; bi < nbatches; ++bi) run(bi);
  }
  stats->timeProviderS += SecondsSince(t0);
  stats->providerCalls += int64_t(nbatches);
  for (const Status& s : results) {
    if (s.pending()) {
      if (pending) *pending = std::move(pixels);
      return s;
    }
    if (!s.ok()) return s;
  }

  // The pixels are distinct: their samples are stored in parallel, and the
  // counts (integers) summed per range add up to the same whatever the split.
  struct Counts {
    int64_t clamped = 0, nonFinite = 0;
    std::array<int64_t, kSampleReasonCount> byReason{};
  };
  tbb::enumerable_thread_specific<Counts> counts;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
    Counts& n = counts.local();
    for (size_t k = r.begin(); k != r.end(); ++k) {
      const int64_t i = Index(pixels[k].x, pixels[k].y);
      ExactSample& s = samples[k];
      if (ClampSample(&s)) ++n.clamped;
      reason_[i] = reasons[k];
      ++n.byReason[size_t(reasons[k])];
      out_[i] = s.L;
      if (split_) {
        a_[i] = s.Li;
        b_[i] = s.Lc;
      }
      // Where tau is exactly zero (a surface without diffuse texture: the sky,
      // chrome, an emitter, a black texel) L = L_c and L_i means nothing: it is
      // set to 0, and the sample interpolates L_c for pixels whose tau is zero
      // too (the surface test keeps tau = 0 and tau != 0 apart).
      const bool tauZero = split_ && TauZero(tau_[i]);
      if (tauZero) a_[i] = RGB{};
      const bool finite =
          dcm::IsFinite(s.L) && (!split_ || ((tauZero || dcm::IsFinite(s.Li)) && dcm::IsFinite(s.Lc)));
      if (!finite) ++n.nonFinite;
      // Where tau is denormal, L_i = L_t / tau is not recoverable: the sample
      // keeps its own exact L but never serves to interpolate others.
      finite_[i] = (finite && (!split_ || tauZero || TauRecoverable(tau_[i]))) ? 1 : 0;
      if (!var_.empty()) var_[i] = LuminanceVariances(s.variance, split_ ? tau_[i] : RGB::Gray(1.f));
    }
  });
  for (const Counts& n : counts) {
    stats->clampedSamples += n.clamped;
    stats->nonFiniteSamples += n.nonFinite;
    for (size_t r = 0; r < n.byReason.size(); ++r) stats->byReason[r] += n.byReason[r];
  }
  return Status::Ok();
}

}  // namespace dcm::detail
