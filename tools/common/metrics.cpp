// Error metrics of an image against a reference.
#include "metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace dcm::toolkit {


namespace {

/// SSIM (Wang et al. 2004, constants K1 = 0.01, K2 = 0.03, dynamic range 1) of
/// two gray images, averaged over every w x w window (stride 1, w = 8 or the
/// image size when smaller), computed with summed-area tables.
double MeanSsim(const std::vector<double>& a, const std::vector<double>& b, int width, int height) {
  const int wx = std::min(8, width), wy = std::min(8, height);
  const size_t W = size_t(width) + 1;
  // Summed-area tables of a, b, a^2, b^2, ab.
  std::vector<double> sa(W * size_t(height + 1)), sb(sa.size()), saa(sa.size()), sbb(sa.size()),
      sab(sa.size());
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const size_t i = size_t(y) * size_t(width) + size_t(x);
      const size_t o = size_t(y + 1) * W + size_t(x + 1);
      const size_t up = size_t(y) * W + size_t(x + 1), left = o - 1, diag = up - 1;
      const double va = a[i], vb = b[i];
      sa[o] = va + sa[up] + sa[left] - sa[diag];
      sb[o] = vb + sb[up] + sb[left] - sb[diag];
      saa[o] = va * va + saa[up] + saa[left] - saa[diag];
      sbb[o] = vb * vb + sbb[up] + sbb[left] - sbb[diag];
      sab[o] = va * vb + sab[up] + sab[left] - sab[diag];
    }
  }
  auto box = [&](const std::vector<double>& s, int x, int y) {
    const size_t x0 = size_t(x), y0 = size_t(y), x1 = x0 + size_t(wx), y1 = y0 + size_t(wy);
    return s[y1 * W + x1] - s[y0 * W + x1] - s[y1 * W + x0] + s[y0 * W + x0];
  };
  const double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03, n = double(wx) * double(wy);
  double sum = 0;
  long count = 0;
  for (int y = 0; y + wy <= height; ++y) {
    for (int x = 0; x + wx <= width; ++x) {
      const double ma = box(sa, x, y) / n, mb = box(sb, x, y) / n;
      const double va = std::max(0.0, box(saa, x, y) / n - ma * ma);
      const double vb = std::max(0.0, box(sbb, x, y) / n - mb * mb);
      const double cov = box(sab, x, y) / n - ma * mb;
      sum += ((2 * ma * mb + c1) * (2 * cov + c2)) / ((ma * ma + mb * mb + c1) * (va + vb + c2));
      ++count;
    }
  }
  return count ? sum / double(count) : 1.0;
}

}  // namespace

ImageError Compare(std::span<const RGB> image, std::span<const RGB> reference, int width, int height) {
  ImageError e;
  const size_t n = size_t(std::max(width, 0)) * size_t(std::max(height, 0));
  if (n == 0 || image.size() < n || reference.size() < n) {
    e.psnr = e.rmse = e.relmse = std::numeric_limits<double>::quiet_NaN();
    e.ssim = std::numeric_limits<double>::quiet_NaN();
    return e;
  }
  double sqDisplay = 0, sqLinear = 0, rel = 0;
  long used = 0;
  std::vector<double> ya(n), yb(n);
  for (size_t i = 0; i < n; ++i) {
    const RGB x = image[i], r = reference[i];
    const bool fx = IsFinite(x), fr = IsFinite(r);
    if (!fx) ++e.nonFinite;
    // Non-finite pixels count as black in the SSIM luminance images.
    ya[i] = fx ? SrgbEncode(Luminance(x)) : 0.0;
    yb[i] = fr ? SrgbEncode(Luminance(r)) : 0.0;
    if (!fx || !fr) continue;
    ++used;
    for (int c = 0; c < 3; ++c) {
      const double dd = double(SrgbEncode(x[c])) - double(SrgbEncode(r[c]));
      const double dl = double(x[c]) - double(r[c]);
      sqDisplay += dd * dd;
      sqLinear += dl * dl;
      rel += dl * dl / (double(r[c]) * double(r[c]) + 0.01);
    }
  }
  if (used == 0) {
    e.psnr = e.rmse = e.relmse = std::numeric_limits<double>::quiet_NaN();
  } else {
    const double m = 3.0 * double(used);
    const double mse = sqDisplay / m;
    e.psnr = mse > 0 ? 10.0 * std::log10(1.0 / mse) : std::numeric_limits<double>::infinity();
    e.rmse = std::sqrt(sqLinear / m);
    e.relmse = rel / m;
  }
  e.ssim = MeanSsim(ya, yb, width, height);
  return e;
}

}  // namespace dcm::toolkit
