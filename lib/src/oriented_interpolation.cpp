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

bool OrientedInterpolant(const SampleStore& store, const Block& b, Point2i q, Direction d,
                         Interpolant* out) {
  BorderPoint fwd, back;
  if (!ExitPoint(b, q.x, q.y, d, &fwd) ||
      !ExitPoint(b, q.x, q.y, Direction{-d.dx, -d.dy}, &back))
    return false;
  // The nearer border point gets the larger weight.
  const double total = fwd.t + back.t;
  const double wf = back.t / total, wb = fwd.t / total;
  out->count = 0;
  auto add = [&](Point2i p, double w) {
    if (w <= 0) return;
    out->index[out->count] = store.Index(p.x, p.y);
    out->weight[out->count] = w;
    ++out->count;
  };
  add(fwd.p0, wf * (1 - fwd.w1));
  add(fwd.p1, wf * fwd.w1);
  add(back.p0, wb * (1 - back.w1));
  add(back.p1, wb * back.w1);
  return true;
}

Value Evaluate(const SampleStore& store, const Interpolant& in) {
  // Weights in double: a linear ramp is reproduced to float rounding.
  double a[3] = {0, 0, 0}, bb[3] = {0, 0, 0}, varA = 0, varB = 0;
  for (int k = 0; k < in.count; ++k) {
    const Value v = store.ValueAt(in.index[k]);
    const double w = in.weight[k];
    for (int c = 0; c < 3; ++c) {
      a[c] += w * v.a[c];
      bb[c] += w * v.b[c];
    }
    // Independent samples: the variance of the weighted sum.
    varA += w * w * v.varA;
    varB += w * w * v.varB;
  }
  return {RGB(float(a[0]), float(a[1]), float(a[2])), RGB(float(bb[0]), float(bb[1]), float(bb[2])),
          float(varA), float(varB)};
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

}  // namespace dcm::detail
