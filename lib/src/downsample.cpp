#include "dcm/downsample.h"

#include <tbb/parallel_for.h>

#include <algorithm>

namespace dcm {

RGB BoxMean(std::span<const RGB> in, int w, int h, int s, int ox, int oy) {
  s = std::max(s, 1);
  double acc[3] = {0, 0, 0};
  int n = 0;
  for (int y = oy * s; y < std::min(h, oy * s + s); ++y)
    for (int x = ox * s; x < std::min(w, ox * s + s); ++x, ++n) {
      const RGB& c = in[size_t(y) * size_t(w) + size_t(x)];
      acc[0] += c.r, acc[1] += c.g, acc[2] += c.b;
    }
  return RGB(float(acc[0] / n), float(acc[1] / n), float(acc[2] / n));
}

std::vector<RGB> BoxDownsample(std::span<const RGB> in, int w, int h, int s, int* outW, int* outH) {
  s = std::max(s, 1);
  *outW = (w + s - 1) / s;
  *outH = (h + s - 1) / s;
  if (in.size() < size_t(w) * size_t(h)) return std::vector<RGB>(size_t(*outW) * size_t(*outH));
  if (s == 1) return std::vector<RGB>(in.begin(), in.begin() + ptrdiff_t(size_t(w) * size_t(h)));
  std::vector<RGB> out(size_t(*outW) * size_t(*outH));
  const int ow = *outW;
  tbb::parallel_for(0, *outH, [&](int oy) {
    for (int ox = 0; ox < ow; ++ox) out[size_t(oy) * size_t(ow) + size_t(ox)] = BoxMean(in, w, h, s, ox, oy);
  });
  return out;
}

}  // namespace dcm
