#include "dcm/embree/scene_file.h"

#include <limits>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "json_fields.h"

namespace dcm::embree {
namespace {

namespace fs = std::filesystem;

constexpr uint32_t kMaxObjectId = 0x7fffffffu;  // the top bit marks mirrored IDs

/// Resolves `name` against `baseDir` and checks that it is a readable file.
Status ResolveFile(FieldReader& r, std::string_view key, const std::string& name,
                   const std::string& baseDir, std::string* out) {
  fs::path p(name);
  if (p.is_relative() && !baseDir.empty()) p = fs::path(baseDir) / p;
  std::error_code ec;
  if (!fs::is_regular_file(p, ec)) {
    r.Fail(key, "file '" + p.string() + "' not found");
    return r.status();
  }
  std::ifstream probe(p, std::ios::binary);
  if (!probe) {
    r.Fail(key, "cannot read file '" + p.string() + "'");
    return r.status();
  }
  *out = p.lexically_normal().string();
  return Status::Ok();
}

Status ReadCamera(const Json& j, const std::string& file, CameraDesc* cam) {
  FieldReader r(j, "camera", file);
  r.Vector3("position", &cam->position, true);
  r.Vector3("look_at", &cam->lookAt, true);
  r.Vector3("up", &cam->up);
  r.Float("fov", &cam->fovDeg, false, 1.f, 170.f);
  if (const Json* res = r.Get("resolution"); res && r.ok()) {
    if (!res->is_array() || res->size() != 2 || !(*res)[0].is_number_integer() ||
        !(*res)[1].is_number_integer()) {
      r.Fail("resolution", "expected [width, height] (2 integers), found " + TypeName(*res));
    } else {
      int64_t w = (*res)[0].get<int64_t>(), h = (*res)[1].get<int64_t>();
      if (w < 1 || h < 1 || w > 16384 || h > 16384) {
        r.Fail("resolution", "width and height must be in [1, 16384]");
      } else {
        cam->width = int(w);
        cam->height = int(h);
      }
    }
  }
  if (r.ok() && Length(cam->lookAt - cam->position) == 0.f) {
    r.Fail("look_at", "equals camera.position");
  }
  if (r.ok() && Length(Cross(cam->lookAt - cam->position, cam->up)) == 0.f) {
    r.Fail("up", "is parallel to the viewing direction");
  }
  return r.Finish();
}

Status ReadRender(const Json& j, const std::string& file, RenderSettings* s) {
  FieldReader r(j, "render", file);
  r.Int("shadow_rays", &s->shadowRays, false, 1, 65536);
  r.Int("secondary_shadow_rays", &s->secondaryShadowRays, false, 1, 65536);
  r.Int("glossy_rays", &s->glossyRays, false, 0, 65536);
  r.Int("mirror_depth", &s->mirrorDepth, false, 0, 64);
  r.Int("supersampling", &s->supersampling, false, 1, 16);
  r.Int("samples_per_pixel", &s->samplesPerPixel, false, 1, 1 << 20);
  r.Uint32("seed", &s->seed, 0, UINT32_MAX);
  r.Color("background", &s->background);
  if (const Json* g = r.Get("shadow_guide"); g && r.ok()) {
    if (g->is_boolean())
      s->shadowGuide = g->get<bool>() ? RenderSettings::ShadowGuide::kOn : RenderSettings::ShadowGuide::kOff;
    else if (g->is_string() && g->get<std::string>() == "auto")
      s->shadowGuide = RenderSettings::ShadowGuide::kAuto;
    else
      r.Fail("shadow_guide", "expected true, false or \"auto\", got " + TypeName(*g));
  }
  r.Bool("highlight_guide", &s->highlightGuide);
  if (const Json* ind = r.Get("indirect"); ind && r.ok()) {
    FieldReader ri(*ind, r.Path("indirect"), file);
    ri.Int("bounces", &s->indirectBounces, false, 0, 16);
    ri.Int("rays", &s->indirectRays, false, 1, 65536);
    DCM_RETURN_IF_ERROR(ri.Finish());
  }
  return r.Finish();
}

Status ReadTexture(const Json& j, const std::string& path, const std::string& file,
                   const std::string& baseDir, TextureDesc* t) {
  FieldReader r(j, path, file);
  std::string type;
  r.String("type", &type, true);
  if (!r.ok()) return r.status();
  r.Vector2("scale", &t->scale);
  r.Vector2("offset", &t->offset);
  if (type == "image") {
    t->kind = TextureKind::kImage;
    std::string name;
    r.String("file", &name, true);
    if (r.ok()) DCM_RETURN_IF_ERROR(ResolveFile(r, "file", name, baseDir, &t->file));
  } else if (type == "checker") {
    t->kind = TextureKind::kChecker;
    r.Color("color0", &t->color0);
    r.Color("color1", &t->color1);
  } else if (type == "planks") {
    t->kind = TextureKind::kPlanks;
    r.Float("plank_length", &t->plankLength, false, 1e-6f, 1e6f);
    r.Float("plank_width", &t->plankWidth, false, 1e-6f, 1e6f);
    r.Float("gap", &t->gap, false, 0.f, 1e6f);
    r.Color("wood0", &t->wood0);
    r.Color("wood1", &t->wood1);
    r.Color("gap_color", &t->gapColor);
    r.Float("grain", &t->grain, false, 0.f, 1.f);
  } else {
    r.Fail("type", "unknown texture type '" + type + "' (expected image, checker or planks)");
  }
  return r.Finish();
}

Status ReadMaterial(const Json& j, const std::string& path, const std::string& file,
                    const std::string& baseDir, MaterialDesc* m) {
  FieldReader r(j, path, file);
  std::string type;
  r.String("type", &type, true);
  if (!r.ok()) return r.status();
  if (type == "diffuse" || type == "plastic") {
    m->kind = type == "diffuse" ? MaterialKind::kDiffuse : MaterialKind::kPlastic;
    r.Color("color", &m->color);
    if (const Json* tex = r.Get("texture"); tex && r.ok()) {
      TextureDesc t;
      DCM_RETURN_IF_ERROR(ReadTexture(*tex, r.Path("texture"), file, baseDir, &t));
      m->texture = t;
    }
    if (m->kind == MaterialKind::kPlastic) {
      m->specular = RGB::Gray(0.04f);
      r.Color("specular", &m->specular);
      r.Float("exponent", &m->exponent, false, 0.f, 1e6f);
    }
  } else if (type == "mirror") {
    m->kind = MaterialKind::kMirror;
    m->color = RGB::Gray(0.f);
    m->specular = RGB::Gray(0.9f);
    r.Color("color", &m->specular);
  } else {
    r.Fail("type", "unknown material type '" + type + "' (expected diffuse, plastic or mirror)");
  }
  return r.Finish();
}

Status ReadTransform(const Json& j, const std::string& path, const std::string& file,
                     TransformDesc* t) {
  FieldReader r(j, path, file);
  if (const Json* s = r.Get("scale"); s && s->is_number()) {
    float f = 1.f;
    r.Float("scale", &f, true, -std::numeric_limits<float>::max(), std::numeric_limits<float>::max());
    t->scale = {f, f, f};
  } else {
    r.Vector3("scale", &t->scale);
  }
  r.Vector3("rotate", &t->rotateDeg);
  r.Vector3("translate", &t->translate);
  if (r.ok() && (t->scale.x == 0.f || t->scale.y == 0.f || t->scale.z == 0.f)) {
    r.Fail("scale", "must not be zero");
  }
  return r.Finish();
}

Status ReadObject(const Json& j, const std::string& path, const std::string& file,
                  const std::string& baseDir, const std::map<std::string, int>& materials,
                  ObjectDesc* o) {
  FieldReader r(j, path, file);
  o->path = path;
  std::string type, material;
  r.String("type", &type, true);
  r.String("material", &material, true);
  r.Uint32("id", &o->id, 1, kMaxObjectId);
  if (!r.ok()) return r.status();
  if (auto it = materials.find(material); it != materials.end()) {
    o->material = it->second;
  } else {
    r.Fail("material", "unknown material '" + material + "'");
    return r.status();
  }
  if (const Json* t = r.Get("transform"); t) {
    DCM_RETURN_IF_ERROR(ReadTransform(*t, r.Path("transform"), file, &o->transform));
  }
  if (type == "quad") {
    o->shape = ShapeKind::kQuad;
    r.Vector3("origin", &o->origin, true);
    r.Vector3("edge_u", &o->edgeU, true);
    r.Vector3("edge_v", &o->edgeV, true);
    if (r.ok() && Length(Cross(o->edgeU, o->edgeV)) == 0.f) r.Fail("edge_v", "is parallel to edge_u");
  } else if (type == "box") {
    o->shape = ShapeKind::kBox;
    r.Vector3("min", &o->boxMin, true);
    r.Vector3("max", &o->boxMax, true);
    if (r.ok() && !(o->boxMin.x < o->boxMax.x && o->boxMin.y < o->boxMax.y && o->boxMin.z < o->boxMax.z)) {
      r.Fail("max", "must be greater than min in x, y and z");
    }
  } else if (type == "sphere") {
    o->shape = ShapeKind::kSphere;
    r.Vector3("center", &o->center);
    r.Float("radius", &o->radius, true, 1e-9f, 1e9f);
    r.Int("segments", &o->segments, false, 3, 4096);
  } else if (type == "cylinder") {
    o->shape = ShapeKind::kCylinder;
    r.Vector3("from", &o->from, true);
    r.Vector3("to", &o->to, true);
    r.Float("radius", &o->radius, true, 1e-9f, 1e9f);
    r.Bool("caps", &o->caps);
    r.Int("segments", &o->segments, false, 3, 4096);
    if (r.ok() && Length(o->to - o->from) == 0.f) r.Fail("to", "equals from");
  } else if (type == "mesh") {
    o->shape = ShapeKind::kMesh;
    std::string name;
    r.String("file", &name, true);
    if (r.ok()) DCM_RETURN_IF_ERROR(ResolveFile(r, "file", name, baseDir, &o->file));
  } else {
    r.Fail("type", "unknown object type '" + type + "' (expected quad, box, sphere, cylinder or mesh)");
  }
  return r.Finish();
}

Status ReadLight(const Json& j, const std::string& path, const std::string& file, LightDesc* l) {
  FieldReader r(j, path, file);
  l->path = path;
  std::string type;
  r.String("type", &type, true);
  if (!r.ok()) return r.status();
  if (type == "point") {
    l->kind = LightKind::kPoint;
    r.Vector3("position", &l->position, true);
    r.Color("intensity", &l->intensity, true);
  } else if (type == "rect") {
    l->kind = LightKind::kRect;
    r.Vector3("origin", &l->origin, true);
    r.Vector3("edge_u", &l->edgeU, true);
    r.Vector3("edge_v", &l->edgeV, true);
    r.Color("radiance", &l->radiance, true);
    r.Bool("visible", &l->visible);
    r.Uint32("id", &l->id, 1, kMaxObjectId);
    if (r.ok() && Length(Cross(l->edgeU, l->edgeV)) == 0.f) r.Fail("edge_v", "is parallel to edge_u");
  } else {
    r.Fail("type", "unknown light type '" + type + "' (expected point or rect)");
  }
  return r.Finish();
}

/// Applies one "KEY.PATH=JSON" override to the root of a scene.
Status ApplyOverride(const std::string& setting, const std::string& file, Json* root) {
  const size_t eq = setting.find('=');
  const std::string key = setting.substr(0, eq);
  if (eq == std::string::npos || key.empty() || key.front() == '.' || key.back() == '.' ||
      key.find("..") != std::string::npos)
    return Status::Error(file + ": override '" + setting + "': expected KEY.PATH=VALUE (e.g. render.shadow_rays=4)");
  Json value;
  const std::string text = setting.substr(eq + 1);
  if (!ParseJsonText(text, "override", &value).ok()) value = text;  // a bare word is a string
  Json* node = root;
  size_t begin = 0;
  for (;;) {
    const size_t dot = key.find('.', begin);
    const std::string part = key.substr(begin, dot == std::string::npos ? std::string::npos : dot - begin);
    if (!node->is_object())
      return Status::Error(file + ": override '" + setting + "': '" + key.substr(0, begin ? begin - 1 : 0) +
                           "' is not an object");
    if (dot == std::string::npos) {
      (*node)[part] = std::move(value);
      return Status::Ok();
    }
    if (!node->contains(part)) (*node)[part] = Json::object();
    node = &(*node)[part];
    begin = dot + 1;
  }
}

}  // namespace

Status ParseScene(std::string_view text, const std::string& file, const std::string& baseDir,
                  Scene* scene, std::span<const std::string> overrides) {
  Json root;
  DCM_RETURN_IF_ERROR(ParseJsonText(text, file, &root));
  for (const std::string& o : overrides) DCM_RETURN_IF_ERROR(ApplyOverride(o, file, &root));
  Scene s;
  s.file = file;
  FieldReader r(root, "", file);
  if (!r.ok()) return r.status();

  const Json* camera = r.Get("camera");
  if (!camera) return FieldError(file, "camera", "missing (the scene needs a camera)");
  DCM_RETURN_IF_ERROR(ReadCamera(*camera, file, &s.camera));
  if (const Json* render = r.Get("render")) DCM_RETURN_IF_ERROR(ReadRender(*render, file, &s.render));

  std::map<std::string, int> materialIndex;
  const Json* materials = r.Get("materials");
  if (!materials) return FieldError(file, "materials", "missing (an object of named materials)");
  if (!materials->is_object()) {
    return FieldError(file, "materials", "expected an object of named materials, found " + TypeName(*materials));
  }
  for (auto it = materials->begin(); it != materials->end(); ++it) {
    MaterialDesc m;
    m.name = it.key();
    DCM_RETURN_IF_ERROR(ReadMaterial(it.value(), "materials." + it.key(), file, baseDir, &m));
    materialIndex[m.name] = int(s.materials.size());
    s.materials.push_back(std::move(m));
  }

  const Json* objects = r.Get("objects");
  if (!objects) return FieldError(file, "objects", "missing (an array of objects)");
  if (!objects->is_array()) return FieldError(file, "objects", "expected an array, found " + TypeName(*objects));
  if (objects->empty()) return FieldError(file, "objects", "the scene has no objects");
  for (size_t i = 0; i < objects->size(); ++i) {
    ObjectDesc o;
    o.id = uint32_t(i + 1);
    DCM_RETURN_IF_ERROR(ReadObject((*objects)[i], "objects[" + std::to_string(i) + "]", file, baseDir,
                                   materialIndex, &o));
    s.objects.push_back(std::move(o));
  }

  const Json* lights = r.Get("lights");
  if (!lights) return FieldError(file, "lights", "missing (an array of lights)");
  if (!lights->is_array()) return FieldError(file, "lights", "expected an array, found " + TypeName(*lights));
  if (lights->empty()) return FieldError(file, "lights", "the scene has no lights");
  for (size_t i = 0; i < lights->size(); ++i) {
    LightDesc l;
    l.id = uint32_t(objects->size() + i + 1);
    DCM_RETURN_IF_ERROR(ReadLight((*lights)[i], "lights[" + std::to_string(i) + "]", file, &l));
    s.lights.push_back(std::move(l));
  }
  DCM_RETURN_IF_ERROR(r.Finish());
  *scene = std::move(s);
  return Status::Ok();
}

Status LoadSceneFile(const std::string& path, Scene* scene, std::span<const std::string> overrides) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error(path + ": cannot open the scene file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) return Status::Error(path + ": read error");
  std::string baseDir = fs::path(path).parent_path().string();
  return ParseScene(buffer.str(), path, baseDir, scene, overrides);
}

}  // namespace dcm::embree
