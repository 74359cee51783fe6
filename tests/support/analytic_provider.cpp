#include "analytic_provider.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace dcm::testing {

AnalyticProvider::AnalyticProvider(int width, int height, SceneFunction scene, AnalyticChannels channels)
    : width_(width), height_(height), scene_(std::move(scene)), channels_(channels),
      count_(new std::atomic<int>[size_t(width) * size_t(height)]) {
  for (size_t i = 0; i < size_t(width) * size_t(height); ++i) count_[i] = 0;
}

ProviderCapabilities AnalyticProvider::Capabilities() const {
  ProviderCapabilities c;
  c.width = width_;
  c.height = height_;
  c.objectId = channels_.ids;
  c.shaderId = channels_.ids && channels_.shaders;
  c.texture = channels_.texture;
  c.splitRadiance = channels_.texture;
  c.normal = channels_.normals;
  c.hardShadowsGuided = channels_.hardShadowsGuided;
  c.name = "analytic";
  return c;
}

Status AnalyticProvider::Guides(const Bounds2i& region, const GuideRequest& what, GuideImage* out) {
  out->region = region;
  const size_t n = size_t(region.area());
  out->objectId.assign(what.objectId ? n : 0, 0);
  out->shaderId.assign(what.shaderId ? n : 0, 0);
  out->texture.assign(what.texture ? n : 0, RGB{});
  out->normal.assign(what.normal ? n : 0, Vec3f{});
  for (int y = region.min.y; y < region.max.y; ++y)
    for (int x = region.min.x; x < region.max.x; ++x) {
      const PixelTruth t = scene_(x, y);
      const size_t i = size_t(region.offset({x, y}));
      if (what.objectId) out->objectId[i] = t.objectId;
      if (what.shaderId) out->shaderId[i] = t.shaderId;
      if (what.texture) out->texture[i] = t.tau;
      if (what.normal) out->normal[i] = t.normal;
    }
  return Status::Ok();
}

Status AnalyticProvider::Evaluate(std::span<const Point2i> pixels, const SampleRequest& what,
                                  std::span<ExactSample> out) {
  for (size_t k = 0; k < pixels.size(); ++k) {
    const Point2i p = pixels[k];
    if (p.x < 0 || p.y < 0 || p.x >= width_ || p.y >= height_)
      return Status::Error("analytic: pixel outside the image");
    ++count_[size_t(p.y) * size_t(width_) + size_t(p.x)];
    const PixelTruth t = scene_(p.x, p.y);
    out[k].L = t.L();
    if (what.split) {
      out[k].Li = t.Li;
      out[k].Lc = t.Lc;
    }
  }
  return Status::Ok();
}

std::vector<RGB> AnalyticProvider::FullRender() const {
  std::vector<RGB> img(size_t(width_) * size_t(height_));
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) img[size_t(y) * size_t(width_) + size_t(x)] = scene_(x, y).L();
  return img;
}

int AnalyticProvider::MaxEvaluationsOfOnePixel() const {
  int m = 0;
  for (size_t i = 0; i < size_t(width_) * size_t(height_); ++i) m = std::max(m, count_[i].load());
  return m;
}

int64_t AnalyticProvider::TotalEvaluations() const {
  int64_t s = 0;
  for (size_t i = 0; i < size_t(width_) * size_t(height_); ++i) s += count_[i].load();
  return s;
}

namespace {
float Smoothstep(float e0, float e1, float x) {
  const float t = std::clamp((x - e0) / (e1 - e0), 0.f, 1.f);
  return t * t * (3 - 2 * t);
}
constexpr float kLineAngle = 34.f * std::numbers::pi_v<float> / 180.f;
}  // namespace

bool OnThinLine(int width, int height, int x, int y) {
  // A line through (0.1 W, 0.55 H) at 34 degrees (between two of the eight
  // candidate directions); pixels whose centre lies
  // within half a pixel of it, from 0.05 W to 0.6 W.
  const float px = float(x) + 0.5f, py = float(y) + 0.5f;
  const float ox = 0.1f * float(width), oy = 0.55f * float(height);
  const float dx = std::cos(kLineAngle), dy = -std::sin(kLineAngle);
  const float along = (px - ox) * dx + (py - oy) * dy;
  const float across = -(px - ox) * dy + (py - oy) * dx;
  return std::fabs(across) < 0.5f && along > -0.05f * float(width) && along < 0.5f * float(width);
}

