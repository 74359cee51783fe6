// A window of a provider's working image, the window a region needs, and
// tiles of a frame.
#include "dcm/window_provider.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "dcm/downsample.h"
#include "settings.h"

namespace dcm {

namespace {

std::string Text(const Bounds2i& b) {
  return std::to_string(b.min.x) + "," + std::to_string(b.min.y) + " " + std::to_string(b.width()) + "x" +
         std::to_string(b.height());
}

/// Boundaries of `parts` intervals covering [0, extent): on multiples of
/// `align` when that leaves every interval non-empty, otherwise as even as
/// integers allow. Empty when extent < parts.
std::vector<int> Splits(int extent, int parts, int align) {
  std::vector<int> b(size_t(parts) + 1, 0);
  b[size_t(parts)] = extent;
  auto valid = [&] {
    for (int k = 0; k < parts; ++k)
      if (b[size_t(k) + 1] <= b[size_t(k)]) return false;
    return true;
  };
  if (align > 1) {
    const int64_t pa = int64_t(parts) * align;
    for (int k = 1; k < parts; ++k)
      b[size_t(k)] = int((2 * int64_t(k) * extent + pa) / (2 * pa)) * align;
    if (valid()) return b;
  }
  for (int k = 1; k < parts; ++k) b[size_t(k)] = int(int64_t(k) * extent / parts);
  if (valid()) return b;
  return {};
}

}  // namespace

WindowProvider::WindowProvider(SampleProvider& inner, const Bounds2i& window)
    : inner_(inner), window_(window), innerCaps_(inner.Capabilities()) {}

Status WindowProvider::Validate() const {
  const Bounds2i all{{0, 0}, {innerCaps_.width, innerCaps_.height}};
  if (window_.empty() || Intersect(window_, all) != window_)
    return Status::Error("window " + Text(window_) + " is empty or not inside the working image of provider '" +
                         innerCaps_.name + "' (" + std::to_string(innerCaps_.width) + "x" +
                         std::to_string(innerCaps_.height) + ")");
  return Status::Ok();
}

ProviderCapabilities WindowProvider::Capabilities() const {
  ProviderCapabilities c = innerCaps_;
  c.width = window_.width();
  c.height = window_.height();
  return c;
}

Status WindowProvider::Guides(const Bounds2i& region, const GuideRequest& what, GuideImage* out) {
  const Bounds2i local{{0, 0}, {window_.width(), window_.height()}};
  if (Intersect(region, local) != region)
    return Status::Error("guides requested for " + Text(region) + ", outside the window's " +
                         std::to_string(local.width()) + "x" + std::to_string(local.height()) + " pixels");
  const Point2i o = window_.min;
  const Bounds2i shifted{{region.min.x + o.x, region.min.y + o.y}, {region.max.x + o.x, region.max.y + o.y}};
  DCM_RETURN_IF_ERROR(inner_.Guides(shifted, what, out));
  out->region = region;
  return Status::Ok();
}

Status WindowProvider::Evaluate(std::span<const Point2i> pixels, const SampleRequest& what,
                                std::span<ExactSample> out) {
  std::vector<Point2i> shifted(pixels.size());
  const int w = window_.width(), h = window_.height();
  for (size_t i = 0; i < pixels.size(); ++i) {
    const Point2i p = pixels[i];
    if (p.x < 0 || p.y < 0 || p.x >= w || p.y >= h)
      return Status::Error("sample requested at (" + std::to_string(p.x) + ", " + std::to_string(p.y) +
                           "), outside the window's " + std::to_string(w) + "x" + std::to_string(h) + " pixels");
    shifted[i] = {p.x + window_.min.x, p.y + window_.min.y};
  }
  return inner_.Evaluate(shifted, what, out);
}

int RegionHaloBlocks(const ReconstructionOptions& options, const ProviderCapabilities& caps) {
  // One block: a block side is also set by the neighbouring block. Denoised
  // samples reach further: a sample on a side depends on the exact samples
  // within the denoising radius, whose state depends on the blocks they lie
  // in: as many more blocks as the radius spans.
  const detail::Settings settings = detail::Resolve(options, caps);
  if (!settings.denoise) return 1;
  const int block = std::max(1, settings.elementaryBlock);
  return 1 + (settings.denoiseRadius + block - 1) / block;
}

Point2i OutputSize(int workWidth, int workHeight, int downsample) {
  const int s = std::max(1, downsample);
  return {(workWidth + s - 1) / s, (workHeight + s - 1) / s};
}

Bounds2i WorkRegion(const Bounds2i& outputRegion, int workWidth, int workHeight, int downsample) {
  const int64_t s = std::max(1, downsample);
  auto clip = [](int64_t v, int hi) { return int(std::clamp<int64_t>(v, 0, hi)); };
  return {{clip(outputRegion.min.x * s, workWidth), clip(outputRegion.min.y * s, workHeight)},
          {clip(outputRegion.max.x * s, workWidth), clip(outputRegion.max.y * s, workHeight)}};
}

Bounds2i RegionWindow(const Bounds2i& outputRegion, int workWidth, int workHeight, int downsample,
                      int elementaryBlock, int haloBlocks) {
  const Bounds2i work = WorkRegion(outputRegion, workWidth, workHeight, downsample);
  if (work.empty()) return work;
  const int64_t S = std::max(1, elementaryBlock);
  const int64_t halo = int64_t(std::max(0, haloBlocks)) * S;
  // Start: the lattice line at or before the first pixel. End (exclusive): one
  // past the lattice line at or after the last pixel, so that the window's
  // last block ends where the frame's does.
  auto lo = [&](int first) { return std::max<int64_t>(0, first / S * S - halo); };
  auto hi = [&](int last, int extent) {
    return std::min<int64_t>(extent, (last + S - 1) / S * S + halo + 1);
  };
  return {{int(lo(work.min.x)), int(lo(work.min.y))},
          {int(hi(work.max.x - 1, workWidth)), int(hi(work.max.y - 1, workHeight))}};
}

Status ReconstructRegion(SampleProvider& provider, const ReconstructionOptions& options,
                         const Bounds2i& outputRegion, Reconstruction* out, RegionInfo* info,
                         std::vector<Point2i>* pending, int haloBlocks) {
  DCM_RETURN_IF_ERROR(options.Validate());
  const ProviderCapabilities caps = provider.Capabilities();
  const int s = std::max(1, options.downsample);
  const Point2i frame = OutputSize(caps.width, caps.height, s);
  const Bounds2i all{{0, 0}, frame};
  if (outputRegion.empty() || Intersect(outputRegion, all) != outputRegion)
    return Status::Error("region " + Text(outputRegion) + " is empty or not inside the " +
                         std::to_string(frame.x) + "x" + std::to_string(frame.y) + " output frame");
  const Bounds2i work = WorkRegion(outputRegion, caps.width, caps.height, s);
  if (haloBlocks < 0) haloBlocks = RegionHaloBlocks(options, caps);
  const Bounds2i window =
      RegionWindow(outputRegion, caps.width, caps.height, s, detail::Resolve(options, caps).elementaryBlock, haloBlocks);

  if (info) {
    info->output = outputRegion;
    info->haloBlocks = haloBlocks;
    info->work = work;
    info->window = window;
    info->frameWidth = frame.x;
    info->frameHeight = frame.y;
    info->frameWorkWidth = caps.width;
    info->frameWorkHeight = caps.height;
  }
  WindowProvider windowed(provider, window);
  DCM_RETURN_IF_ERROR(windowed.Validate());
  Reconstruction r;
  std::vector<Point2i> windowPending;
  Status st = Reconstruct(windowed, options, &r, pending ? &windowPending : nullptr);
  if (pending) {
    pending->clear();
    for (Point2i p : windowPending) pending->push_back({p.x + window.min.x, p.y + window.min.y});
  }
  if (!st.ok()) return st;
  if (r.workWidth != window.width() || r.workHeight != window.height())
    return Status::Error("the engine returned a " + std::to_string(r.workWidth) + "x" +
                         std::to_string(r.workHeight) + " image for a " + Text(window) + " window");

  // Crop the working image and sample map to the region's working pixels and
  // box-filter them: the boxes are the frame's (work.min is a multiple of s),
  // and a partial box at the frame's right or bottom edge stays partial.
  const int cw = work.width(), ch = work.height();
  out->workWidth = cw;
  out->workHeight = ch;
  out->workImage.assign(size_t(cw) * size_t(ch), RGB{});
  out->sampleMap.assign(size_t(cw) * size_t(ch), SampleReason::kInterpolated);
  for (int y = 0; y < ch; ++y) {
    const size_t src = size_t(y + work.min.y - window.min.y) * size_t(r.workWidth) +
                       size_t(work.min.x - window.min.x);
    std::copy_n(r.workImage.begin() + ptrdiff_t(src), cw, out->workImage.begin() + ptrdiff_t(size_t(y) * size_t(cw)));
    std::copy_n(r.sampleMap.begin() + ptrdiff_t(src), cw, out->sampleMap.begin() + ptrdiff_t(size_t(y) * size_t(cw)));
  }
  out->image = BoxDownsample(out->workImage, cw, ch, s, &out->width, &out->height);

  out->blocks.clear();
  for (BlockRecord b : r.blocks) {
    b.x0 += window.min.x, b.x1 += window.min.x, b.y0 += window.min.y, b.y1 += window.min.y;
    if (b.x1 >= work.min.x && b.x0 < work.max.x && b.y1 >= work.min.y && b.y0 < work.max.y)
      out->blocks.push_back(b);
  }

  out->stats = r.stats;
  out->stats.totalPixels = int64_t(cw) * ch;
  out->stats.byReason.fill(0);
  for (SampleReason reason : out->sampleMap) ++out->stats.byReason[size_t(reason)];
  out->stats.exactPixels =
      out->stats.totalPixels - out->stats.byReason[size_t(SampleReason::kInterpolated)];

  // The record covers the whole window: a part's channels are reconstructed
  // in it and cut as the image was.
  out->interpolation = std::move(r.interpolation);
  if (out->interpolation) out->interpolation->SetOrigin(window.min);
  if (info) info->windowStats = r.stats;
  return Status::Ok();
}

Point2i TileGridShape(int width, int height, int count) {
  Point2i best{0, 0};  // {columns, rows}
  double bestAspect = 0;
  for (int rows = 1; rows <= count; ++rows) {
    if (count % rows) continue;
    const int cols = count / rows;
    if (cols > width || rows > height) continue;
    const double tw = double(width) / cols, th = double(height) / rows;
    const double aspect = std::max(tw / th, th / tw);
    if (best.x == 0 || aspect < bestAspect - 1e-12) {
      best = {cols, rows};
      bestAspect = aspect;
    }
  }
  return best;
}

Status TileRegion(int width, int height, int index, int count, int align, Bounds2i* region) {
  if (width <= 0 || height <= 0)
    return Status::Error("tiles of an empty frame (" + std::to_string(width) + "x" + std::to_string(height) + ")");
  if (count < 1) return Status::Error("tile count " + std::to_string(count) + ": must be at least 1");
  if (index < 0 || index >= count)
    return Status::Error("tile index " + std::to_string(index) + " is not in 0.." + std::to_string(count - 1) +
                         " (tiles are numbered from 0)");
  const Point2i shape = TileGridShape(width, height, count);
  if (shape.x == 0)
    return Status::Error("a " + std::to_string(width) + "x" + std::to_string(height) + " frame cannot be split into " +
                         std::to_string(count) + " non-empty tiles");
  const std::vector<int> xs = Splits(width, shape.x, align), ys = Splits(height, shape.y, align);
  if (xs.empty() || ys.empty())
    return Status::Error("a " + std::to_string(width) + "x" + std::to_string(height) + " frame cannot be split into " +
                         std::to_string(count) + " non-empty tiles");
  const int col = index % shape.x, row = index / shape.x;
  *region = {{xs[size_t(col)], ys[size_t(row)]}, {xs[size_t(col) + 1], ys[size_t(row) + 1]}};
  return Status::Ok();
}

}  // namespace dcm
