// Textures: the value tau that multiplies a material's diffuse albedo. Images go
// through OpenImageIO's TextureSystem (mip-mapped, filtered over the pixel's
// footprint); checker and parquet planks are procedural.
#pragma once

#include <memory>
#include <string>

#include "dcm/color.h"
#include "dcm/status.h"
#include "dcm/embree/scene.h"
#include "dcm/embree/vec3.h"


namespace dcm::embree {

/// Texture coordinates at a hit and their derivatives per working pixel in x
/// and y (zero when unknown: the finest detail is sampled).
struct TexCoord {
  Vec2 uv;
  Vec2 duvdx, duvdy;
};

/// A texture; Eval() is thread safe.
class Texture {
 public:
  virtual ~Texture() = default;
  /// The texture value (linear RGB) filtered over the footprint of `tc`.
  virtual RGB Eval(const TexCoord& tc) const = 0;
};

/// Checks the size an image file declares in its header against what the
/// file can hold (its raw size for PNM, 1/kMaxCompressionRatio of it for
/// any other format) and against MemoryBudget(). An unreadable file
/// passes (the texture system reports it). The message names the file and
/// the declared size.
Status CheckDeclaredTextureSize(const std::string& path, const std::string& what);

/// Owns the OpenImageIO texture system shared by all image textures of a scene.
class TextureCache {
 public:
  TextureCache();
  ~TextureCache();
  TextureCache(const TextureCache&) = delete;
  TextureCache& operator=(const TextureCache&) = delete;

  /// Creates the texture `desc`; image files are opened now so that a missing
  /// or unreadable file is reported here. `what` names the texture in messages.
  Status Create(const TextureDesc& desc, const std::string& what, std::unique_ptr<Texture>* out);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dcm::embree
