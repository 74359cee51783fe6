// Reconstruction to a PSNR target or a budget of exact pixels, with the
// estimate of its error from exactly evaluated validation pixels.
#include "dcm/quality_target.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>
#include <optional>
#include <string>

#include "dcm/downsample.h"

namespace dcm {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// z of the one-sided 95 % bound (the two-sided 90 % interval).
constexpr double kZ = 1.6448536269514722;
/// The first run's threshold is this many times the options' threshold; the
/// runs go down from it, so that each one's samples are mostly reused by the
/// next (a lower threshold refines a superset of the blocks). Not above the
/// default: coarser runs miss small features (a highlight, a ball's shadow)
/// that few validation pixels see, and the estimate then errs high by 5 to
/// 8 dB (docs/QUALITY.md); the default threshold catches them on the scenes
/// it was tuned on.
constexpr double kStartFactor = 1.0;
/// With a budget, from higher still: a run the budget refuses leaves its
/// samples spent, and the coarsest run's samples are the ones every later run
/// needs (the corners, the probes), so the first run must fit.
constexpr double kStartFactorBudget = 16.0;
/// Below this threshold the next step is the full evaluation.
constexpr double kMinThreshold = 1e-3;
/// Threshold steps: at least this ratio (a large jump overshoots the cost),
/// at most the other (small steps cost engine runs).
constexpr double kMinStep = 0.5, kMaxStep = 0.85, kDefaultStep = 0.7;
/// At most this many validation draws (each of the first's size) in the
/// search: more where the point estimate reaches the target and its bound
/// does not.
constexpr int kMaxSearchDraws = 4;
/// The descent stops where two runs raised the lower bound by less than
/// this many dB while the pixels spent grew by more than this factor.
constexpr double kPlateauDb = 0.5, kPlateauGrowth = 1.25;
/// The share of the budget left that a run of the descent may spend.
constexpr double kDescentShare = 0.6;
/// Bisections between the last run within the budget and the one beyond.
constexpr int kBudgetBisections = 3;

/// Status message of an evaluation the budget refused (never shown: the
/// caller recognises CachingProvider::BudgetHit()).
constexpr const char* kBudgetMessage = "the exact-pixel budget is spent";

/// splitmix64: a small, seedable, platform-independent generator.
struct SplitMix64 {
  uint64_t s;
  uint64_t Next() {
    uint64_t z = (s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
  /// Uniform in [0, n).
  int Below(int n) { return int(Next() % uint64_t(n)); }
};

/// A number as a message shows it ("0.03", "40").
std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

double PsnrOf(double mse) { return mse > 0 ? 10.0 * std::log10(1.0 / mse) : kInf; }

/// A provider that evaluates each pixel of `inner` at most once over its
/// lifetime (several runs of the engine, the validation pixels), keeps the
/// guides of the whole image, and refuses an evaluation that would take the
/// distinct pixels beyond `limit` (0: none).
class CachingProvider : public SampleProvider {
 public:
  CachingProvider(SampleProvider& inner, int64_t limit)
      : inner_(inner), caps_(inner.Capabilities()), limit_(limit),
        index_(size_t(std::max(0, caps_.width)) * size_t(std::max(0, caps_.height)), -1) {}

  ProviderCapabilities Capabilities() const override { return caps_; }

  Status Guides(const Bounds2i& region, const GuideRequest& what, GuideImage* out) override {
    std::lock_guard<std::mutex> lock(guideMutex_);
    const bool same = guides_ && guides_->region == region && guideRequest_.objectId == what.objectId &&
                      guideRequest_.shaderId == what.shaderId && guideRequest_.texture == what.texture &&
                      guideRequest_.normal == what.normal;
    if (!same) {
      GuideImage g;
      DCM_RETURN_IF_ERROR(inner_.Guides(region, what, &g));
      guides_ = std::move(g);
      guideRequest_ = what;
    }
    *out = *guides_;
    return Status::Ok();
  }

  Status Evaluate(std::span<const Point2i> pixels, const SampleRequest& what, std::span<ExactSample> out) override {
    const uint8_t need = Mask(what);
    std::vector<size_t> misses;
    int64_t fresh = 0;  // pixels never evaluated before, reserved in the budget
    {
      std::lock_guard<std::mutex> lock(mutex_);
      for (size_t k = 0; k < pixels.size(); ++k) {
        const int32_t i = index_[Index(pixels[k])];
        if (i < 0 || (masks_[size_t(i)] & need) != need) misses.push_back(k);
      }
      for (size_t k : misses) fresh += index_[Index(pixels[k])] < 0 ? 1 : 0;
      if (limit_ > 0 && distinct_ + fresh > limit_) {
        budgetHit_ = true;
        return Status::Error(kBudgetMessage);
      }
      // Reserved before the (unlocked) evaluation: concurrent batches are
      // disjoint, so no pixel is counted twice.
      distinct_ += fresh;
    }
    std::vector<Point2i> ask(misses.size());
    for (size_t k = 0; k < misses.size(); ++k) ask[k] = pixels[misses[k]];
    std::vector<ExactSample> got(misses.size());
    const Status st = ask.empty() ? Status::Ok() : inner_.Evaluate(ask, what, got);
    std::lock_guard<std::mutex> lock(mutex_);
    if (!st.ok()) {
      distinct_ -= fresh;
      return st;
    }
    for (size_t k = 0; k < misses.size(); ++k) {
      int32_t& i = index_[Index(ask[k])];
      if (i < 0) {
        i = int32_t(samples_.size());
        samples_.push_back(got[k]);
        masks_.push_back(need);
      } else {
        samples_[size_t(i)] = got[k];
        masks_[size_t(i)] = need;
      }
    }
    for (size_t k = 0; k < pixels.size(); ++k) out[k] = samples_[size_t(index_[Index(pixels[k])])];
    return Status::Ok();
  }

  int64_t Distinct() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return distinct_;
  }
  bool BudgetHit() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return budgetHit_;
  }
  void ClearBudgetHit() {
    std::lock_guard<std::mutex> lock(mutex_);
    budgetHit_ = false;
  }
  /// The largest number of distinct pixels from now on (0: none).
  void SetLimit(int64_t limit) {
    std::lock_guard<std::mutex> lock(mutex_);
    limit_ = limit;
  }

