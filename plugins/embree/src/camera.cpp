#include "dcm/embree/camera.h"

#include <cmath>

namespace dcm::embree {

Camera::Camera(const CameraDesc& d, int width, int height) : width_(width), height_(height) {
  origin_ = d.position;
  forward_ = Normalize(d.lookAt - d.position);
  right_ = Normalize(Cross(forward_, d.up));
  up_ = Cross(right_, forward_);
  tanHalf_ = std::tan(0.5f * d.fovDeg * kPi / 180.f);
  aspect_ = float(width) / float(height);
}

Vec3 Camera::Direction(float fx, float fy) const {
  float sx = (2.f * fx / float(width_) - 1.f) * tanHalf_ * aspect_;
  float sy = (1.f - 2.f * fy / float(height_)) * tanHalf_;
  return Normalize(forward_ + right_ * sx + up_ * sy);
}

CameraRay Camera::Generate(int x, int y) const {
  float fx = float(x) + 0.5f, fy = float(y) + 0.5f;
  return {origin_, Direction(fx, fy), Direction(fx + 1.f, fy), Direction(fx, fy + 1.f)};
}

void Camera::GenerateRow(int y, int x0, int x1, bool differentials, CameraRay* out) const {
  const float fy = float(y) + 0.5f;
  for (int x = x0; x < x1; ++x) {
    CameraRay& r = out[x - x0];
    r.origin = origin_;
    r.dir = r.dirDx = r.dirDy = Direction(float(x) + 0.5f, fy);
  }
  if (!differentials || x1 <= x0) return;
  for (int x = x0; x < x1; ++x) {
    out[x - x0].dirDx = x + 1 < x1 ? out[x + 1 - x0].dir : Direction(float(x) + 0.5f + 1.f, fy);
    out[x - x0].dirDy = Direction(float(x) + 0.5f, fy + 1.f);
  }
}

}  // namespace dcm::embree
