// Reconstruction to a PSNR target or a budget of exact pixels, with the
// estimate of its error from exactly evaluated validation pixels.
#include "dcm/quality_target.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <mutex>
#include <optional>
#include <string>
#include <utility>

#include "dcm/downsample.h"
#include "number_text.h"
#include "sample_mask.h"

namespace dcm {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// z of the one-sided 95 % bound (the two-sided 90 % interval).
constexpr double kZ = 1.6448536269514722;
/// The first run's threshold is this many times the options' threshold; the
/// runs go down from it, so that each one's samples are mostly reused by the
/// next (a lower threshold refines a superset of the blocks). Not above the
/// default: a coarser run misses small features (a highlight, a ball's
/// shadow) that no draw of a few percent sees reliably; from twice the
/// default, the traced test scene stopped at 39.2 dB for a target of 40
/// (docs/QUALITY.md).
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
/// this many dB while the pixels spent grew by more than this factor, and
/// the samples are noisy or fewer than kFewEffectivePixels carry the
/// estimate; elsewhere the error is spread over the image, only lower
/// thresholds remove it, and a target asked for is spent for.
constexpr double kPlateauDb = 0.5, kPlateauGrowth = 1.25;
/// The share of the budget left that a run of the descent may spend.
constexpr double kDescentShare = 0.6;
/// The pixels a run of the descent may reach: `used` and the share of the rest.
int64_t ShareOfWhatIsLeft(int64_t used, int64_t limit) {
  return used + int64_t(kDescentShare * double(limit - used));
}
/// Where what is left of the budget allows only a step of the threshold above
/// this factor, the descent stops: such a step buys a few pixels for a run.
constexpr double kLastBudgetStep = 0.97;
/// Bisections between the last run within the budget and the one beyond.
constexpr int kBudgetBisections = 3;
/// Without a budget, at most this many confirming draws (and runs after the
/// first); with one, the budget bounds them.
constexpr int kMaxConfirmations = 3;

/// The step of the threshold from `t` that brings the lower bound `low` to
/// `target`, by the secant through the run before (`lastT`, `lastLow`) in log
/// threshold; `fallback` where there is no rising secant. Not clamped.
double SecantStep(double t, double low, double lastT, double lastLow, double target, double fallback) {
  if (!(lastT > 0) || !std::isfinite(low) || !std::isfinite(lastLow) || !(low > lastLow)) return fallback;
  return std::exp((target - low) * (std::log(t) - std::log(lastT)) / (low - lastLow));
}

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

double PsnrOf(double mse) { return mse > 0 ? 10.0 * std::log10(1.0 / mse) : kInf; }

/// A provider that evaluates each pixel of `inner` at most once over its
/// lifetime (several runs of the engine, the validation pixels), keeps the
/// guides of the whole image, and refuses an evaluation that would take the
/// distinct pixels beyond `limit` (0: none). Each pixel is asked for at
/// least `widest`, the channels any run of the search asks for: a full
/// evaluation asks for L alone, and a later run would pay for the pixel again.
class CachingProvider : public SampleProvider {
 public:
  CachingProvider(SampleProvider& inner, int64_t limit, SampleRequest widest)
      : inner_(inner), caps_(inner.Capabilities()), limit_(limit), widest_(widest),
        index_(size_t(std::max(0, caps_.width)) * size_t(std::max(0, caps_.height)), -1),
        reserved_(index_.size(), 0) {}

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

  /// With a budget, reserves the pixels of `pixels` never evaluated nor
  /// reserved before, or refuses them all: the engine's batches of one
  /// request then run within the budget whatever their order.
  Status Admit(std::span<const Point2i> pixels, const SampleRequest& asked) override {
    (void)asked;
    if (limit_ <= 0) return Status::Ok();
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<size_t> fresh;
    for (const Point2i& p : pixels)
      if (Uncounted(Index(p))) fresh.push_back(Index(p));
    std::sort(fresh.begin(), fresh.end());
    fresh.erase(std::unique(fresh.begin(), fresh.end()), fresh.end());
    if (!Reserve(int64_t(fresh.size()))) return Status::OverBudget(kBudgetMessage);
    for (size_t i : fresh) reserved_[i] = 1;
    return Status::Ok();
  }