 private:
  static uint8_t Mask(const SampleRequest& w) { return uint8_t(1 | (w.split ? 2 : 0) | (w.variance ? 4 : 0)); }
  size_t Index(Point2i p) const { return size_t(p.y) * size_t(caps_.width) + size_t(p.x); }

  SampleProvider& inner_;
  ProviderCapabilities caps_;
  int64_t limit_;
  mutable std::mutex mutex_;
  std::vector<int32_t> index_;  ///< per working pixel: its sample, -1 none
  std::vector<ExactSample> samples_;
  std::vector<uint8_t> masks_;  ///< what each sample holds (Mask)
  int64_t distinct_ = 0;
  bool budgetHit_ = false;
  std::mutex guideMutex_;
  std::optional<GuideImage> guides_;
  GuideRequest guideRequest_;
};

/// The validation pixels (output pixels) with their weights and exact values.
struct Validation {
  std::vector<Point2i> pixels;  ///< output pixels
  std::vector<double> weights;  ///< output pixels each stands for
  std::vector<RGB> exact;       ///< box mean of the exact working samples
};

/// One output pixel drawn uniformly in each cell of a grid of about `count`
/// cells over the output image (stratified: no region goes unchecked).
std::vector<Point2i> DrawValidation(int outW, int outH, int64_t count, uint64_t seed, std::vector<double>* weights) {
  const double area = double(outW) * double(outH);
  const int cell = std::max(1, int(std::lround(std::sqrt(area / double(std::max<int64_t>(1, count))))));
  SplitMix64 rng{seed};
  std::vector<Point2i> out;
  for (int y0 = 0; y0 < outH; y0 += cell) {
    for (int x0 = 0; x0 < outW; x0 += cell) {
      const int cw = std::min(cell, outW - x0), ch = std::min(cell, outH - y0);
      out.push_back({x0 + rng.Below(cw), y0 + rng.Below(ch)});
      weights->push_back(double(cw) * double(ch));
    }
  }
  return out;
}

RGB Display(const QualityGoal& goal, RGB c) {
  if (goal.display) return goal.display(c);
  return {SrgbEncode(c.r), SrgbEncode(c.g), SrgbEncode(c.b)};
}

/// The estimate of `image` (output resolution, `outW` wide) at the validation pixels.
PsnrEstimate EstimateAt(const Validation& v, const QualityGoal& goal, const std::vector<RGB>& image, int outW) {
  std::vector<double> d, w;
  d.reserve(v.pixels.size());
  w.reserve(v.pixels.size());
  for (size_t k = 0; k < v.pixels.size(); ++k) {
    const RGB x = image[size_t(v.pixels[k].y) * size_t(outW) + size_t(v.pixels[k].x)], r = v.exact[k];
    // Left out where either is not finite, as the stats' PSNR does.
    if (!IsFinite(x) || !IsFinite(r)) continue;
    const RGB dx = Display(goal, x), dr = Display(goal, r);
    double sq = 0;
    for (int c = 0; c < 3; ++c) sq += (double(dx[c]) - double(dr[c])) * (double(dx[c]) - double(dr[c]));
    d.push_back(sq / 3.0);
    w.push_back(v.weights[k]);
  }
  return EstimatePsnr(d, w);
}

/// Evaluates the working pixels of the validation's output pixels through
/// `cache` and keeps their box means.
Status EvaluateValidation(CachingProvider& cache, const ReconstructionOptions& options, const SampleRequest& what,
                          Validation* v, std::vector<Point2i>* pending) {
  const ProviderCapabilities caps = cache.Capabilities();
  const int s = std::max(1, options.downsample);
  std::vector<Point2i> work;
  for (const Point2i& p : v->pixels)
    for (int y = p.y * s; y < std::min(caps.height, (p.y + 1) * s); ++y)
      for (int x = p.x * s; x < std::min(caps.width, (p.x + 1) * s); ++x) work.push_back({x, y});
  std::vector<ExactSample> samples(work.size());
  const Status st = cache.Evaluate(work, what, samples);
  if (st.pending() && pending) *pending = work;
  DCM_RETURN_IF_ERROR(st);
  size_t k = 0;
  for (const Point2i& p : v->pixels) {
    RGB sum;
    int n = 0;
    for (int y = p.y * s; y < std::min(caps.height, (p.y + 1) * s); ++y)
      for (int x = p.x * s; x < std::min(caps.width, (p.x + 1) * s); ++x, ++n) sum += samples[k++].L;
    v->exact.push_back(sum * (1.f / float(n)));
  }
  return Status::Ok();
}

/// One finished run.
struct Run {
  Reconstruction rec;
  PsnrEstimate estimate;
  std::vector<LevelEstimate> levels;
  double threshold = 0;
};

}  // namespace

