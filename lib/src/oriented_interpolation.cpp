#include "oriented_interpolation.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace dcm::detail {

Direction Direction::Of(int k, int count) {
  const double theta = std::numbers::pi * double(k) / double(count);
  Direction d{std::cos(theta), std::sin(theta)};
  // Exact zeros keep axis-aligned lines on their pixel rows and columns.
  if (std::fabs(d.dx) < 1e-12) d.dx = 0;
  if (std::fabs(d.dy) < 1e-12) d.dy = 0;
  return d;
}

bool ExitPoint(const Block& b, double px, double py, Direction d, BorderPoint* out) {
  constexpr double kEps = 1e-9;
  // In block-local coordinates (pixel positions are integers, so the shift is
  // exact): the rounding then does not depend on where the block lies in the
  // image, and a block reconstructed in a window of the image gives the same
  // bits as in the whole image (tiles, dcm/window_provider.h).
  const double lx = px - b.x0, ly = py - b.y0;
  const int w = b.x1 - b.x0, h = b.y1 - b.y0;
  double t = INFINITY;
  int side = -1;  // 0: x = x0, 1: x = x1, 2: y = y0, 3: y = y1
  auto consider = [&](double tc, int s) {
    if (tc > kEps && tc < t) t = tc, side = s;
  };
  if (d.dx != 0) {
    consider((0 - lx) / d.dx, 0);
    consider((w - lx) / d.dx, 1);
  }
  if (d.dy != 0) {
    consider((0 - ly) / d.dy, 2);
    consider((h - ly) / d.dy, 3);
  }
  if (side < 0) return false;
  // The ray must cross the open interior, not run along the border.
  const double mx = lx + 0.5 * t * d.dx, my = ly + 0.5 * t * d.dy;
  if (!(mx > kEps && mx < w - kEps && my > kEps && my < h - kEps)) return false;

  out->t = t;
  if (side <= 1) {
    const int x = side == 0 ? b.x0 : b.x1;
    double y = std::clamp(ly + t * d.dy, 0.0, double(h));
    const int y0 = std::min(int(std::floor(y)), h);
    const int y1 = std::min(y0 + 1, h);
    out->p0 = {x, b.y0 + y0};
    out->p1 = {x, b.y0 + y1};
    out->w1 = y1 == y0 ? 0.0 : y - y0;
  } else {
    const int y = side == 2 ? b.y0 : b.y1;
    double x = std::clamp(lx + t * d.dx, 0.0, double(w));
    const int x0 = std::min(int(std::floor(x)), w);
    const int x1 = std::min(x0 + 1, w);
    out->p0 = {b.x0 + x0, y};
    out->p1 = {b.x0 + x1, y};
    out->w1 = x1 == x0 ? 0.0 : x - x0;
  }
  return true;
}

namespace {
/// The oriented element of block-local pixel (x, y) of a width x height block.
OrientedElements::Element LocalElement(int width, int height, int x, int y, Direction d) {
  const Block local{0, 0, width, height};
  OrientedElements::Element e;
  BorderPoint fwd, back;
  if (!ExitPoint(local, x, y, d, &fwd) || !ExitPoint(local, x, y, Direction{-d.dx, -d.dy}, &back)) return e;
  // The nearer border point gets the larger weight.
  const double total = fwd.t + back.t;
  const double wf = back.t / total, wb = fwd.t / total;
  e.count = 0;
  auto add = [&](Point2i p, double w, uint8_t end) {
    if (w <= 0) return;
    e.p[size_t(e.count)] = p;
    e.weight[size_t(e.count)] = w;
    e.end[size_t(e.count)] = end;
    ++e.count;
  };
  add(fwd.p0, wf * (1 - fwd.w1), 0);
  add(fwd.p1, wf * fwd.w1, 0);
  add(back.p0, wb * (1 - back.w1), 1);
  add(back.p1, wb * back.w1, 1);
  return e;
}

bool ToInterpolant(const SampleStore& store, const Block& b, const OrientedElements::Element& e,
                   Interpolant* out) {
  if (e.count < 0) return false;
  out->count = e.count;
  for (int k = 0; k < e.count; ++k) {
    out->index[size_t(k)] = store.Index(b.x0 + e.p[size_t(k)].x, b.y0 + e.p[size_t(k)].y);
    out->weight[size_t(k)] = e.weight[size_t(k)];
    out->end[size_t(k)] = e.end[size_t(k)];
  }
  return true;
}
}  // namespace

bool OrientedInterpolant(const SampleStore& store, const Block& b, Point2i q, Direction d,
                         Interpolant* out) {
  return ToInterpolant(store, b, LocalElement(b.width(), b.height(), q.x - b.x0, q.y - b.y0, d), out);
}

OrientedElements::OrientedElements(int width, int height, Direction d) : width_(width), height_(height), d_(d) {
  for (int y = 1; y < height; ++y)
    for (int x = 1; x < width; ++x) elements_.push_back(LocalElement(width, height, x, y, d));
}

bool OrientedElements::At(const SampleStore& store, const Block& b, Point2i q,
                          Interpolant* out) const {
  const int x = q.x - b.x0, y = q.y - b.y0;
  if (b.width() != width_ || b.height() != height_ || x < 1 || y < 1 || x >= width_ || y >= height_)
    return OrientedInterpolant(store, b, q, d_, out);
  return ToInterpolant(store, b, elements_[size_t(y - 1) * size_t(width_ - 1) + size_t(x - 1)], out);
}

Value Evaluate(const SampleStore& store, const Interpolant& in) {
  Value v[4];
  const Value* p[4] = {&v[0], &v[1], &v[2], &v[3]};
  for (int k = 0; k < in.count; ++k) v[k] = store.ValueAt(in.index[size_t(k)]);
  return WeightedSum(p, in.weight.data(), in.count);
}

Value Bilinear(const SampleStore& store, const Block& b, Point2i q) {
  const double u = b.x1 > b.x0 ? double(q.x - b.x0) / (b.x1 - b.x0) : 0.0;
  const double v = b.y1 > b.y0 ? double(q.y - b.y0) / (b.y1 - b.y0) : 0.0;
  Interpolant in;
  auto add = [&](int x, int y, double w) {
    if (w <= 0) return;
    in.index[in.count] = store.Index(x, y);
    in.weight[in.count] = w;
    ++in.count;
  };
  add(b.x0, b.y0, (1 - u) * (1 - v));
  add(b.x1, b.y0, u * (1 - v));
  add(b.x0, b.y1, (1 - u) * v);
  add(b.x1, b.y1, u * v);
  return Evaluate(store, in);
}

bool OneEnded(const Interpolant& in) {
  for (int k = 1; k < in.count; ++k)
    if (in.end[k] != in.end[0]) return false;
  return in.count > 0;
}

}  // namespace dcm::detail