  Status Evaluate(std::span<const Point2i> pixels, const SampleRequest& asked, std::span<ExactSample> out) override {
    const SampleRequest what{asked.split || widest_.split, asked.variance || widest_.variance};
    const uint8_t need = detail::RequestMask(what);
    std::vector<size_t> misses;
    int64_t fresh = 0;  // pixels neither evaluated nor admitted before, reserved in the budget
    {
      std::lock_guard<std::mutex> lock(mutex_);
      for (size_t k = 0; k < pixels.size(); ++k) {
        const int32_t i = index_[Index(pixels[k])];
        if (i < 0 || (masks_[size_t(i)] & need) != need) misses.push_back(k);
      }
      // A pixel twice in one batch (importance draws are with replacement) is evaluated once.
      std::sort(misses.begin(), misses.end(), [&](size_t a, size_t b) { return Index(pixels[a]) < Index(pixels[b]); });
      misses.erase(std::unique(misses.begin(), misses.end(),
                               [&](size_t a, size_t b) { return Index(pixels[a]) == Index(pixels[b]); }),
                   misses.end());
      for (size_t k : misses) fresh += Uncounted(Index(pixels[k])) ? 1 : 0;
      // Reserved before the (unlocked) evaluation: concurrent batches are
      // disjoint, so no pixel is counted twice.
      if (!Reserve(fresh)) return Status::OverBudget(kBudgetMessage);
      if (marking_)
        for (const Point2i& p : pixels) engine_[Index(p)] = 1;
    }
    std::vector<Point2i> ask(misses.size());
    for (size_t k = 0; k < misses.size(); ++k) ask[k] = pixels[misses[k]];
    std::vector<ExactSample> got(misses.size());
    const Status st = ask.empty() ? Status::Ok() : inner_.Evaluate(ask, what, got);
    std::vector<Point2i> extra;
    std::vector<ExactSample> extraSamples;
    if (st.ok() && !ask.empty()) inner_.TakeExtraSamples(&extra, &extraSamples);
    std::lock_guard<std::mutex> lock(mutex_);
    if (!st.ok()) {
      distinct_ -= fresh;
      return st;
    }
    // Without a budget, the pixels the call computed besides are cached and
    // counted as evaluated; TakeExtraSamples passes them on. A budget does
    // not take them: counted at par they crowd out the pixels the runs ask
    // for, which are worth more (docs/QUALITY.md).
    pendingExtra_.clear();
    pendingExtraSamples_.clear();
    for (size_t k = 0; k < extra.size() && k < extraSamples.size() && limit_ <= 0; ++k) {
      const Point2i p = extra[k];
      if (p.x < 0 || p.y < 0 || p.x >= caps_.width || p.y >= caps_.height) continue;
      int32_t& i = index_[Index(p)];
      if (i >= 0) continue;
      i = int32_t(samples_.size());
      samples_.push_back(extraSamples[k]);
      masks_.push_back(need);
      ++distinct_;
      pendingExtra_.push_back(p);
      pendingExtraSamples_.push_back(extraSamples[k]);
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

  /// The extra pixels of the last call that evaluated something, once.
  void TakeExtraSamples(std::vector<Point2i>* pixels, std::vector<ExactSample>* samples) override {
    std::lock_guard<std::mutex> lock(mutex_);
    *pixels = std::exchange(pendingExtra_, {});
    *samples = std::exchange(pendingExtraSamples_, {});
  }

  int64_t Distinct() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return distinct_;
  }
  /// The sample of working pixel p, or null where none was evaluated; valid
  /// until the next Evaluate().
  const ExactSample* SampleAt(Point2i p) const {
    std::lock_guard<std::mutex> lock(mutex_);
    const int32_t i = index_[Index(p)];
    return i < 0 ? nullptr : &samples_[size_t(i)];
  }
  /// The working pixels (row-major indices) that hold a sample.
  std::vector<size_t> Evaluated() const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<size_t> out;
    out.reserve(samples_.size());
    for (size_t i = 0; i < index_.size(); ++i)
      if (index_[i] >= 0) out.push_back(i);
    return out;
  }
  bool BudgetHit() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return budgetHit_;
  }
  void ClearBudgetHit() {
    std::lock_guard<std::mutex> lock(mutex_);
    budgetHit_ = false;
  }
  /// While on, every pixel asked is marked as the engine's (EngineAsked):
  /// on during a run of the engine, off for the validation. Turning it on
  /// clears the marks of the run before.
  void MarkEngine(bool on) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (on) engine_.assign(index_.size(), 0);
    marking_ = on;
  }
  /// The working pixel (row-major index) was asked by the current (or last)
  /// run of the engine. Read between batches (the level callbacks).
  bool EngineAsked(size_t i) const { return i < engine_.size() && engine_[i]; }
  /// The largest number of distinct pixels from now on (0: none).
  void SetLimit(int64_t limit) {
    std::lock_guard<std::mutex> lock(mutex_);
    limit_ = limit;
  }

 private:
  size_t Index(Point2i p) const { return size_t(p.y) * size_t(caps_.width) + size_t(p.x); }
  /// Working pixel i is not yet in the distinct count: neither evaluated nor
  /// admitted. With mutex_ held.
  bool Uncounted(size_t i) const { return index_[i] < 0 && !reserved_[i]; }
  /// Counts `fresh` more distinct pixels, or refuses them where they would
  /// pass the budget (BudgetHit). With mutex_ held.
  bool Reserve(int64_t fresh) {
    if (limit_ > 0 && distinct_ + fresh > limit_) {
      budgetHit_ = true;
      return false;
    }
    distinct_ += fresh;
    return true;
  }

  SampleProvider& inner_;
  ProviderCapabilities caps_;
  int64_t limit_;
  SampleRequest widest_;
  mutable std::mutex mutex_;
  std::vector<int32_t> index_;  ///< per working pixel: its sample, -1 none
  std::vector<uint8_t> reserved_;  ///< per working pixel: counted in the budget by Admit
  std::vector<ExactSample> samples_;
  std::vector<uint8_t> masks_;  ///< what each sample holds (detail::RequestMask)
  int64_t distinct_ = 0;
  bool budgetHit_ = false;
  bool marking_ = false;
  std::vector<uint8_t> engine_;  ///< per working pixel: asked by the engine's run (MarkEngine)
  std::vector<Point2i> pendingExtra_;  ///< TakeExtraSamples's
  std::vector<ExactSample> pendingExtraSamples_;
  std::mutex guideMutex_;
  std::optional<GuideImage> guides_;
  GuideRequest guideRequest_;
};

