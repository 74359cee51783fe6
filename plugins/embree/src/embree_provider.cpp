#include "dcm/embree/embree_provider.h"

#include "dcm/embree/scene_file.h"

#include <algorithm>
#include <new>

#include <tbb/parallel_for.h>

namespace dcm::embree {

std::vector<std::string> Effects::Names() const {
  std::vector<std::string> n;
  if (pointLights) n.push_back("point_lights");
  if (areaLights) n.push_back("area_lights");
  if (glossy) n.push_back("glossy");
  if (mirror) n.push_back("mirror");
  if (textures) n.push_back("textures");
  if (indirect) n.push_back("indirect");
  if (shadowGuide) n.push_back("shadow_guide");
  if (highlightGuide) n.push_back("highlight_guide");
  return n;
}

Status EmbreeProvider::FromFile(const std::string& path, std::unique_ptr<EmbreeProvider>* out) {
  Scene scene;
  DCM_RETURN_IF_ERROR(LoadSceneFile(path, &scene));
  return Create(scene, out);
}

Status EmbreeProvider::Create(const Scene& scene, std::unique_ptr<EmbreeProvider>* out) {
  std::unique_ptr<EmbreeProvider> p(new EmbreeProvider());
  p->scene_ = scene;
  const RenderSettings& rs = scene.render;
  const std::string prefix = scene.file.empty() ? "" : scene.file + ": ";
  if (scene.lights.empty()) return Status::Error(prefix + "lights: the scene has no lights");
  if (scene.objects.empty()) return Status::Error(prefix + "objects: the scene has no objects");
  p->workWidth_ = scene.camera.width * rs.supersampling;
  p->workHeight_ = scene.camera.height * rs.supersampling;

  // Only what the objects use decides the effects.
  std::vector<bool> used(scene.materials.size(), false);
  std::vector<int> objectMaterial;
  std::vector<uint32_t> objectId;
  for (const ObjectDesc& o : scene.objects) {
    if (o.material < 0 || size_t(o.material) >= scene.materials.size()) {
      return Status::Error(prefix + o.path + ".material: index out of range");
    }
    used[size_t(o.material)] = true;
    objectMaterial.push_back(o.material);
    objectId.push_back(o.id);
  }
  std::vector<Material> materials;
  Effects fx;
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    const MaterialDesc& d = scene.materials[i];
    Material m;
    m.kind = d.kind;
    m.color = d.color;
    m.specular = d.specular;
    m.exponent = d.exponent;
    if (d.texture && used[i]) {
      std::unique_ptr<Texture> t;
      DCM_RETURN_IF_ERROR(p->textureCache_.Create(*d.texture, prefix + "materials." + d.name + ".texture", &t));
      m.texture = t.get();
      p->textures_.push_back(std::move(t));
      fx.textures = true;
    }
    if (used[i] && m.glossy()) fx.plastic = true;
    if (used[i] && m.glossy() && rs.glossyRays > 0) fx.glossy = true;
    if (used[i] && m.kind == MaterialKind::kMirror && rs.mirrorDepth > 0) fx.mirror = true;
    materials.push_back(m);
  }
  std::vector<Light> lights;
  std::vector<uint32_t> lightId;
  for (const LightDesc& l : scene.lights) {
    lights.push_back(Light::From(l));
    lightId.push_back(l.id);
    if (l.kind == LightKind::kPoint) fx.pointLights = true;
    else fx.areaLights = true;
  }
  fx.indirect = rs.indirectBounces > 0;
  using SG = RenderSettings::ShadowGuide;
  fx.shadowGuide = fx.pointLights && (rs.shadowGuide == SG::kOn ||
                                      (rs.shadowGuide == SG::kAuto && (rs.samplesPerPixel > 1 || fx.indirect)));
  fx.highlightGuide = fx.plastic && rs.highlightGuide;
  p->effects_ = fx;

