// Preview correction: a local Wiener shrinkage of the interpolation toward a
// noisy, unbiased preview (lib/include/dcm/preview_correction.h).
#include "dcm/preview_correction.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <new>
#include <string>
#include <vector>

#include "dcm/downsample.h"
#include "dcm/preview_filter.h"
#include "dcm/preview_pooling.h"

namespace dcm {

namespace {

/// The excess e = d^2 - v, averaged over a window, counts as bias where it
/// stands this many standard errors above 0 (its sd measured in the window:
/// a path tracer's noise is heavy-tailed, and one bright outlier is not a
/// bias of its window); below it, a weight would only let the noise in.
constexpr double kSignificance = 1.5;

/// Where the preview's variance is measured on its own halves (each pixel's
/// own is given), an interpolated pixel takes the share k of its difference d
/// (none, the Wiener share or all) whose cross-fit error between the halves,
/// (1 - k)^2 d^2 + (1 + k)^2 v per channel (v the preview's variance), summed
/// over this window, is least: the 11 x 11 mean dilutes a bias that a few
/// pixels carry (a texture's lines, a lost dot) and lets the noise in beside
/// one that stops. An assumed variance does not show a firefly, which would
/// pass for such a bias. Chosen on the tuning set (docs/TUNING.md).
constexpr int kChoiceRadius = 3;

/// An interpolated pixel with a filtered preview (FilterPreview) ends as the
/// mean of its corrected value and that: each misses what the other keeps
/// (the corrected value the preview's noise, the filter what its weights cut
/// across). Chosen on the tuning set (docs/TUNING.md).
constexpr double kFilterShare = 0.5;

/// Sums of `v` (W x H) over the window of radius r around each pixel,
/// clipped to the grid: a horizontal then a vertical pass, each summed
/// afresh per pixel. Running sums would subtract: after one outlier (a
/// firefly's d^4 can reach 1e12) the small windows behind it lose their digits.
std::vector<double> WindowSums(const std::vector<double>& v, int W, int H, int r) {
  std::vector<double> rows(v.size()), out(v.size());
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      double s = 0;
      for (int i = std::max(x - r, 0); i <= std::min(x + r, W - 1); ++i) s += v[size_t(y) * size_t(W) + size_t(i)];
      rows[size_t(y) * size_t(W) + size_t(x)] = s;
    }
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      double s = 0;
      for (int j = std::max(y - r, 0); j <= std::min(y + r, H - 1); ++j) s += rows[size_t(j) * size_t(W) + size_t(x)];
      out[size_t(y) * size_t(W) + size_t(x)] = s;
    }
  return out;
}

/// The expected squared sRGB error against the truth of x + k (p - x) for a
/// preview p whose two halves are p + s and p - s (s^2 = v, the variance of
/// their mean: (A - B)^2 / 4 for equal halves A, B): with A, B, X the
/// encodings, E[(X - A)(X - B)] = (X - E A)(X - E B) where x does not depend
/// on their noise, plus k^2 the display variance of p, (A - B)^2 / 4.
/// Where x moves with the halves' noise (x = L_i tau + L_c with the preview's
/// own tau: `cov`, the covariance of x and p, is L_i cov(tau, L)), x_A, x_B =
/// x + D, x - D are x made with each half's tau (D = cov / s, the
/// half-difference that goes with +s), and the cross-fit
/// 1/2 [(X_A - B)^2 + (X_B - A)^2] - (A - B)^2 / 2 - (X_A - X_B)^2 / 4 is
/// unbiased instead (it is the product above at D = 0); x + k (p - x) adds
/// 2 k (1 - k) times that covariance, (X_A - X_B)(A - B) / 4.
/// Negative values are part of an unbiased sum.
double DisplayError(float p, double v, float x, double k, double cov = 0) {
  const double s = std::sqrt(std::max(v, 0.0));
  const double D = s > 0 && std::isfinite(cov) ? cov / s : 0.0;
  const double A = SrgbEncode(float(p + s)), B = SrgbEncode(float(p - s));
  const double XA = SrgbEncode(float(x + D)), XB = SrgbEncode(float(x - D));
  const double cross = ((XA - B) * (XA - B) + (XB - A) * (XB - A)) / 2 - (A - B) * (A - B) / 2 - (XA - XB) * (XA - XB) / 4;
  return (1 - k) * (1 - k) * cross + k * k * (A - B) * (A - B) / 4 + k * (1 - k) * (XA - XB) * (A - B) / 2;
}

