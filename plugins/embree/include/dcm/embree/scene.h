// The scene description of the internal ray tracer, as read from a scene file
// (see SCENE-FORMAT.md). Plain data: the ray tracer builds its acceleration
// structure, textures and lights from it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "dcm/color.h"
#include "dcm/embree/vec3.h"

namespace dcm::embree {

/// A pinhole camera; `fovDeg` is the vertical field of view.
struct CameraDesc {
  Vec3 position{0.f, 0.f, 5.f};
  Vec3 lookAt{0.f, 0.f, 0.f};
  Vec3 up{0.f, 1.f, 0.f};
  float fovDeg = 40.f;
  int width = 256;   ///< output resolution (before supersampling)
  int height = 256;
};

/// Kinds of texture: an image read through OpenImageIO's TextureSystem
/// (filtered, mip-mapped), a checkerboard or parquet planks.
enum class TextureKind { kImage, kChecker, kPlanks };

/// A texture: multiplies the diffuse albedo of a material (tau of the paper).
struct TextureDesc {
  TextureKind kind = TextureKind::kChecker;
  std::string file;            ///< kImage: absolute path of the image
  Vec2 scale{1.f, 1.f};        ///< texture coordinates are multiplied by this
  Vec2 offset{0.f, 0.f};       ///< then shifted by this
  // kChecker
  RGB color0{0.2f, 0.2f, 0.2f};
  RGB color1{0.8f, 0.8f, 0.8f};
  // kPlanks: parquet in basket weave: square tiles of side `plankLength`
  // (texture units), each of round(plankLength / plankWidth) parallel planks,
  // the direction alternating from tile to tile like a checkerboard. Each plank
  // has its own tone between wood0 and wood1 and grain along it; planks are
  // separated by a joint `gap` wide in `gapColor`.
  float plankLength = 1.f;
  float plankWidth = 0.125f;
  float gap = 0.006f;
  RGB wood0{0.45f, 0.26f, 0.12f};
  RGB wood1{0.75f, 0.50f, 0.28f};
  RGB gapColor{0.08f, 0.05f, 0.03f};
  float grain = 0.35f;  ///< strength of the grain stripes in [0, 1]
};

/// Kinds of material.
enum class MaterialKind {
  kDiffuse,  ///< Lambert: color * tau / pi
  kPlastic,  ///< Lambert plus a normalised Phong lobe (glossy reflection)
  kMirror,   ///< perfect specular reflection tinted by `specular`
};

/// A material. `color` is the diffuse albedo (times the texture, if any);
/// `specular` the Phong lobe's or the mirror's reflectance.
struct MaterialDesc {
  std::string name;
  MaterialKind kind = MaterialKind::kDiffuse;
  RGB color{0.7f, 0.7f, 0.7f};
  std::optional<TextureDesc> texture;
  RGB specular{0.f, 0.f, 0.f};
  float exponent = 50.f;  ///< Phong exponent of kPlastic
};

/// Built-in shapes and meshes from files.
enum class ShapeKind { kQuad, kBox, kSphere, kCylinder, kMesh };

/// An affine placement: scale, then rotate about x, y, z (degrees), then translate.
struct TransformDesc {
  Vec3 scale{1.f, 1.f, 1.f};
  Vec3 rotateDeg{0.f, 0.f, 0.f};
  Vec3 translate{0.f, 0.f, 0.f};
};

/// One object of the scene: a shape with a material and an object ID.
struct ObjectDesc {
  std::string path;           ///< key path in the scene file, for messages ("objects[3]")
  ShapeKind shape = ShapeKind::kQuad;
  uint32_t id = 0;            ///< object ID of the guides (1 .. 2^31-1)
  int material = 0;           ///< index into Scene::materials
  TransformDesc transform;
  // kQuad: the parallelogram origin + s*edgeU + t*edgeV, (s,t) in [0,1]^2 = uv.
  Vec3 origin{-1.f, 0.f, -1.f}, edgeU{2.f, 0.f, 0.f}, edgeV{0.f, 0.f, 2.f};
  // kBox: axis-aligned box (before the transform).
  Vec3 boxMin{-0.5f, -0.5f, -0.5f}, boxMax{0.5f, 0.5f, 0.5f};
  // kSphere
  Vec3 center{0.f, 0.f, 0.f};
  float radius = 1.f;  ///< kSphere and kCylinder
  // kCylinder: from `from` to `to`, closed with discs when `caps`.
  Vec3 from{0.f, 0.f, 0.f}, to{0.f, 1.f, 0.f};
  bool caps = true;
  int segments = 0;  ///< tessellation of sphere/cylinder; 0: automatic
  // kMesh
  std::string file;  ///< absolute path of an OBJ, PLY or glTF file
};

enum class LightKind { kPoint, kRect };

/// A light: a point light of radiant intensity `intensity` (W/sr per channel),
/// or a one-sided rectangle origin + s*edgeU + t*edgeV of radiance `radiance`
/// emitting towards cross(edgeU, edgeV).
struct LightDesc {
  std::string path;
  LightKind kind = LightKind::kPoint;
  Vec3 position{0.f, 0.f, 0.f};
  RGB intensity{1.f, 1.f, 1.f};
  Vec3 origin{0.f, 0.f, 0.f}, edgeU{1.f, 0.f, 0.f}, edgeV{0.f, 0.f, 1.f};
  RGB radiance{1.f, 1.f, 1.f};
  bool visible = true;  ///< a rect light is seen by camera and reflection rays
  uint32_t id = 0;      ///< object ID of a visible rect light
};

/// How exactly a pixel is evaluated.
struct RenderSettings {
  int shadowRays = 16;           ///< N: stratified shadow rays per area light (direct hit)
  int secondaryShadowRays = 1;   ///< shadow rays per area light at glossy/indirect hits
  int glossyRays = 8;            ///< M: rays sampling the glossy lobe
  int mirrorDepth = 4;           ///< longest chain of mirror reflections
  int indirectBounces = 0;       ///< 0: no indirect diffuse light
  int indirectRays = 16;         ///< cosine-distributed rays at the first diffuse hit
  int supersampling = 1;         ///< working resolution = resolution * supersampling per axis
  /// Independent estimates averaged per exact pixel; from 2 on, each pixel
  /// also reports the variance of its mean (a Monte Carlo renderer's "spp").
  int samplesPerPixel = 1;
  uint32_t seed = 0;             ///< changes the per-pixel random streams
  /// Point-light visibility as a guide: which point lights a pixel's surface
  /// sees, one shadow ray each, so that hard shadow edges are surface changes
  /// and thin shadows are found like thin objects. kAuto: when an exact pixel
  /// is a Monte Carlo estimate (samples_per_pixel > 1 or indirect light),
  /// where one ray per point light is cheap beside it.
  enum class ShadowGuide { kAuto, kOn, kOff } shadowGuide = ShadowGuide::kAuto;
  /// Highlights as a guide: where the direct glossy light of a plastic
  /// surface (unshadowed, from fixed points of each light) is brighter than
  /// kHighlightLevel, a highlight and the rest of its surface are different
  /// surfaces, so that a highlight smaller than the lattice is found like a
  /// thin object. No ray. true: on wherever a plastic material is used; false:
  /// off.
  bool highlightGuide = true;
  RGB background{0.f, 0.f, 0.f}; ///< radiance of rays that leave the scene
};

/// A whole scene as read from a file.
struct Scene {
  std::string file;  ///< where it came from (for messages), may be empty
  CameraDesc camera;
  std::vector<MaterialDesc> materials;
  std::vector<ObjectDesc> objects;
  std::vector<LightDesc> lights;
  RenderSettings render;
};

}  // namespace dcm::embree