Status QualityGoal::Validate() const {
  if (!(targetPsnr >= 0) || targetPsnr > 99 || !std::isfinite(targetPsnr))
    return Status::Error("--target-psnr: must be in (0, 99] dB, got " + Num(targetPsnr));
  if (!(budget >= 0) || budget > 1 || !std::isfinite(budget))
    return Status::Error("--budget: must be a share of the pixels in (0, 1], got " + Num(budget));
  if (targetPsnr == 0 && budget == 0) return Status::Error("--target-psnr or --budget: neither is given");
  if (!(validationFraction > 0) || validationFraction > 1)
    return Status::Error("validationFraction: must be in (0, 1]");
  if (minValidationPixels < 2) return Status::Error("minValidationPixels: must be at least 2");
  return Status::Ok();
}

PsnrEstimate EstimatePsnr(const std::vector<double>& d, const std::vector<double>& w) {
  PsnrEstimate e;
  const size_t n = std::min(d.size(), w.size());
  double W = 0, sum = 0;
  for (size_t i = 0; i < n; ++i) W += w[i], sum += w[i] * d[i];
  if (n == 0 || !(W > 0)) {
    e.psnr = e.low = e.high = kNaN;
    return e;
  }
  const double m = sum / W;
  e.psnr = PsnrOf(m);
  if (n < 2) {
    e.low = e.high = kNaN;
    return e;
  }
  // Variance of the weighted mean as of independent draws (the stratified
  // draws vary less: this errs towards a wider interval).
  double var = 0;
  for (size_t i = 0; i < n; ++i) var += (w[i] / W) * (w[i] / W) * (d[i] - m) * (d[i] - m);
  var *= double(n) / double(n - 1);
  const double se = std::sqrt(var);
  e.low = PsnrOf(m + kZ * se);
  e.high = PsnrOf(std::max(0.0, m - kZ * se));
  return e;
}

