// Preview pooling: exact pixels take their independent preview samples in
// (lib/include/dcm/preview_pooling.h).
#include "dcm/preview_pooling.h"

#include <cmath>
#include <new>
#include <string>
#include <vector>

#include "dcm/downsample.h"

namespace dcm {

double PreviewPoolWeight(double exactShare) {
  return exactShare > 0 && std::isfinite(exactShare) ? exactShare / (1 + exactShare) : 0.0;
}

Status PoolExactWithPreview(SampleProvider& preview, double exactShare, int downsample, Reconstruction* rec,
                            int64_t* pooled) {
  if (pooled) *pooled = 0;
  if (downsample < 1) return Status::Error("preview pooling: downsample " + std::to_string(downsample) + " is below 1");
  const double w = PreviewPoolWeight(exactShare);
  if (!(w > 0)) return Status::Ok();
  const int W = rec->workWidth, H = rec->workHeight;
  const size_t n = size_t(W) * size_t(H);
  if (rec->workImage.size() != n || rec->sampleMap.size() != n)
    return Status::Error("preview pooling: the reconstruction has no working image");
  const ProviderCapabilities caps = preview.Capabilities();
  if (caps.width != W || caps.height != H)
    return Status::Error("preview pooling: the preview is " + std::to_string(caps.width) + "x" +
                         std::to_string(caps.height) + ", the working image " + std::to_string(W) + "x" +
                         std::to_string(H));
  try {
    std::vector<Point2i> exact;
    for (size_t i = 0; i < n; ++i)
      if (HoldsExactSample(rec->sampleMap[i])) exact.push_back({int(i % size_t(W)), int(i / size_t(W))});
    if (exact.empty()) return Status::Ok();
    std::vector<ExactSample> p(exact.size());
    if (Status s = preview.Evaluate(exact, SampleRequest{}, p); !s.ok())
      return Status::Error("preview pooling: " + s.message());
    int64_t moved = 0;
    for (size_t k = 0; k < exact.size(); ++k) {
      RGB& x = rec->workImage[size_t(exact[k].y) * size_t(W) + size_t(exact[k].x)];
      if (!IsFinite(x) || !IsFinite(p[k].L)) continue;
      for (int c = 0; c < 3; ++c) x[c] = float((1 - w) * double(x[c]) + w * double(p[k].L[c]));
      ++moved;
    }
    rec->image = BoxDownsample(rec->workImage, W, H, downsample, &rec->width, &rec->height);
    if (pooled) *pooled = moved;
  } catch (const std::bad_alloc&) {
    return Status::Error("out of memory in the preview pooling");
  }
  return Status::Ok();
}

}  // namespace dcm