/// The preview's display variance at a pixel (a mean over the channels) of
/// value L and own variance v.
double DisplayNoise(const RGB& L, const RGB& v) {
  double noise = 0;
  for (int c = 0; c < 3; ++c) noise += DisplayError(L[c], std::max(double(v[c]), 0.0), L[c], 1.0) / 3;
  return noise;
}

bool Usable(const ExactSample& p, const RGB& v) {
  return IsFinite(p.L) && IsFinite(v) && v.r >= 0 && v.g >= 0 && v.b >= 0;
}

}  // namespace

double PreviewNoisePsnr(SampleProvider& preview, std::span<const RGB> ownVariance) {
  const ProviderCapabilities caps = preview.Capabilities();
  const size_t n = size_t(std::max(caps.width, 0)) * size_t(std::max(caps.height, 0));
  if (n == 0 || !caps.variance || (!ownVariance.empty() && ownVariance.size() != n))
    return std::numeric_limits<double>::quiet_NaN();
  std::vector<Point2i> all(n);
  for (int y = 0; y < caps.height; ++y)
    for (int x = 0; x < caps.width; ++x) all[size_t(y) * size_t(caps.width) + size_t(x)] = {x, y};
  std::vector<ExactSample> p(n);
  if (!preview.Evaluate(all, SampleRequest{false, true}, p).ok()) return std::numeric_limits<double>::quiet_NaN();
  double noiseSum = 0;
  for (size_t i = 0; i < n; ++i) {
    const RGB& v = ownVariance.empty() ? p[i].variance : ownVariance[i];
    if (Usable(p[i], p[i].variance)) noiseSum += DisplayNoise(p[i].L, v);
  }
  return 10 * std::log10(double(n) / std::max(noiseSum, 1e-30));
}