Status ReconstructToQuality(SampleProvider& provider, const ReconstructionOptions& options, const QualityGoal& goal,
                            Reconstruction* out, QualityReport* report, std::vector<Point2i>* pending) {
  DCM_RETURN_IF_ERROR(goal.Validate());
  DCM_RETURN_IF_ERROR(options.Validate());
  const ProviderCapabilities caps = provider.Capabilities();
  if (caps.width <= 0 || caps.height <= 0) return Status::Error("the provider's image is empty");
  *report = QualityReport{};
  const int64_t total = int64_t(caps.width) * int64_t(caps.height);
  const int s = std::max(1, options.downsample);
  const int outW = (caps.width + s - 1) / s, outH = (caps.height + s - 1) / s;
  const int64_t limit = goal.budget > 0 ? std::max<int64_t>(1, int64_t(std::floor(goal.budget * double(total)))) : 0;
  CachingProvider cache(provider, limit);

  // The validation: a share of the output pixels, at most a quarter of the budget.
  const int64_t outPixels = int64_t(outW) * int64_t(outH);
  int64_t count = std::max<int64_t>(goal.minValidationPixels, int64_t(std::ceil(goal.validationFraction * double(outPixels))));
  // Without a target the estimate is only reported: a twentieth of the budget.
  if (limit > 0)
    count = std::min(count, std::max<int64_t>(2, limit / (goal.targetPsnr > 0 ? 4 : 20) / (int64_t(s) * s)));
  count = std::min(count, outPixels);
  const bool split = caps.splitRadiance && options.textureSplit;
  const SampleRequest what{split, caps.variance};
  Validation v;
  std::vector<uint8_t> drawn(size_t(outPixels), 0);  // output pixels validated, for the cost
  int draws = 0;
  // One more stratified draw of `count` pixels, with its own seed: the union
  // of independent unbiased draws (equal total weights) is unbiased.
  auto drawMore = [&](Validation* into) -> Status {
    Validation more;
    more.pixels = DrawValidation(outW, outH, count, goal.seed + uint64_t(draws), &more.weights);
    DCM_RETURN_IF_ERROR(EvaluateValidation(cache, options, what, &more, pending));
    ++draws;
    for (size_t k = 0; k < more.pixels.size(); ++k) {
      const Point2i p = more.pixels[k];
      uint8_t& mark = drawn[size_t(p.y) * size_t(outW) + size_t(p.x)];
      if (!mark) {
        const int bw = std::min(s, caps.width - p.x * s), bh = std::min(s, caps.height - p.y * s);
        report->validationExactPixels += int64_t(bw) * bh;
        ++report->validationPixels;
        mark = 1;
      }
      into->pixels.push_back(p);
      into->weights.push_back(more.weights[k]);
      into->exact.push_back(more.exact[k]);
    }
    return Status::Ok();
  };
  if (Status st = drawMore(&v); !st.ok()) {
    if (cache.BudgetHit())
      return Status::Error("--budget " + Num(goal.budget) + ": too small for the validation pixels");
    return st;
  }
  report->totalPixels = total;

  // What every run cost, refused ones included.
  ReconstructionStats spent;
  // One run at threshold t (< 0: the full evaluation); nullopt where the budget refused it.
  auto runAt = [&](double t, std::optional<Run>* result) -> Status {
    ReconstructionOptions o = options;
    if (t < 0) o.fullEvaluation = true;
    else o.contrastThreshold = float(t);
    Run r;
    r.threshold = t;
    if (options.onLevel) {
      o.onLevel = [&](int level, int w, int h, const std::vector<RGB>& work) {
        int ow = 0, oh = 0;
        const std::vector<RGB> image = BoxDownsample(work, w, h, s, &ow, &oh);
        r.levels.push_back({level, EstimateAt(v, goal, image, ow)});
        options.onLevel(level, w, h, work);
      };
    }
    ++report->runs;
    cache.ClearBudgetHit();
    const Status st =
        goal.reconstruct ? goal.reconstruct(cache, o, &r.rec, pending) : Reconstruct(cache, o, &r.rec, pending);
    spent.timeGuidesS += r.rec.stats.timeGuidesS;
    spent.timeProviderS += r.rec.stats.timeProviderS;
    spent.timeEngineS += r.rec.stats.timeEngineS;
    spent.providerCalls += r.rec.stats.providerCalls;
    if (!st.ok()) {
      if (cache.BudgetHit()) {
        result->reset();
        return Status::Ok();
      }
      return st;
    }
    r.estimate = EstimateAt(v, goal, r.rec.image, r.rec.width);
    *result = std::move(r);
    return Status::Ok();
  };

  const double threshold = double(ResolveSettings(options, caps).contrastThreshold);
  // Contrasts are at most 1 but for the display-weighted metric's brightest sets.
  const double t0 = limit > 0 ? std::min(kStartFactorBudget * threshold, 1.0) : kStartFactor * threshold;
  auto meets = [&](const Run& r) { return goal.targetPsnr > 0 && r.estimate.low >= goal.targetPsnr; };

  std::optional<Run> best, tried;
  std::vector<double> lows, spends;  // per run of the descent: the lower bound, the pixels spent
  double t = t0 > 0 ? t0 : kMinThreshold;
  double lastT = 0, lastLow = kNaN, lastUsed = 0;
  std::optional<double> refused;  // the largest threshold the budget refused (-1: the full evaluation)
  for (;;) {
    // A run of the descent after the first may spend only part of what is
    // left: one the budget refuses leaves the rest to the bisection below.
    if (limit > 0 && best) {
      const int64_t used = cache.Distinct();
      cache.SetLimit(used + int64_t(kDescentShare * double(limit - used)));
    }
    DCM_RETURN_IF_ERROR(runAt(t, &tried));
    if (!tried) {
      refused = t;
      break;
    }
    best = std::move(tried);
    // The point estimate reaches the target but its bound does not: the
    // validation is too small for how the error is spread (a few pixels
    // carry most of it). More draws before more samples of the image.
    while (goal.targetPsnr > 0 && !meets(*best) && best->estimate.psnr >= goal.targetPsnr && draws < kMaxSearchDraws) {
      cache.ClearBudgetHit();
      if (Status st = drawMore(&v); !st.ok()) {
        if (cache.BudgetHit()) break;
        return st;
      }
      best->estimate = EstimateAt(v, goal, best->rec.image, best->rec.width);
    }
    const double low = best->estimate.low;
    if (meets(*best) || t < 0) break;
    // A plateau: the bound barely moved over the last two runs while the
    // samples grew. What the validation sees is then error that a lower
    // threshold does not remove (a feature the lattice misses at any
    // threshold, hit by a validation pixel); the last draw judges the result.
    lows.push_back(low);
    spends.push_back(double(cache.Distinct()));
    const size_t n = lows.size();
    if (goal.targetPsnr > 0 && n >= 3 && std::isfinite(lows[n - 3]) && lows[n - 1] - lows[n - 3] < kPlateauDb &&
        spends[n - 1] > kPlateauGrowth * spends[n - 3])
      break;
    if (t <= kMinThreshold) {
      // The threshold cannot go lower: the full evaluation reaches any target.
      t = -1;
      continue;
    }
    // Secants in log threshold: of the lower bound, the step that reaches the
    // target; of the log exact pixels, the step that fills the budget. The
    // smaller step of the two.
    double toTarget = goal.targetPsnr > 0 ? kDefaultStep : 0, toBudget = limit > 0 ? kDefaultStep : 0;
    const double used = double(cache.Distinct());
    if (lastT > 0) {
      const double dlogT = std::log(t) - std::log(lastT);
      if (toTarget > 0 && std::isfinite(low) && std::isfinite(lastLow) && low > lastLow)
        toTarget = std::exp((goal.targetPsnr - low) * dlogT / (low - lastLow));
      if (toBudget > 0 && used > lastUsed)
        toBudget = std::exp((std::log(double(limit)) - std::log(used)) * dlogT / (std::log(used) - std::log(lastUsed)));
    }
    const double step = std::max(toTarget, toBudget);
    lastT = t;
    lastLow = low;
    lastUsed = used;
    t = std::max(kMinThreshold, t * std::clamp(step, kMinStep, kMaxStep));
  }
  cache.SetLimit(limit);
  if (!best) {
    // The first run did not fit: try thresholds above it (fewer edge blocks).
    for (double up = t0 * 4; !best && up <= t0 * 1024; up *= 4) {
      DCM_RETURN_IF_ERROR(runAt(up, &best));
      if (!best) refused = up;
    }
    if (!best)
      return Status::Error("--budget " + Num(goal.budget) +
                           ": below what the coarsest reconstruction needs (the block corners and the validation)");
  }
  if (refused && !meets(*best) && best->threshold > 0) {
    // Between the last run within the budget and the one beyond: the samples
    // the refused run left are spent already.
    report->budgetBound = true;
    double hi = best->threshold, lo = *refused < 0 ? 0 : *refused;
    for (int i = 0; i < kBudgetBisections; ++i) {
      const double mid = lo > 0 ? std::sqrt(hi * lo) : hi * 0.5;
      DCM_RETURN_IF_ERROR(runAt(mid, &tried));
      if (!tried) {
        lo = mid;
        continue;
      }
      hi = mid;
      const bool done = meets(*tried);
      best = std::move(tried);
      if (done) break;
    }
  } else if (refused && !meets(*best)) {
    report->budgetBound = true;
  }

  // The search stopped where its validation pixels looked good enough: on
  // them the result errs high (the more runs, the more; 10 dB on the tracer's
  // room). A fresh draw, which chose nothing, estimates the result.
  if (goal.targetPsnr > 0 && best->threshold >= 0) {
    Validation fresh;
    cache.ClearBudgetHit();
    if (Status st = drawMore(&fresh); st.ok()) {
      best->estimate = EstimateAt(fresh, goal, best->rec.image, best->rec.width);
      report->confirmed = true;
    } else if (!cache.BudgetHit()) {
      return st;
    }
  }
  report->estimate = best->estimate;
  report->levels = std::move(best->levels);
  report->threshold = best->threshold;
  report->targetReached = goal.targetPsnr <= 0 || meets(*best);
  report->exactPixels = cache.Distinct();
  *out = std::move(best->rec);
  // The cost of the whole search: every pixel evaluated, every run's time.
  out->stats.exactPixels = report->exactPixels;
  out->stats.timeGuidesS = spent.timeGuidesS;
  out->stats.timeProviderS = spent.timeProviderS;
  out->stats.timeEngineS = spent.timeEngineS;
  out->stats.providerCalls = spent.providerCalls;
  return Status::Ok();
}

}  // namespace dcm