  DCM_RETURN_IF_ERROR(EmbreeScene::Build(scene, &p->bvh_));
  p->camera_ = std::make_unique<Camera>(scene.camera, p->workWidth_, p->workHeight_);

  IntegratorConfig cfg;
  cfg.shadowRays = rs.shadowRays;
  cfg.secondaryShadowRays = rs.secondaryShadowRays;
  cfg.glossyRays = fx.glossy ? rs.glossyRays : 0;
  cfg.mirrorDepth = fx.mirror ? rs.mirrorDepth : 0;
  cfg.indirectBounces = fx.indirect ? rs.indirectBounces : 0;
  cfg.indirectRays = fx.indirect ? rs.indirectRays : 0;
  cfg.samplesPerPixel = rs.samplesPerPixel;
  cfg.seed = rs.seed;
  cfg.background = rs.background;
  cfg.shadowGuide = fx.shadowGuide;
  cfg.highlightGuide = fx.highlightGuide;
  p->integrator_ = std::make_unique<Integrator>(*p->bvh_, *p->camera_, cfg, std::move(materials), std::move(lights),
                                                std::move(objectMaterial), std::move(objectId), std::move(lightId));
  *out = std::move(p);
  return Status::Ok();
}

ProviderCapabilities EmbreeProvider::Capabilities() const {
  ProviderCapabilities c;
  c.width = workWidth_;
  c.height = workHeight_;
  c.objectId = true;
  c.shaderId = true;
  c.texture = effects_.textures;
  c.normal = true;
  c.splitRadiance = effects_.textures;
  c.variance = scene_.render.samplesPerPixel > 1;
  // Point lights cast the only hard shadows, the shadow guide marks them;
  // a highlight between a block's corners is what else a probe would find.
  c.hardShadowsGuided = (!effects_.pointLights || effects_.shadowGuide) && (!effects_.plastic || effects_.highlightGuide);
  c.threadSafe = true;
  c.name = "embree";
  return c;
}

Status EmbreeProvider::Guides(const Bounds2i& region, const GuideRequest& what, GuideImage* out) {
  const Bounds2i image{{0, 0}, {workWidth_, workHeight_}};
  if (Intersect(region, image) != region) {
    return Status::Error("embree: guide region outside the working image");
  }
  out->region = region;
  const size_t n = size_t(region.area());
  out->objectId.assign(what.objectId ? n : 0, 0u);
  out->shaderId.assign(what.shaderId ? n : 0, 0u);
  const bool tau = what.texture && effects_.textures;
  out->texture.assign(what.texture ? n : 0, RGB::Gray(1.f));
  out->normal.assign(what.normal ? n : 0, Vec3f{0.f, 0.f, 0.f});
  if (!what.objectId && !what.shaderId && !tau && !what.normal) return Status::Ok();
  // Rows in parallel: primary rays are independent and deterministic.
  tbb::parallel_for(region.min.y, region.max.y, [&](int y) {
    RayCounts counts;
    std::vector<PixelGuide> row(size_t(region.width()));
    integrator_->GuideRow(y, region.min.x, region.max.x, tau, &counts, row.data());
    for (int x = region.min.x; x < region.max.x; ++x) {
      const PixelGuide& g = row[size_t(x - region.min.x)];
      size_t i = size_t(region.offset({x, y}));
      if (what.objectId) out->objectId[i] = g.objectId;
      if (what.shaderId) out->shaderId[i] = g.shaderId;
      if (tau) out->texture[i] = g.tau;
      if (what.normal) out->normal[i] = Vec3f{g.normal.x, g.normal.y, g.normal.z};
    }
    AddCounts(counts);
  });
  return Status::Ok();
}