/// The validation pixels (output pixels) with their weights and exact values.
struct Validation {
  std::vector<Point2i> pixels;  ///< output pixels
  std::vector<double> weights;  ///< output pixels each stands for
  std::vector<RGB> exact;       ///< box mean of the exact working samples
  /// With samples that carry their variance: per output pixel, the variance
  /// of each of its working samples divided by the box's pixel count squared
  /// (its share in the variance of the box mean), from `first[k]` on.
  std::vector<RGB> variance;
  std::vector<size_t> first;
  /// The output pixel count times the number of draws: what the weights sum
  /// to (exactly for stratified draws, on average for importance draws).
  double total = 0;
  bool importance = false;  ///< some draw followed an error proxy (EstimatePsnr's `total`)

  /// Adds pixel `k` of `from`.
  void Append(const Validation& from, size_t k) {
    pixels.push_back(from.pixels[k]);
    weights.push_back(from.weights[k]);
    exact.push_back(from.exact[k]);
    if (from.variance.empty()) return;
    if (first.empty()) first.push_back(0);
    variance.insert(variance.end(), from.variance.begin() + std::ptrdiff_t(from.first[k]),
                    from.variance.begin() + std::ptrdiff_t(from.first[k + 1]));
    first.push_back(variance.size());
  }
  /// Adds every pixel of `from` (a whole draw).
  void AppendAll(const Validation& from) {
    for (size_t k = 0; k < from.pixels.size(); ++k) Append(from, k);
    total += from.total;
    importance = importance || from.importance;
  }
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

/// The display-referred encoding of a linear value (QualityGoal::display).
RGB Display(const QualityGoal& goal, RGB c) {
  if (goal.display) return goal.display(c);
  return {SrgbEncode(c.r), SrgbEncode(c.g), SrgbEncode(c.b)};
}

/// Share of an importance draw that follows the error proxy; the rest is
/// uniform over the image, so that every pixel can be drawn (a draw then
/// estimates any run, not only the one whose proxy chose it) and no weight
/// exceeds 1 / (1 - kProxyShare) times the uniform draw's. Chosen on the
/// tuning set (docs/TUNING.md, Q) with kProxySpread, by simulated draws on
/// the results and their references: 0.5 and 0.8 shares, spreads of 1/16,
/// 1/4 and 1/2 elementary block.
constexpr double kProxyShare = 0.8;
/// The max filter that spreads the proxy: this share of the elementary block
/// on each side.
constexpr double kProxySpread = 0.25;

/// Where a run's error is likely, per output pixel (any scale): the detail
/// the run found, i.e. the squared display difference between the result and
/// the bilinear interpolation of its elementary lattice, spread by a max
/// filter (kProxySpread). The error that remains sits by what the engine has
/// seen of an edge, a highlight or a thin object: the ends it did not follow,
/// the crossings it filled, the preview stand-ins it kept. Noise-free, a box
/// the engine evaluated entirely has no error (the result is its exact
/// value): 0 there.
std::vector<double> ErrorProxy(const Reconstruction& rec, const QualityGoal& goal, int s, bool noise) {
  const int outW = rec.width, outH = rec.height;
  const size_t N = size_t(outW) * size_t(outH);
  const int L = std::max(1, rec.stats.settings.elementaryBlock / s);
  auto pix = [&](int x, int y) {
    return Display(goal, rec.image[size_t(std::min(y, outH - 1)) * size_t(outW) + size_t(std::min(x, outW - 1))]);
  };
  std::vector<double> detail(N, 0.0);
  for (int y = 0; y < outH; ++y)
    for (int x = 0; x < outW; ++x) {
      const int x0 = x / L * L, y0 = y / L * L;
      const float u = float(x - x0) / float(L), v = float(y - y0) / float(L);
      const RGB lerp = pix(x0, y0) * ((1 - u) * (1 - v)) + pix(x0 + L, y0) * (u * (1 - v)) +
                       pix(x0, y0 + L) * ((1 - u) * v) + pix(x0 + L, y0 + L) * (u * v);
      const RGB r = pix(x, y);
      double sq = 0;
      for (int k = 0; k < 3; ++k) sq += (double(r[k]) - double(lerp[k])) * (double(r[k]) - double(lerp[k]));
      if (std::isfinite(sq)) detail[size_t(y) * size_t(outW) + size_t(x)] = sq;
    }
  // The max filter, separable.
  const int r = int(std::lround(kProxySpread * double(L)));
  std::vector<double> rows(N, 0.0);
  for (int y = 0; y < outH; ++y)
    for (int x = 0; x < outW; ++x) {
      double m = 0;
      for (int k = std::max(0, x - r); k <= std::min(outW - 1, x + r); ++k)
        m = std::max(m, detail[size_t(y) * size_t(outW) + size_t(k)]);
      rows[size_t(y) * size_t(outW) + size_t(x)] = m;
    }
  std::vector<double> proxy(N, 0.0);
  for (int y = 0; y < outH; ++y)
    for (int x = 0; x < outW; ++x) {
      double m = 0;
      for (int k = std::max(0, y - r); k <= std::min(outH - 1, y + r); ++k)
        m = std::max(m, rows[size_t(k) * size_t(outW) + size_t(x)]);
      proxy[size_t(y) * size_t(outW) + size_t(x)] = m;
    }
  // A preview stand-in is a pixel the engine wanted exact and did not get:
  // as likely wrong as the likeliest detail.
  double top = 0;
  for (double p : proxy) top = std::max(top, p);
  for (int wy = 0; wy < rec.workHeight; ++wy)
    for (int wx = 0; wx < rec.workWidth; ++wx)
      if (rec.sampleMap[size_t(wy) * size_t(rec.workWidth) + size_t(wx)] == SampleReason::kPreviewStandIn)
        proxy[size_t(wy / s) * size_t(outW) + size_t(wx / s)] = top > 0 ? top : 1.0;
  if (noise) return proxy;
  for (int y = 0; y < outH; ++y)
    for (int x = 0; x < outW; ++x) {
      bool all = true;
      for (int wy = y * s; all && wy < std::min(rec.workHeight, (y + 1) * s); ++wy)
        for (int wx = x * s; all && wx < std::min(rec.workWidth, (x + 1) * s); ++wx) {
          const SampleReason why = rec.sampleMap[size_t(wy) * size_t(rec.workWidth) + size_t(wx)];
          all = HoldsExactSample(why);
        }
      if (all) proxy[size_t(y) * size_t(outW) + size_t(x)] = 0;
    }
  return proxy;
}

/// `count` output pixels drawn independently with probability q = a mixture
/// of the uniform (1 - kProxyShare) and of `proxy` (kProxyShare); each with
/// the weight 1 / (count q), the share of the image it stands for (their sum
/// is the pixel count on average): the Hansen-Hurwitz estimate of the mean
/// error, unbiased whatever the proxy.
std::vector<Point2i> DrawImportance(const std::vector<double>& proxy, int outW, int64_t count, uint64_t seed,
                                    std::vector<double>* weights) {
  const size_t N = proxy.size();
  double total = 0;
  for (double p : proxy) total += p;
  const double share = total > 0 ? kProxyShare : 0.0;
  std::vector<double> cdf(N);
  double acc = 0;
  for (size_t i = 0; i < N; ++i) {
    acc += (1.0 - share) / double(N) + (total > 0 ? share * proxy[i] / total : 0.0);
    cdf[i] = acc;
  }
  SplitMix64 rng{seed};
  std::vector<Point2i> out;
  for (int64_t k = 0; k < count; ++k) {
    const double u = double(rng.Next() >> 11) * 0x1.0p-53 * acc;
    const size_t i = std::min(N - 1, size_t(std::upper_bound(cdf.begin(), cdf.end(), u) - cdf.begin()));
    const double q = (1.0 - share) / double(N) + (total > 0 ? share * proxy[i] / total : 0.0);
    out.push_back({int(i % size_t(outW)), int(i / size_t(outW))});
    weights->push_back(1.0 / (double(count) * q));
  }
  return out;
}

/// Which working pixels (row-major index) the engine evaluated itself.
using SampledFn = std::function<bool(size_t)>;

/// The standard deviations of variances `var` (negative ones as 0).
RGB StdDev(RGB var) {
  return {std::sqrt(std::max(0.f, var.r)), std::sqrt(std::max(0.f, var.g)), std::sqrt(std::max(0.f, var.b))};
}

/// The display-space variance (mean over the display's channels) of a linear
/// value x whose channels have variances `var`, by the first-order
/// propagation through the display's Jacobian at x. The Jacobian's column of
/// a channel is a central difference of half-width `step` (that channel's
/// standard deviation of the box mean: a secant over the noise's own scale,
/// so that the clipping and the curve at dark values are seen as the noise
/// sees them). Channels are taken as uncorrelated; with a display that
/// encodes each channel on its own (sRGB) their correlation does not enter.
double DisplayVariance(const QualityGoal& goal, RGB x, RGB var, RGB step) {
  double sum = 0;
  for (int c = 0; c < 3; ++c) {
    if (!(var[c] > 0) || !(step[c] > 0)) continue;
    RGB up = x, down = x;
    up[c] += step[c];
    down[c] -= step[c];
    const RGB du = Display(goal, up), dd = Display(goal, down);
    for (int k = 0; k < 3; ++k) {
      const double j = (double(du[k]) - double(dd[k])) / (2.0 * double(step[c]));
      sum += j * j * double(var[c]);
    }
  }
  return sum / 3.0;
}

/// The estimate of `image` (output resolution, `outW` wide) at the validation
/// pixels.
///
/// Without variance: the mean squared display difference to the exact
/// values, i.e. against the full render. With variance (v.variance filled),
/// against the converged image: at a validation pixel whose working pixels
/// split into those the engine evaluated itself (S, `sampled`) and those it
/// interpolated (I), rec - x = sum over I of (rec_w - x_w) / n when the
/// engine kept its samples, and the interpolated values do not depend on the
/// noise of x_w (the engine never sees the validation's samples), so
///   E[(rec - x)^2] = E[(rec - truth)^2] - V_S + V_I,
/// V the display variance of the box mean's share of S or I. The estimate of
/// the error against the converged image is then d - V_I + V_S. Where every
/// working pixel is the engine's (all at 1x) rec is built from x itself: its
/// error is V_S, the noise of the sample as if kept; where the engine
/// denoised it the fit lowers that variance and d says nothing about how
/// much (it is correlated with x), so V_S is the estimate, an upper one but
/// for the fit's bias. In mixed boxes (supersampled) the interpolated pixels
/// may use the box's own samples; that covariance is left out.
PsnrEstimate EstimateAt(const Validation& v, const QualityGoal& goal, const std::vector<RGB>& image, int outW,
                        const SampledFn& sampled, int workW, int s) {
  const bool noise = !v.variance.empty();
  std::vector<double> d, w;
  d.reserve(v.pixels.size());
  w.reserve(v.pixels.size());
  for (size_t k = 0; k < v.pixels.size(); ++k) {
    const RGB x = image[size_t(v.pixels[k].y) * size_t(outW) + size_t(v.pixels[k].x)], e = v.exact[k];
    // Left out where either is not finite, as the stats' PSNR does.
    if (!IsFinite(x) || !IsFinite(e)) continue;
    const RGB dx = Display(goal, x), de = Display(goal, e);
    double sq = 0;
    for (int c = 0; c < 3; ++c) sq += (double(dx[c]) - double(de[c])) * (double(dx[c]) - double(de[c]));
    sq /= 3.0;
    if (noise) {
      RGB varS, varI;
      bool anyI = false;
      const Point2i p = v.pixels[k];
      size_t i = v.first[k];
      for (int y = p.y * s; i < v.first[k + 1] && y < (p.y + 1) * s; ++y)
        for (int xw = p.x * s; i < v.first[k + 1] && xw < (p.x + 1) * s; ++xw, ++i) {
          if (sampled(size_t(y) * size_t(workW) + size_t(xw))) {
            varS += v.variance[i];
          } else {
            varI += v.variance[i];
            anyI = true;
          }
        }
      if (!IsFinite(varS + varI)) continue;
      const RGB step = StdDev(varS + varI);
      const double vs = DisplayVariance(goal, e, varS, step);
      sq = anyI ? sq - DisplayVariance(goal, e, varI, step) + vs : vs;
    }
    d.push_back(sq);
    w.push_back(v.weights[k]);
  }
  return EstimatePsnr(d, w, v.importance ? v.total : 0);
}

/// The full render's own estimate against the converged image: at each
/// validation pixel, its exact value is the full render's, and its error is
/// the display variance of the box mean. NaN without variance.
PsnrEstimate RenderEstimate(const Validation& v, const QualityGoal& goal) {
  if (v.variance.empty()) return {kNaN, kNaN, kNaN};
  std::vector<double> d, w;
  for (size_t k = 0; k < v.pixels.size(); ++k) {
    RGB var;
    for (size_t i = v.first[k]; i < v.first[k + 1]; ++i) var += v.variance[i];
    if (!IsFinite(v.exact[k]) || !IsFinite(var)) continue;
    d.push_back(DisplayVariance(goal, v.exact[k], var, StdDev(var)));
    w.push_back(v.weights[k]);
  }
  return EstimatePsnr(d, w, v.importance ? v.total : 0);
}

/// Evaluates the working pixels of the validation's output pixels through
/// `cache` and keeps their box means.
Status EvaluateValidation(CachingProvider& cache, const ReconstructionOptions& options, const SampleRequest& what,
                          const QualityGoal& goal, Validation* v, std::vector<Point2i>* pending) {
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
  if (what.variance && goal.ownVariance) {
    std::vector<RGB> variance(work.size());
    for (size_t i = 0; i < work.size(); ++i) variance[i] = samples[i].variance;
    goal.ownVariance(work, variance);
    for (size_t i = 0; i < work.size(); ++i) samples[i].variance = variance[i];
  }
  size_t k = 0;
  for (const Point2i& p : v->pixels) {
    RGB sum;
    const size_t from = k;
    for (int y = p.y * s; y < std::min(caps.height, (p.y + 1) * s); ++y)
      for (int x = p.x * s; x < std::min(caps.width, (p.x + 1) * s); ++x) sum += samples[k++].L;
    const float n = float(k - from);
    v->exact.push_back(sum * (1.f / n));
    if (what.variance) {
      if (v->first.empty()) v->first.push_back(0);
      for (size_t i = from; i < k; ++i) v->variance.push_back(samples[i].variance * (1.f / (n * n)));
      v->first.push_back(v->variance.size());
    }
  }
  return Status::Ok();
}

/// Gives the result's interpolated working pixels among `pixels` (row-major
/// working indices) that `cache` holds their exact samples, which were paid
/// for, as `why`, and their output pixels the box mean again. For noise-free
/// samples only: a noisy exact value need not be closer to the converged
/// image than the engine's denoised interpolation.
void KeepSamples(std::span<const size_t> pixels, const CachingProvider& cache, int s, SampleReason why,
                 Reconstruction* rec) {
  const int W = rec->workWidth, H = rec->workHeight;
  for (size_t k : pixels) {
    SampleReason& was = rec->sampleMap[k];
    if (HoldsExactSample(was)) continue;
    const ExactSample* e = cache.SampleAt({int(k % size_t(W)), int(k / size_t(W))});
    if (!e) continue;
    --rec->stats.byReason[size_t(was)];
    ++rec->stats.byReason[size_t(why)];
    was = why;
    rec->workImage[k] = e->L;
    if (rec->interpolation) rec->interpolation->MarkExact(int64_t(k));
    const int ox = int(k % size_t(W)) / s, oy = int(k / size_t(W)) / s;
    rec->image[size_t(oy) * size_t(rec->width) + size_t(ox)] = BoxMean(rec->workImage, W, H, s, ox, oy);
  }
}

/// The working pixels (row-major indices) of the validation's output pixels.
std::vector<size_t> WorkingPixelsOf(const Validation& v, int s, int W, int H) {
  std::vector<size_t> out;
  for (const Point2i& p : v.pixels)
    for (int wy = p.y * s; wy < std::min(H, (p.y + 1) * s); ++wy)
      for (int wx = p.x * s; wx < std::min(W, (p.x + 1) * s); ++wx) out.push_back(size_t(wy) * size_t(W) + size_t(wx));
  return out;
}

/// One finished run.
struct Run {
  Reconstruction rec;
  PsnrEstimate estimate;
  PsnrEstimate second{kNaN, kNaN, kNaN};  ///< QualityGoal::secondEstimate of the run, NaN: none
  std::vector<LevelEstimate> levels;
  double threshold = 0;
};

}  // namespace