SceneFunction FurnishedScene(int width, int height, FurnishedOptions o) {
  const float W = float(width), H = float(height);
  return [=](int x, int y) {
    const float px = float(x) + 0.5f, py = float(y) + 0.5f;
    const float u = px / W, v = py / H;
    PixelTruth t;
    // Light: a smooth gradient, darkened by a soft shadow whose penumbra is a
    // band about 6 px wide along a line at 60 degrees.
    RGB light(0.25f + 0.5f * u, 0.3f + 0.3f * v, 0.45f);
    if (o.softShadow) {
      const float d = (px - 0.3f * W) * 0.866f - (py - 0.0f) * 0.5f;  // signed distance to the shadow line
      light = light * (0.25f + 0.75f * Smoothstep(-3.f, 3.f, d));
    }
    t.Li = light;
    const float fx = px - 0.7f * W, fy = py - 0.3f * H, r = 0.15f * W;
    if (o.hdr && (px - 0.85f * W) * (px - 0.85f * W) + (py - 0.08f * H) * (py - 0.08f * H) < 0.02f * W * 0.02f * W) {
      t.objectId = 5, t.shaderId = 5;
      t.Li = RGB::Gray(1000.f);
    } else if (o.disc && fx * fx + fy * fy < r * r) {
      t.objectId = 2, t.shaderId = 2;
      const float nz = std::sqrt(std::max(0.f, 1 - (fx * fx + fy * fy) / (r * r)));
      t.Li = RGB(0.9f, 0.25f, 0.1f) * (0.15f + 0.85f * nz * std::clamp(0.5f - 0.5f * fx / r, 0.f, 1.f));
    } else if (o.thinLine && OnThinLine(width, height, x, y)) {
      t.objectId = 3, t.shaderId = 3;
      t.Li = RGB(1.0f, 0.9f, 0.2f);
    } else if (o.texture && v > 0.62f) {
      // A plank floor: tau varies every few pixels, the light does not.
      t.objectId = 4, t.shaderId = 4;
      const int plank = int(py / 6.f);
      const float offset = float((plank * 37) % 23);
      const int board = int((px + offset) / 18.f);
      const float grain = 0.5f + 0.5f * std::sin(0.9f * px + 3.f * float(plank));
      const float shade = 0.45f + 0.3f * float((board * 7 + plank * 3) % 5) / 4.f + 0.1f * grain;
      t.tau = RGB(shade, 0.75f * shade, 0.5f * shade);
      // A glossy highlight that the texture does not modulate.
      const float hx = (px - 0.4f * W) / (0.08f * W), hy = (py - 0.8f * H) / (0.05f * H);
      t.Lc = RGB::Gray(0.6f * std::exp(-(hx * hx + hy * hy)));
    }
    return t;
  };
}

SceneFunction LinearRamp(RGB a, RGB bx, RGB cy) {
  return [=](int x, int y) {
    PixelTruth t;
    t.Li = a + bx * float(x) + cy * float(y);
    return t;
  };
}

SceneFunction Constant(RGB c) {
  return [=](int, int) {
    PixelTruth t;
    t.Li = c;
    return t;
  };
}

SceneFunction Noise(uint32_t seed) {
  return [=](int x, int y) {
    auto hash = [](uint32_t h) {
      h ^= h >> 16, h *= 0x7feb352dU, h ^= h >> 15, h *= 0x846ca68bU, h ^= h >> 16;
      return h;
    };
    PixelTruth t;
    const uint32_t h = hash(seed ^ hash(uint32_t(x) * 73856093U ^ uint32_t(y) * 19349663U));
    t.Li = RGB(float(h & 0x3ff) / 1024.f, float((h >> 10) & 0x3ff) / 1024.f, float((h >> 20) & 0x3ff) / 1024.f);
    return t;
  };
}

SceneFunction ManyPrimitivesOneShader(int s) {
  return [=](int x, int y) {
    PixelTruth t;
    const int cx = x / s, cy = y / s;
    const bool upper = (x % s) > (y % s);  // two triangles per cell
    t.objectId = uint32_t(2 * (cy * 1000 + cx) + (upper ? 1 : 0) + 10);
    t.shaderId = 7;
    t.Li = RGB(0.4f + 0.001f * float(x), 0.5f, 0.3f + 0.0005f * float(y));
    return t;
  };
}

double DisplayPsnr(const std::vector<RGB>& image, const std::vector<RGB>& reference) {
  double se = 0;
  for (size_t i = 0; i < image.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double d = double(SrgbEncode(image[i][c])) - double(SrgbEncode(reference[i][c]));
      se += d * d;
    }
  const double mse = se / (3.0 * double(image.size()));
  return mse > 0 ? 10 * std::log10(1.0 / mse) : INFINITY;
}

}  // namespace dcm::testing