Status CorrectTowardPreview(SampleProvider& preview, int radius, int downsample, Reconstruction* rec,
                            PreviewCorrectionStats* stats, std::span<const RGB> ownVariance, double exactShare,
                            std::span<const RGB> textureCovariance, int filterRadius, const GuideImage& guides,
                            std::vector<float>* excess, bool exactPooled) {
  if (radius < 0) return Status::Error("preview correction: radius " + std::to_string(radius) + " is negative");
  if (filterRadius < 0)
    return Status::Error("preview correction: filter radius " + std::to_string(filterRadius) + " is negative");
  if (downsample < 1)
    return Status::Error("preview correction: downsample " + std::to_string(downsample) + " is below 1");
  PreviewCorrectionStats result;
  if (stats) *stats = result;
  if (radius == 0) return Status::Ok();
  const int W = rec->workWidth, H = rec->workHeight;
  const size_t n = size_t(W) * size_t(H);
  if (rec->workImage.size() != n || rec->sampleMap.size() != n)
    return Status::Error("preview correction: the reconstruction has no working image");
  const ProviderCapabilities caps = preview.Capabilities();
  if (caps.width != W || caps.height != H)
    return Status::Error("preview correction: the preview is " + std::to_string(caps.width) + "x" +
                         std::to_string(caps.height) + ", the working image " + std::to_string(W) + "x" +
                         std::to_string(H));
  if (!caps.variance) return Status::Error("preview correction: the preview has no variance");
  if (!ownVariance.empty() && ownVariance.size() != n)
    return Status::Error("preview correction: " + std::to_string(ownVariance.size()) +
                         " own variances for " + std::to_string(n) + " working pixels");
  if (!textureCovariance.empty() && textureCovariance.size() != n)
    return Status::Error("preview correction: " + std::to_string(textureCovariance.size()) +
                         " texture covariances for " + std::to_string(n) + " working pixels");
  // D = L_i dtau needs the preview's L_i (the interpolation's own is not kept;
  // the preview's is as good an estimate of it for D, a small term).
  const bool shared = !textureCovariance.empty() && caps.splitRadiance;
  try {
    std::vector<Point2i> all(n);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) all[size_t(y) * size_t(W) + size_t(x)] = {x, y};
    std::vector<ExactSample> p(n);
    // The filter averages L_i and L_c apart where it has the texture guide.
    const bool split = caps.splitRadiance && (shared || (filterRadius > 0 && !guides.texture.empty()));
    if (Status s = preview.Evaluate(all, SampleRequest{split, true}, p); !s.ok())
      return Status::Error("preview correction: " + s.message());
    const bool apart = split && !guides.texture.empty();  // as FilterPreview averages

    std::vector<uint8_t> usable(n);
    for (size_t i = 0; i < n; ++i) usable[i] = Usable(p[i], p[i].variance) && IsFinite(rec->workImage[i]);
    std::vector<double> count(n);
    for (size_t i = 0; i < n; ++i) count[i] = usable[i];
    const std::vector<double> counts = WindowSums(count, W, H, radius);
    count = {};

    std::vector<RGB> corrected = rec->workImage;
    std::vector<uint8_t> moved(n, 0);
    double weightSum = 0;
    int64_t interpolated = 0;
    for (size_t i = 0; i < n; ++i) interpolated += rec->sampleMap[i] == SampleReason::kInterpolated;
    std::vector<double> e(n), e2(n), v(n);
    auto own = [&](size_t i, int c) {
      return ownVariance.empty() ? double(p[i].variance[c]) : double(ownVariance[i][c]);
    };
    // The Wiener share of each interpolated pixel and channel.
    std::vector<float> wiener(3 * n, 0.0f);
    for (int c = 0; c < 3; ++c) {
      // Linear: a noisy preview's mean is the truth there, not after the display's clip and curve.
      for (size_t i = 0; i < n; ++i) {
        const double d = usable[i] ? double(p[i].L[c]) - double(rec->workImage[i][c]) : 0.0;
        v[i] = usable[i] ? double(p[i].variance[c]) : 0.0;
        // Where the run's own exact sample stands, d carries its noise too (the
        // preview renders with seeds of its own); a pixel rendered but
        // interpolated by the run holds its interpolated value until Finish.
        const SampleReason r = rec->sampleMap[i];
        const bool exact = r != SampleReason::kInterpolated && r != SampleReason::kRendered &&
                           r != SampleReason::kPreviewStandIn;
        e[i] = d * d - v[i] * (exact ? 1 + exactShare : 1.0);
        e2[i] = e[i] * e[i];
      }
      const std::vector<double> se = WindowSums(e, W, H, radius), se2 = WindowSums(e2, W, H, radius),
                                sv = WindowSums(v, W, H, radius);
      for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
          const size_t i = size_t(y) * size_t(W) + size_t(x);
          if (rec->sampleMap[i] != SampleReason::kInterpolated || !usable[i]) continue;
          const double m = counts[i];  // >= 1: this pixel is usable
          const double meanV = sv[i] / m;
          const double bias2 = se[i] / m;
          const double sdE = std::sqrt(std::max(se2[i] / m - bias2 * bias2, 0.0));
          if (bias2 > 0 && bias2 > kSignificance * sdE / std::sqrt(m)) wiener[3 * i + size_t(c)] = float(bias2 / (bias2 + meanV));
        }
    }
    e = {};
    e2 = {};
    v = {};
    // Which share each pixel takes: 0 the Wiener share, 1 none, 2 all.
    std::vector<uint8_t> choice(n, 0);
    if (!ownVariance.empty()) {
      std::vector<double> best(n, std::numeric_limits<double>::infinity()), fit(n);
      for (uint8_t j = 0; j < 3; ++j) {
        for (size_t i = 0; i < n; ++i) {
          fit[i] = 0;
          if (!usable[i]) continue;
          for (int c = 0; c < 3; ++c) {
            const double k = j == 0 ? double(wiener[3 * i + size_t(c)]) : j == 1 ? 0.0 : 1.0;
            const double d = double(p[i].L[c]) - double(rec->workImage[i][c]);
            fit[i] += (1 - k) * (1 - k) * d * d + (1 + k) * (1 + k) * double(p[i].variance[c]);
          }
        }
        const std::vector<double> sums = WindowSums(fit, W, H, kChoiceRadius);
        for (size_t i = 0; i < n; ++i)
          if (sums[i] < best[i]) best[i] = sums[i], choice[i] = j;
      }
    }
    // The share of its difference each interpolated pixel and channel takes.
    std::vector<float> share(3 * n, 0.0f);
    for (size_t i = 0; i < n; ++i) {
      if (rec->sampleMap[i] != SampleReason::kInterpolated || !usable[i]) continue;
      for (int c = 0; c < 3; ++c) {
        const double k = choice[i] == 0 ? double(wiener[3 * i + size_t(c)]) : choice[i] == 1 ? 0.0 : 1.0;
        share[3 * i + size_t(c)] = float(k);
        if (k <= 0) continue;
        corrected[i][c] = float(double(rec->workImage[i][c]) + k * (double(p[i].L[c]) - double(rec->workImage[i][c])));
        moved[i] = 1;
        weightSum += k;
      }
    }
    // The filtered preview, its pilot the corrected image (which carries the
    // edges the correction found); it leaves each pixel's own preview out.
    // The centre's pilot moves with its own preview by k s (s the preview's
    // sd): the filtered value made with each half's pilot, for the estimate.
    FilteredPreview filtered;
    if (filterRadius > 0) {
      std::vector<RGB> shift(n);
      for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c)
          shift[i][c] = float(double(share[3 * i + size_t(c)]) * std::sqrt(std::max(own(i, c), 0.0)));
      DCM_RETURN_IF_ERROR(FilterPreview(p, split, guides, corrected, shift, rec->sampleMap, W, H, filterRadius,
                                        &filtered));
    }
    // Per pixel, the estimated squared display error of the result (a sum over channels).
    std::vector<double> error(downsample == 1 ? n : 0, 0.0);
    for (size_t i = 0; i < n; ++i) {
      if (rec->sampleMap[i] != SampleReason::kInterpolated || !usable[i]) continue;
      const bool mixed = !filtered.value.empty() && IsFinite(filtered.value[i]);
      const bool moves = mixed && IsFinite(filtered.plus[i]) && IsFinite(filtered.minus[i]);
      result.filtered += mixed;
      for (int c = 0; c < 3; ++c) {
        // (1 - s) (x + k (p - x)) + s f, with f the filtered value and s its
        // share, is x' + k' (p - x') with k' = (1 - s) k and x' = ((1 - s)
        // (1 - k) x + s f) / (1 - k'), the form the estimate takes; f moves
        // with p's noise through its pilot by (f+ - f-) / 2 per sd of p.
        const double x = rec->workImage[i][c], k = share[3 * i + size_t(c)], s = mixed ? kFilterShare : 0.0;
        const double kk = (1 - s) * k;
        const double xx = mixed ? ((1 - s) * (1 - k) * x + s * double(filtered.value[i][c])) / (1 - kk) : x;
        // What of x' carries this pixel's own tau, and with it the preview's
        // noise: x, and f where it multiplies back averaged L_i by that tau
        // (then all of x': (1 - s) (1 - k) + s = 1 - k').
        const double ofTau = mixed && !apart ? (1 - s) * (1 - k) / (1 - kk) : 1.0;
        if (mixed) corrected[i][c] = float(xx + kk * (double(p[i].L[c]) - xx)), moved[i] = 1;
        if (error.empty()) continue;
        double cov = shared ? ofTau * double(p[i].Li[c]) * double(textureCovariance[i][c]) : 0.0;
        if (moves)
          cov += std::sqrt(std::max(own(i, c), 0.0)) * s *
                 (double(filtered.plus[i][c]) - double(filtered.minus[i][c])) / 2 / (1 - kk);
        error[i] += DisplayError(p[i].L[c], own(i, c), float(xx), kk, cov);
      }
    }
    if (!error.empty()) {
      // A stand-in keeps the preview's value, so its error is the preview's
      // noise; an exact pixel's is its own: the exact share of the preview's
      // variance (pooled: the pooled share), taken through the display at the
      // pixel's value in the result (the interpolated one where the round's
      // value is filled in later: as good for the slope). A share of the
      // preview's display variance would understate it where the preview's
      // far larger noise meets the curve's bend and clip.
      std::vector<double> d;
      d.reserve(n);
      std::vector<double> over(excess ? n : 0), noises(excess ? n : 0);
      double noiseSum = 0, renderSum = 0;
      const float pooledShare = float(PreviewPoolWeight(exactShare));
      for (size_t i = 0; i < n; ++i) {
        const RGB& pv = ownVariance.empty() ? p[i].variance : ownVariance[i];
        const double noise = usable[i] ? DisplayNoise(p[i].L, pv) : 0.0;
        const bool finite = usable[i] && IsFinite(corrected[i]);
        const double renderNoise = finite ? DisplayNoise(corrected[i], pv * float(exactShare)) : 0.0;
        const double ownNoise = exactPooled && finite ? DisplayNoise(corrected[i], pv * pooledShare) : renderNoise;
        noiseSum += noise;
        renderSum += renderNoise;
        const SampleReason r = rec->sampleMap[i];
        if (r == SampleReason::kPreviewStandIn) d.push_back(noise);
        else if (r != SampleReason::kInterpolated) d.push_back(ownNoise);
        else if (usable[i]) d.push_back(error[i] / 3);
        if (excess) {
          noises[i] = noise;
          over[i] = r == SampleReason::kInterpolated && usable[i] ? error[i] / 3 - ownNoise
                                                                   : std::numeric_limits<double>::quiet_NaN();
        }
      }
      if (excess) {
        // One pixel's variance from its two halves has one degree of freedom:
        // the noise is pooled over the pixel's 5 x 5 neighbours, and never
        // below the image's mean (where the preview has no noise, a clear
        // sky, any error would stand out of none).
        const std::vector<double> pooled = WindowSums(noises, W, H, 2),
                                  ones = WindowSums(std::vector<double>(n, 1.0), W, H, 2);
        const double floor = noiseSum / double(n);
        excess->assign(n, std::numeric_limits<float>::quiet_NaN());
        for (size_t i = 0; i < n; ++i) {
          const double scale = std::max(pooled[i] / ones[i], floor);
          if (std::isfinite(over[i]) && scale > 0) (*excess)[i] = float(over[i] / scale);
        }
      }
      result.previewPsnr = 10 * std::log10(double(n) / std::max(noiseSum, 1e-30));
      if (exactShare > 0) result.renderPsnr = 10 * std::log10(double(n) / std::max(renderSum, 1e-30));
      if (result.previewPsnr >= kMinPreviewPsnrForEstimate) result.estimate = EstimatePsnr(d, std::vector<double>(d.size(), 1.0));
    }
    rec->workImage = std::move(corrected);
    rec->image = BoxDownsample(rec->workImage, W, H, downsample, &rec->width, &rec->height);
    for (uint8_t m : moved) result.pixels += m;
    result.meanWeight = interpolated > 0 ? weightSum / (3.0 * double(interpolated)) : 0.0;
  } catch (const std::bad_alloc&) {
    return Status::Error("out of memory in the preview correction");
  }
  if (stats) *stats = result;
  return Status::Ok();
}

}  // namespace dcm
