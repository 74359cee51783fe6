// Preview filter: a leave-one-out cross-bilateral mean of the preview around
// each interpolated pixel (lib/include/dcm/preview_filter.h).
#include "dcm/preview_filter.h"

#include <cmath>
#include <limits>
#include <new>
#include <string>

#include <tbb/parallel_for.h>

#include "dcm/color.h"

namespace dcm {

namespace {

// The widths of the weights, chosen on the tuning set (docs/TUNING.md): a
// step of one width (a crease of about 12 degrees, an albedo or a display
// step of 0.05) keeps exp(-1/2) = 0.61 of a neighbour's weight.
constexpr double kNormalSd = 0.2;
constexpr double kTextureSd = 0.05;
constexpr double kPilotSd = 0.05;

/// Below this total weight a pixel has no neighbour like it: a thin line or a
/// lone dot, which the filter would blur into its surroundings.
constexpr double kMinTotalWeight = 1e-3;

}  // namespace

Status FilterPreview(std::span<const ExactSample> preview, bool split, const GuideImage& guides,
                     std::span<const RGB> pilot, std::span<const RGB> centreShift,
                     std::span<const SampleReason> sampleMap, int W, int H, int radius, FilteredPreview* out) {
  if (W < 0 || H < 0 || radius < 0)
    return Status::Error("preview filter: a " + std::to_string(W) + "x" + std::to_string(H) + " image, radius " +
                         std::to_string(radius));
  const size_t n = size_t(W) * size_t(H);
  if (preview.size() != n || pilot.size() != n || sampleMap.size() != n ||
      (!centreShift.empty() && centreShift.size() != n))
    return Status::Error("preview filter: " + std::to_string(preview.size()) + " preview, " +
                         std::to_string(pilot.size()) + " pilot, " + std::to_string(centreShift.size()) +
                         " shift and " + std::to_string(sampleMap.size()) + " sample-map values for " +
                         std::to_string(n) + " pixels");
  auto sized = [n](size_t s) { return s == 0 || s == n; };
  if (!sized(guides.objectId.size()) || !sized(guides.shaderId.size()) || !sized(guides.texture.size()) ||
      !sized(guides.normal.size()))
    return Status::Error("preview filter: the guides do not cover the " + std::to_string(W) + "x" +
                         std::to_string(H) + " image");
  const bool apart = split && !guides.texture.empty();
  try {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const bool shifted = !centreShift.empty();
    out->value.assign(n, RGB(nan, nan, nan));
    out->plus.assign(shifted ? n : 0, RGB(nan, nan, nan));
    out->minus.assign(shifted ? n : 0, RGB(nan, nan, nan));
    std::vector<RGB> encoded(n);
    std::vector<uint8_t> usable(n);
    for (size_t i = 0; i < n; ++i) {
      usable[i] = IsFinite(preview[i].L) && IsFinite(pilot[i]) &&
                  (!apart || (IsFinite(preview[i].Li) && IsFinite(preview[i].Lc) && IsFinite(guides.texture[i])));
      for (int c = 0; c < 3; ++c) encoded[i][c] = SrgbEncode(pilot[i][c]);
    }
    std::vector<Vec3f> normal(guides.normal.size());
    for (size_t i = 0; i < normal.size(); ++i) {
      const Vec3f& v = guides.normal[i];
      const float len = std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
      if (len > 0 && std::isfinite(len)) normal[i] = {v.x / len, v.y / len, v.z / len};
    }
    auto squared = [](const RGB& a, const RGB& b) {
      const RGB d = a - b;
      return double(d.r) * d.r + double(d.g) * d.g + double(d.b) * d.b;
    };
    // Per centre pilot (as it is, moved by +shift, by -shift): the total
    // weight and the weighted sums of L, or of L_i and L_c.
    struct Sums {
      double total = 0, a[3] = {0, 0, 0}, b[3] = {0, 0, 0};
    };
    // Rows apart: each pixel's value is its own (no sums carried between them).
    tbb::parallel_for(0, H, [&](int y) {
      for (int x = 0; x < W; ++x) {
        const size_t i = size_t(y) * size_t(W) + size_t(x);
        if (sampleMap[i] != SampleReason::kInterpolated || !usable[i]) continue;
        // Variant 0: the pilot as it is; 1 and 2: its centre moved by + and -
        // its shift in all channels at once (a path tracer's noise is mostly
        // of the path's throughput, the same sign in R, G and B). No shift:
        // the variants are the value.
        const bool moves = shifted && !(centreShift[i] == RGB());
        const int variants = moves ? 3 : 1;
        RGB centre[3] = {encoded[i], encoded[i], encoded[i]};
        for (int v = 1; v < variants; ++v)
          for (int c = 0; c < 3; ++c)
            centre[v][c] = SrgbEncode(pilot[i][c] + (v == 1 ? 1.0f : -1.0f) * centreShift[i][c]);
        Sums sums[3];
        for (int yy = std::max(y - radius, 0); yy <= std::min(y + radius, H - 1); ++yy)
          for (int xx = std::max(x - radius, 0); xx <= std::min(x + radius, W - 1); ++xx) {
            const size_t j = size_t(yy) * size_t(W) + size_t(xx);
            if (j == i || !usable[j]) continue;
            if (!guides.objectId.empty() && guides.objectId[j] != guides.objectId[i]) continue;
            if (!guides.shaderId.empty() && guides.shaderId[j] != guides.shaderId[i]) continue;
            double e = 0;
            if (!normal.empty()) {
              const Vec3f a = normal[i], b = normal[j];
              const bool hasA = a.x != 0 || a.y != 0 || a.z != 0, hasB = b.x != 0 || b.y != 0 || b.z != 0;
              if (hasA != hasB) continue;
              const double dx = a.x - b.x, dy = a.y - b.y, dz = a.z - b.z;
              e += (dx * dx + dy * dy + dz * dz) / (2 * kNormalSd * kNormalSd);
            }
            if (!guides.texture.empty()) {
              const double t = squared(guides.texture[j], guides.texture[i]);
              if (!std::isfinite(t)) continue;
              e += t / (2 * kTextureSd * kTextureSd);
            }
            const ExactSample& q = preview[j];
            for (int v = 0; v < variants; ++v) {
              const double d2 = squared(encoded[j], centre[v]);
              const double w = std::exp(-e - d2 / (2 * kPilotSd * kPilotSd));
              sums[v].total += w;
              for (int c = 0; c < 3; ++c) {
                sums[v].a[c] += w * double(apart ? q.Li[c] : q.L[c]);
                if (apart) sums[v].b[c] += w * double(q.Lc[c]);
              }
            }
          }
        auto value = [&](const Sums& t, int c) {
          return float(apart ? t.a[c] / t.total * double(guides.texture[i][c]) + t.b[c] / t.total : t.a[c] / t.total);
        };
        std::vector<RGB>* dest[3] = {&out->value, &out->plus, &out->minus};
        for (int v = 0; v < variants; ++v)
          if (sums[v].total > kMinTotalWeight)
            for (int c = 0; c < 3; ++c) (*dest[v])[i][c] = value(sums[v], c);
        if (shifted && !moves) out->plus[i] = out->minus[i] = out->value[i];
      }
    });
  } catch (const std::bad_alloc&) {
    return Status::Error("out of memory in the preview filter");
  }
  return Status::Ok();
}

}  // namespace dcm
