// The pinhole camera of the internal ray tracer.
#pragma once

#include "dcm/embree/scene.h"
#include "dcm/embree/vec3.h"

namespace dcm::embree {

/// A primary ray with the directions through the next pixel centres in x and
/// y (ray differentials, for texture filtering).
struct CameraRay {
  Vec3 origin;
  Vec3 dir;    ///< unit
  Vec3 dirDx;  ///< unit, through (x+1, y)
  Vec3 dirDy;  ///< unit, through (x, y+1)
};

/// A pinhole camera over a working image of `width` x `height` pixels (the
/// supersampled image): pixel (x, y) is sampled at its centre, y grows down.
class Camera {
 public:
  Camera(const CameraDesc& desc, int width, int height);

  /// The ray through the centre of working pixel (x, y).
  CameraRay Generate(int x, int y) const;
  /// Generate() of pixels [x0, x1) of row y into out[0 .. x1-x0): the same
  /// rays, each direction computed once (pixel x's dirDx is pixel x+1's dir).
  /// Without `differentials`, dirDx and dirDy are left equal to dir.
  void GenerateRow(int y, int x0, int x1, bool differentials, CameraRay* out) const;

 private:
  Vec3 Direction(float fx, float fy) const;
  Vec3 origin_, forward_, right_, up_;
  float tanHalf_ = 1.f, aspect_ = 1.f;
  int width_ = 1, height_ = 1;
};

}  // namespace dcm::embree