Status EmbreeProvider::Evaluate(std::span<const Point2i> pixels, const SampleRequest& what,
                                std::span<ExactSample> out) {
  if (out.size() != pixels.size()) return Status::Error("embree: output span size differs from the pixel list");
  RayCounts counts;
  for (size_t i = 0; i < pixels.size(); ++i) {
    const Point2i p = pixels[i];
    if (p.x < 0 || p.y < 0 || p.x >= workWidth_ || p.y >= workHeight_) {
      AddCounts(counts);
      return Status::Error("embree: pixel (" + std::to_string(p.x) + ", " + std::to_string(p.y) +
                           ") outside the working image");
    }
    PixelRadiance r = integrator_->Evaluate(p.x, p.y, &counts);
    ExactSample& s = out[i];
    s.L = r.L;
    if (what.split) {
      s.Li = r.Li;
      s.Lc = r.Lc;
    }
    if (what.variance) s.variance = r.variance;
  }
  AddCounts(counts);
  return Status::Ok();
}

IntegratorConfig EmbreeProvider::PreviewConfig(int divisor) const {
  IntegratorConfig cfg = integrator_->config();
  auto fewer = [divisor](int rays) { return rays > 0 ? std::max(1, rays / divisor) : 0; };
  cfg.shadowRays = fewer(cfg.shadowRays);
  cfg.secondaryShadowRays = fewer(cfg.secondaryShadowRays);
  cfg.glossyRays = fewer(cfg.glossyRays);
  cfg.indirectRays = fewer(cfg.indirectRays);
  cfg.samplesPerPixel = 2;
  // Random numbers of its own: the preview is more samples of the same pixels.
  cfg.seed = cfg.seed ^ 0x9e3779b9u;
  return cfg;
}

Status EmbreeProvider::RenderPreview(int divisor, std::vector<ExactSample>* out) {
  if (divisor < 1) return Status::Error("embree: preview ray divisor " + std::to_string(divisor) + " (at least 1)");
  const Integrator preview(*integrator_, PreviewConfig(divisor));
  try {
    out->assign(size_t(workWidth_) * size_t(workHeight_), ExactSample{});
  } catch (const std::bad_alloc&) {
    return Status::Error("embree: no memory for a preview of " + std::to_string(workWidth_) + "x" +
                         std::to_string(workHeight_) + " pixels");
  }
  tbb::parallel_for(0, workHeight_, [&](int y) {
    RayCounts counts;
    for (int x = 0; x < workWidth_; ++x) {
      const PixelRadiance r = preview.Evaluate(x, y, &counts);
      ExactSample& s = (*out)[size_t(y) * size_t(workWidth_) + size_t(x)];
      s.L = r.L;
      s.Li = r.Li;
      s.Lc = r.Lc;
      s.variance = r.variance;
    }
    AddCounts(counts);
  });
  return Status::Ok();
}

PixelRadiance EmbreeProvider::EvaluatePixel(int x, int y) {
  RayCounts counts;
  PixelRadiance r = integrator_->Evaluate(x, y, &counts);
  AddCounts(counts);
  return r;
}

PixelGuide EmbreeProvider::GuidePixel(int x, int y, bool wantTau) {
  RayCounts counts;
  return integrator_->Guide(x, y, wantTau && effects_.textures, &counts);
}

void EmbreeProvider::AddCounts(const RayCounts& c) {
  counters_[0].fetch_add(c.primary, std::memory_order_relaxed);
  counters_[1].fetch_add(c.guide, std::memory_order_relaxed);
  counters_[2].fetch_add(c.shadow, std::memory_order_relaxed);
  counters_[3].fetch_add(c.glossy, std::memory_order_relaxed);
  counters_[4].fetch_add(c.mirror, std::memory_order_relaxed);
  counters_[5].fetch_add(c.indirect, std::memory_order_relaxed);
}

RayCounts EmbreeProvider::rayCounts() const {
  RayCounts c;
  c.primary = counters_[0].load();
  c.guide = counters_[1].load();
  c.shadow = counters_[2].load();
  c.glossy = counters_[3].load();
  c.mirror = counters_[4].load();
  c.indirect = counters_[5].load();
  return c;
}

void EmbreeProvider::ResetRayCounts() {
  for (auto& c : counters_) c.store(0);
}

}  // namespace dcm::embree