Status QualityGoal::Validate() const {
  if (!(targetPsnr >= 0) || targetPsnr > 99 || !std::isfinite(targetPsnr))
    return Status::Error("--target-psnr: must be in (0, 99] dB, got " + Num(targetPsnr));
  if (!(budget >= 0) || budget > 1 || !std::isfinite(budget))
    return Status::Error("--budget: must be a share of the pixels in (0, 1], got " + Num(budget));
  if (targetRender && targetPsnr > 0)
    return Status::Error("--target-psnr render: the target is the render's estimated PSNR, not also " + Num(targetPsnr) +
                         " dB");
  if (targetPsnr == 0 && !targetRender && budget == 0)
    return Status::Error("--target-psnr or --budget: neither is given");
  if (!(validationFraction > 0) || validationFraction > 1)
    return Status::Error("validationFraction: must be in (0, 1]");
  if (minValidationPixels < 2) return Status::Error("minValidationPixels: must be at least 2");
  return Status::Ok();
}

PsnrEstimate EstimatePsnr(const std::vector<double>& d, const std::vector<double>& w, double total) {
  PsnrEstimate e;
  const size_t n = std::min(d.size(), w.size());
  double W = 0, sum = 0, positive = 0, squares = 0;
  for (size_t i = 0; i < n; ++i) {
    W += w[i], sum += w[i] * d[i];
    if (d[i] > 0) positive += w[i] * d[i], squares += (w[i] * d[i]) * (w[i] * d[i]);
  }
  e.effective = squares > 0 ? positive * positive / squares : kInf;
  if (total > 0 && n >= 2) {
    // Hansen-Hurwitz: each pixel an independent estimate y = n w d / total
    // of the mean; dividing by the realized sum of weights instead (Hajek)
    // is biased where the draw follows the error: there the weights are small
    // exactly where d is large.
    const double m = sum / total;
    double var = 0;
    for (size_t i = 0; i < n; ++i) {
      const double y = double(n) * w[i] * d[i] / total;
      var += (y - m) * (y - m);
    }
    const double se = std::sqrt(var / (double(n) * double(n - 1)));
    return {PsnrOf(m), PsnrOf(std::max(0.0, m) + kZ * se), PsnrOf(std::max(0.0, m - kZ * se)), e.effective};
  }
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
  // A mean squared error is not negative: where the noise taken out of the
  // terms (a preview's) leaves a negative mean, the bound is that of 0.
  e.low = PsnrOf(std::max(0.0, m) + kZ * se);
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
  const SampleRequest what{caps.splitRadiance && options.textureSplit, caps.variance};  // the validation's too
  CachingProvider cache(provider, limit, what);
  if (goal.targetRender && !caps.variance)
    return Status::Error("--target-psnr render: the samples carry no variance (" + caps.name +
                         "), so the full render's own error is not known; give a target in dB");
  const bool hasTarget = goal.targetPsnr > 0 || goal.targetRender;

  // The validation: a share of the output pixels, at most a quarter of the budget.
  const int64_t outPixels = int64_t(outW) * int64_t(outH);
  int64_t count = std::max<int64_t>(goal.minValidationPixels, int64_t(std::ceil(goal.validationFraction * double(outPixels))));
  // Without a target the estimate is only reported: a twentieth of the budget.
  if (limit > 0)
    count = std::min(count, std::max<int64_t>(2, limit / (hasTarget ? 4 : 20) / (int64_t(s) * s)));
  count = std::min(count, outPixels);
  Validation v;
  std::vector<uint8_t> drawn(size_t(outPixels), 0);  // output pixels validated, for the cost
  int draws = 0;
  // One more draw of `count` pixels, with its own seed: stratified before
  // any run, else by importance after the error proxy of run `from`. Each
  // draw's weights sum to the pixel count (on average for importance draws):
  // the union of independent unbiased draws is unbiased.
  auto drawMore = [&](Validation* into, const Reconstruction* from) -> Status {
    Validation more;
    more.pixels = from ? DrawImportance(ErrorProxy(*from, goal, s, caps.variance), outW, count, goal.seed + uint64_t(draws),
                                        &more.weights)
                       : DrawValidation(outW, outH, count, goal.seed + uint64_t(draws), &more.weights);
    more.total = double(outPixels);
    more.importance = from != nullptr;
    DCM_RETURN_IF_ERROR(EvaluateValidation(cache, options, what, goal, &more, pending));
    ++draws;
    for (const Point2i& p : more.pixels) {
      uint8_t& mark = drawn[size_t(p.y) * size_t(outW) + size_t(p.x)];
      if (!mark) {
        const int bw = std::min(s, caps.width - p.x * s), bh = std::min(s, caps.height - p.y * s);
        report->validationExactPixels += int64_t(bw) * bh;
        ++report->validationPixels;
        mark = 1;
      }
    }
    into->AppendAll(more);
    return Status::Ok();
  };
  if (Status st = drawMore(&v, nullptr); !st.ok()) {
    if (cache.BudgetHit())
      return Status::OverBudget("--budget " + Num(goal.budget) + ": too small for the validation pixels");
    return st;
  }
  report->totalPixels = total;
  report->againstConverged = caps.variance;
  // The engine's own pixels of a finished run, and of the run under way (its levels).
  const int workW = caps.width;
  auto sampledBy = [](const Reconstruction& rec) -> SampledFn {
    return [&rec](size_t i) {
      return HoldsExactSample(rec.sampleMap[i]);
    };
  };
  const SampledFn asked = [&cache](size_t i) { return cache.EngineAsked(i); };
  // The target: given, or the full render's own PSNR against the converged image.
  double target = goal.targetPsnr;
  if (goal.targetRender) {
    const PsnrEstimate render = RenderEstimate(v, goal);
    target = std::min(99.0, render.psnr);
    if (!(target > 0))
      return Status::Error("--target-psnr render: the render's estimated PSNR is " + Num(render.psnr) + " dB");
  }
  report->targetPsnr = target;

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
        r.levels.push_back({level, EstimateAt(v, goal, image, ow, asked, workW, s)});
        options.onLevel(level, w, h, work);
      };
    }
    ++report->runs;
    cache.ClearBudgetHit();
    cache.MarkEngine(true);
    const Status st =
        goal.reconstruct ? goal.reconstruct(cache, o, &r.rec, pending) : Reconstruct(cache, o, &r.rec, pending);
    cache.MarkEngine(false);
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
    r.estimate = EstimateAt(v, goal, r.rec.image, r.rec.width, sampledBy(r.rec), workW, s);
    if (goal.secondEstimate && caps.variance) r.second = goal.secondEstimate();
    *result = std::move(r);
    return Status::Ok();
  };

  // A run that may spend the share of the budget left; one refused by the
  // share, not by the budget, runs again with all that is left: it asks for
  // the same pixels first, so nothing spent is lost.
  auto runShared = [&](double t, std::optional<Run>* into) -> Status {
    cache.SetLimit(ShareOfWhatIsLeft(cache.Distinct(), limit));
    DCM_RETURN_IF_ERROR(runAt(t, into));
    if (*into) return Status::Ok();
    cache.SetLimit(limit);
    return runAt(t, into);
  };

  const double threshold = double(ResolveSettings(options, caps).contrastThreshold);
  // Contrasts are at most 1 but for the display-weighted metric's brightest sets.
  const double t0 = limit > 0 && !goal.budgetFromThreshold ? std::min(kStartFactorBudget * threshold, 1.0)
                                                           : kStartFactor * threshold;
  auto meets = [&](const Run& r) {
    return target > 0 && r.estimate.low >= target && !(r.second.low < target);
  };

  std::optional<Run> best, tried;
  std::vector<double> lows, spends;  // per run of the descent: the lower bound, the pixels spent
  double t = t0 > 0 ? t0 : kMinThreshold;
  double lastT = 0, lastLow = kNaN, lastUsed = 0;
  std::optional<double> refused;  // the largest threshold the budget refused (-1: the full evaluation)
  for (;;) {
    // A run of the descent after the first may spend only part of what is
    // left: one the budget refuses leaves the rest to the bisection below.
    DCM_RETURN_IF_ERROR(limit > 0 && best ? runShared(t, &tried) : runAt(t, &tried));
    if (!tried) {
      refused = t;
      break;
    }
    best = std::move(tried);
    // The point estimate reaches the target but its bound does not: the
    // validation is too small for how the error is spread (a few pixels
    // carry most of it). More draws before more samples of the image.
    while (target > 0 && !meets(*best) && best->estimate.psnr >= target && draws < kMaxSearchDraws) {
      cache.ClearBudgetHit();
      if (Status st = drawMore(&v, &best->rec); !st.ok()) {
        if (cache.BudgetHit()) break;
        return st;
      }
      best->estimate = EstimateAt(v, goal, best->rec.image, best->rec.width, sampledBy(best->rec), workW, s);
    }
    const double low = best->estimate.low;
    if (meets(*best) || t < 0) break;
    // A plateau: the bound barely moved over the last two runs while the
    // samples grew. Where a few validation pixels carry the estimate, what
    // they see is error that a lower threshold does not remove (a feature the
    // lattice misses at any threshold); with noisy samples, the exact
    // samples' own noise, which more of them at the same samples per pixel
    // do not lower. The last draw then judges the result. With a budget, the
    // budget ends the descent instead: a target asked for within one spends
    // it before it says "not reached".
    lows.push_back(low);
    spends.push_back(double(cache.Distinct()));
    const size_t n = lows.size();
    if (target > 0 && limit <= 0 && n >= 3 && std::isfinite(lows[n - 3]) && lows[n - 1] - lows[n - 3] < kPlateauDb &&
        spends[n - 1] > kPlateauGrowth * spends[n - 3] &&
        (best->estimate.effective < kFewEffectivePixels || !v.variance.empty()))
      break;
    if (t <= kMinThreshold) {
      // The threshold cannot go lower: the full evaluation reaches any target.
      t = -1;
      continue;
    }
    // Secants in log threshold: of the lower bound, the step that reaches the
    // target; of the log exact pixels, the step that spends the share of the
    // budget a run may. The smaller step of the two.
    const double toTarget = target > 0 ? SecantStep(t, low, lastT, lastLow, target, kDefaultStep) : 0;
    double toBudget = 0;
    const double used = double(cache.Distinct());
    if (limit > 0) {
      // The pixels as a power of the threshold, t^-alpha: alpha from the last
      // two runs, 1 before a second (cautious: a run refused costs pixels).
      double alpha = 1;
      if (lastT > 0 && used > lastUsed)
        alpha = std::clamp((std::log(used) - std::log(lastUsed)) / (std::log(lastT) - std::log(t)), 0.2, 4.0);
      toBudget = std::pow(double(ShareOfWhatIsLeft(int64_t(used), limit)) / used, -1 / alpha);
    }
    lastT = t;
    lastLow = low;
    lastUsed = used;
    if (toBudget > kMaxStep) {
      // The budget binds before the smallest step worth a run: a step to its
      // share, or none where what is left buys almost nothing.
      if (toBudget > kLastBudgetStep) {
        report->budgetBound = true;
        break;
      }
      t *= std::min(std::max(toTarget, toBudget), kLastBudgetStep);
      continue;
    }
    t = std::max(kMinThreshold, t * std::clamp(std::max(toTarget, toBudget), kMinStep, kMaxStep));
  }
  cache.SetLimit(limit);
  if (!best) {
    // The first run did not fit: try thresholds above it (fewer edge blocks).
    for (double up = t0 * 4; !best && up <= t0 * 1024; up *= 4) {
      DCM_RETURN_IF_ERROR(runAt(up, &best));
      if (!best) refused = up;
    }
    if (!best)
      return Status::OverBudget("--budget " + Num(goal.budget) +
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
  // room). A fresh draw, which chose nothing, estimates the result, drawn by
  // importance where the result's error is likely (ErrorProxy). Where it
  // finds the target missed although the search's pixels met it, the descent
  // goes on, each result confirmed by a draw of its own (the draws before
  // join the search's pixels), by secants of the confirming draws' lower
  // bounds. Without a budget a few steps; with one, until it binds: a target
  // asked for within a budget spends the budget before it says "not reached".
  const bool searchMet = meets(*best);
  double confirmedT = 0, confirmedLow = kNaN;
  for (int confirmation = 0; target > 0 && best->threshold >= 0; ++confirmation) {
    Validation fresh;
    cache.ClearBudgetHit();
    if (Status st = drawMore(&fresh, &best->rec); !st.ok()) {
      if (!cache.BudgetHit()) return st;
      break;
    }
    best->estimate = EstimateAt(fresh, goal, best->rec.image, best->rec.width, sampledBy(best->rec), workW, s);
    report->confirmed = true;
    v.AppendAll(fresh);
    if (meets(*best) || !searchMet || (limit <= 0 && confirmation + 1 >= kMaxConfirmations)) break;
    const double low = best->estimate.low;
    const double step =
        std::clamp(SecantStep(best->threshold, low, confirmedT, confirmedLow, target, kDefaultStep), kMinStep, kMaxStep);
    confirmedT = best->threshold;
    confirmedLow = low;
    const double next = best->threshold <= kMinThreshold ? -1 : std::max(kMinThreshold, best->threshold * step);
    DCM_RETURN_IF_ERROR(limit > 0 ? runShared(next, &tried) : runAt(next, &tried));
    cache.SetLimit(limit);
    if (!tried) {
      report->budgetBound = true;
      break;
    }
    best = std::move(tried);
    report->confirmed = false;
  }
  // The render's own error does not depend on the search: every draw counts.
  report->renderEstimate = RenderEstimate(v, goal);
  report->validationEstimate = best->estimate;
  report->secondEstimate = best->second;
  // The more pessimistic judge speaks: a few validation pixels miss error
  // that a few pixels carry (where they see none beyond the noise, their
  // estimate is +inf), the preview's estimate misses error its noise hides.
  const bool secondLower = !std::isnan(best->second.low) && best->second.psnr < best->estimate.psnr;
  report->estimate = secondLower ? best->second : best->estimate;
  report->estimateSource = secondLower ? EstimateSource::kPreview : EstimateSource::kValidation;
  report->levels = std::move(best->levels);
  report->threshold = best->threshold;
  report->targetReached = target <= 0 || meets(*best);
  report->exactPixels = cache.Distinct();
  // Noise-free, every pixel the search paid for holds the full render's value
  // and is kept where the result interpolated it: the validation's, then
  // (exact by now, those are passed over) those of runs the result did not
  // come from (one the budget refused, a coarser one). The estimate stays
  // that of the result the search judged (it reads the validation pixels
  // alone): conservative by the error they remove.
  if (v.variance.empty()) {
    KeepSamples(WorkingPixelsOf(v, s, best->rec.workWidth, best->rec.workHeight), cache, s,
                SampleReason::kValidation, &best->rec);
    KeepSamples(cache.Evaluated(), cache, s, SampleReason::kRendered, &best->rec);
  }
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
