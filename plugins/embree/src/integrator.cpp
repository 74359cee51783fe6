#include "dcm/embree/integrator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace dcm::embree {

/// What may be traced from a hit. A chain of mirrors keeps the quality of the
/// primary hit (a mirror shows a sharp image); every other bounce (glossy,
/// indirect) continues with the secondary quality: `secondaryShadowRays`, no
/// glossy rays, and one indirect bounce less.
struct Integrator::Quality {
  int lightSamples = 1;
  int glossyRays = 0;
  int indirectRays = 0;
  int indirectLeft = 0;
  int mirrorLeft = 0;
};

/// Ray differentials: the rays through the neighbouring pixel centres.
struct Integrator::Differentials {
  Vec3 ox, dx, oy, dy;
};

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

/// Texture-coordinate derivatives per pixel from ray differentials (pbrt 10.1.1):
/// intersect the offset rays with the tangent plane and solve for du, dv.
void UvDerivatives(const SurfaceHit& h, Vec3 ox, Vec3 dx, Vec3 oy, Vec3 dy, Vec2* duvdx, Vec2* duvdy,
                   Vec3* dpdx, Vec3* dpdy) {
  const Vec3 n = h.ng;
  const float d = Dot(n, h.p);
  auto onPlane = [&](Vec3 o, Vec3 dir, Vec3* out) {
    float den = Dot(n, dir);
    if (std::abs(den) < 1e-12f) return false;
    *out = o + dir * ((d - Dot(n, o)) / den);
    return true;
  };
  Vec3 px, py;
  if (!onPlane(ox, dx, &px) || !onPlane(oy, dy, &py)) {
    *duvdx = *duvdy = {0.f, 0.f};
    *dpdx = *dpdy = Vec3{};
    return;
  }
  *dpdx = px - h.p;
  *dpdy = py - h.p;
  // Least squares in the two coordinates where the normal is smallest.
  int a0 = 1, a1 = 2;
  if (std::abs(n.x) > std::abs(n.y) && std::abs(n.x) > std::abs(n.z)) {
    a0 = 1; a1 = 2;
  } else if (std::abs(n.y) > std::abs(n.z)) {
    a0 = 0; a1 = 2;
  } else {
    a0 = 0; a1 = 1;
  }
  float m00 = h.dpdu[a0], m01 = h.dpdv[a0], m10 = h.dpdu[a1], m11 = h.dpdv[a1];
  float det = m00 * m11 - m01 * m10;
  if (std::abs(det) < 1e-20f) {
    *duvdx = *duvdy = {0.f, 0.f};
    return;
  }
  auto solve = [&](Vec3 dp) {
    float b0 = dp[a0], b1 = dp[a1];
    Vec2 r{(m11 * b0 - m01 * b1) / det, (m00 * b1 - m10 * b0) / det};
    if (!std::isfinite(r.x) || !std::isfinite(r.y)) r = {0.f, 0.f};
    return r;
  };
  *duvdx = solve(*dpdx);
  *duvdy = solve(*dpdy);
}

}  // namespace

uint32_t ChainId(const uint32_t* ids, int count) {
  if (count == 1) return ids[0];
  uint32_t h = 0x2545f491u;
  for (int i = 0; i < count; ++i) h = HashU32(h ^ (ids[i] * 0x9e3779b9u + uint32_t(i)));
  return 0x80000000u | h;
}

Integrator::Integrator(const EmbreeScene& bvh, const Camera& camera, IntegratorConfig config,
                       std::vector<Material> materials, std::vector<Light> lights,
                       std::vector<int> objectMaterial, std::vector<uint32_t> objectId,
                       std::vector<uint32_t> lightId)
    : bvh_(bvh),
      camera_(camera),
      cfg_(config),
      materials_(std::move(materials)),
      lights_(std::move(lights)),
      objectMaterial_(std::move(objectMaterial)),
      objectId_(std::move(objectId)),
      lightId_(std::move(lightId)) {}

RGB Integrator::Emission(const SurfaceHit& h) const {
  return h.front ? lights_[size_t(h.light)].radiance : RGB{};
}

RGB Integrator::TauAt(const SurfaceHit& h, const Material& m, const Differentials* diff) const {
  if (!m.texture) return RGB::Gray(1.f);
  TexCoord tc{h.uv, {0.f, 0.f}, {0.f, 0.f}};
  if (diff) {
    Vec3 dpdx, dpdy;
    UvDerivatives(h, diff->ox, diff->dx, diff->oy, diff->dy, &tc.duvdx, &tc.duvdy, &dpdx, &dpdy);
  }
  return m.texture->Eval(tc);
}

void Integrator::DirectLight(const SurfaceHit& h, Vec3 wo, const Material& m, int samples,
                             int glossyRays, Pcg32& rng, RayCounts* counts, Shading* out) const {
  const Vec3 org = EmbreeScene::Offset(h.p, h.ng);
  const bool glossy = m.glossy();
  const Vec3 wr = Reflect(-wo, h.ns);
  for (const Light& light : lights_) {
    if (light.kind == LightKind::kPoint) {
      PointLightRay r;
      if (!FacesPointLight(h, org, light, &r)) continue;
      ++counts->shadow;
      if (!Unoccluded(org, r)) continue;
      const Vec3 wi = r.wi;
      RGB E = light.intensity * (r.cosS / (r.dist * r.dist));
      out->diffuse += E * (1.f / kPi);
      if (glossy) out->constant += m.specular * E * PhongLobe(wr, wi, m.exponent);
      continue;
    }
    // Rect light: `samples` stratified points (a rotated Hammersley set).
    const float rx = rng.Next(), ry = rng.Next();
    const bool mis = glossy && glossyRays > 0 && light.visible;
    for (int i = 0; i < samples; ++i) {
      Vec3 y = light.PointAt(StratifiedSample2D(uint32_t(i), uint32_t(samples), rx, ry));
      Vec3 toLight = y - org;
      float dist = Length(toLight);
      if (dist <= 0.f) continue;
      Vec3 wi = toLight / dist;
      float cosL = -Dot(wi, light.normal);
      float cosS = Dot(h.ns, wi);
      if (cosL <= 0.f || cosS <= 0.f || Dot(h.ng, wi) <= 0.f) continue;
      ++counts->shadow;
      // Stop short of the light's own rectangle, which is in the BVH when visible.
      if (bvh_.Occluded(org, wi, 0.f, dist * (1.f - 1e-4f))) continue;
      float pdfL = light.PdfSolidAngle(dist, cosL);
      RGB contrib = light.radiance * (cosS / (pdfL * float(samples)));
      out->diffuse += contrib * (1.f / kPi);
      if (glossy) {
        float w = 1.f;
        if (mis) {
          float pdfB = PhongPdf(wr, wi, m.exponent);
          w = float(samples) * pdfL / (float(samples) * pdfL + float(glossyRays) * pdfB);
        }
        out->constant += m.specular * contrib * (PhongLobe(wr, wi, m.exponent) * w);
      }
    }
  }
}

Integrator::Shading Integrator::Shade(const SurfaceHit& h, Vec3 wo, const Material& m, const Quality& q,
                                      const Differentials* diff, Pcg32& rng, RayCounts* counts) const {
  Shading s;
  if (m.kind == MaterialKind::kMirror) {
    if (q.mirrorLeft <= 0) return s;
    Vec3 dir = Normalize(Reflect(-wo, h.ns));
    if (Dot(dir, h.ng) <= 0.f) return s;
    Quality next = q;
    next.mirrorLeft--;
    ++counts->mirror;
    Vec3 org = EmbreeScene::Offset(h.p, h.ng);
    if (diff) {
      // Reflect the differential rays as if the mirror were planar around h.
      Vec2 duvdx, duvdy;
      Vec3 dpdx, dpdy;
      UvDerivatives(h, diff->ox, diff->dx, diff->oy, diff->dy, &duvdx, &duvdy, &dpdx, &dpdy);
      Differentials nd{org + dpdx, Normalize(Reflect(diff->dx, h.ns)), org + dpdy,
                       Normalize(Reflect(diff->dy, h.ns))};
      s.constant = m.specular * TraceMirror(org, dir, next, &nd, rng, counts);
    } else {
      s.constant = m.specular * TraceMirror(org, dir, next, nullptr, rng, counts);
    }
    return s;
  }

  const int glossyRays = m.glossy() ? q.glossyRays : 0;
  DirectLight(h, wo, m, q.lightSamples, glossyRays, rng, counts, &s);

  Quality secondary;
  secondary.lightSamples = cfg_.secondaryShadowRays;
  secondary.glossyRays = 0;
  secondary.indirectLeft = std::max(0, q.indirectLeft - 1);
  secondary.indirectRays = secondary.indirectLeft > 0 ? 1 : 0;
  secondary.mirrorLeft = q.mirrorLeft;

  const Vec3 org = EmbreeScene::Offset(h.p, h.ng);
  if (glossyRays > 0) {
    const Vec3 wr = Normalize(Reflect(-wo, h.ns));
    const Frame lobe(wr);
    const float rx = rng.Next(), ry = rng.Next();
    const float e = m.exponent;
    for (int j = 0; j < glossyRays; ++j) {
      Vec3 wi = lobe.ToWorld(SamplePhongLobe(StratifiedSample2D(uint32_t(j), uint32_t(glossyRays), rx, ry), e));
      float cosS = Dot(h.ns, wi);
      if (cosS <= 0.f || Dot(h.ng, wi) <= 0.f) continue;  // below the surface: no light
      ++counts->glossy;
      // f * cos / pdf of the normalised Phong lobe sampled exactly.
      RGB weight = m.specular * ((e + 2.f) / (e + 1.f) * cosS / float(glossyRays));
      SurfaceHit g;
      if (!bvh_.Intersect(org, wi, 0.f, kInf, &g)) {
        s.constant += weight * cfg_.background;
      } else if (g.light >= 0) {
        if (!g.front) continue;
        const Light& light = lights_[size_t(g.light)];
        float pdfL = light.PdfSolidAngle(g.t, -Dot(wi, light.normal));
        float pdfB = PhongPdf(wr, wi, e);
        float w = float(glossyRays) * pdfB / (float(q.lightSamples) * pdfL + float(glossyRays) * pdfB);
        s.constant += weight * light.radiance * w;
      } else {
        s.constant += weight * Reflected(g, wi, secondary, nullptr, rng, counts);
      }
    }
  }

  if (q.indirectRays > 0) {
    const Frame frame(h.ns);
    const float rx = rng.Next(), ry = rng.Next();
    const float inv = 1.f / float(q.indirectRays);
    for (int k = 0; k < q.indirectRays; ++k) {
      Vec3 wi = frame.ToWorld(SampleCosineHemisphere(StratifiedSample2D(uint32_t(k), uint32_t(q.indirectRays), rx, ry)));
      if (Dot(h.ng, wi) <= 0.f) continue;
      ++counts->indirect;
      SurfaceHit g;
      if (!bvh_.Intersect(org, wi, 0.f, kInf, &g)) {
        s.diffuse += cfg_.background * inv;
      } else if (g.light < 0) {
        // Light hit directly is counted by the light samples; only reflected light here.
        s.diffuse += Reflected(g, wi, secondary, nullptr, rng, counts) * inv;
      }
    }
  }
  return s;
}

RGB Integrator::Reflected(const SurfaceHit& h, Vec3 dir, const Quality& q, const Differentials* diff,
                          Pcg32& rng, RayCounts* counts) const {
  const Material& m = materials_[size_t(objectMaterial_[size_t(h.object)])];
  Shading s = Shade(h, -dir, m, q, diff, rng, counts);
  if (!m.diffuse()) return s.constant;
  return m.color * TauAt(h, m, diff) * s.diffuse + s.constant;
}

RGB Integrator::TraceMirror(Vec3 org, Vec3 dir, const Quality& q, const Differentials* diff, Pcg32& rng,
                            RayCounts* counts) const {
  SurfaceHit h;
  if (!bvh_.Intersect(org, dir, 0.f, kInf, &h)) return cfg_.background;
  if (h.light >= 0) return Emission(h);
  return Reflected(h, dir, q, diff, rng, counts);
}

PixelRadiance Integrator::Evaluate(int x, int y, RayCounts* counts) const {
  PixelRadiance r;
  Pcg32 rng(PixelSeed(x, y, cfg_.seed));
  const CameraRay cr = camera_.Generate(x, y);
  ++counts->primary;
  SurfaceHit h;
  if (!bvh_.Intersect(cr.origin, cr.dir, 0.f, kInf, &h)) {
    r.L = r.Lc = cfg_.background;
    return r;
  }
  if (h.light >= 0) {
    r.L = r.Lc = Emission(h);
    return r;
  }
  Quality q;
  q.lightSamples = cfg_.shadowRays;
  q.glossyRays = cfg_.glossyRays;
  q.indirectLeft = cfg_.indirectBounces;
  q.indirectRays = cfg_.indirectBounces > 0 ? cfg_.indirectRays : 0;
  q.mirrorLeft = cfg_.mirrorDepth;
  const Differentials diff{cr.origin, cr.dirDx, cr.origin, cr.dirDy};
  const Material& m = materials_[size_t(objectMaterial_[size_t(h.object)])];
  if (m.diffuse()) r.tau = TauAt(h, m, &diff);
  // samplesPerPixel independent estimates from one random stream; their mean
  // is the sample, the spread of the estimates gives its variance.
  const int n = std::max(1, cfg_.samplesPerPixel);
  double sumLi[3] = {}, sumLc[3] = {}, sumL[3] = {}, sumL2[3] = {};
  for (int k = 0; k < n; ++k) {
    const Shading s = Shade(h, -cr.dir, m, q, &diff, rng, counts);
    const RGB li = m.diffuse() ? m.color * s.diffuse : RGB{};
    const RGB l = li * r.tau + s.constant;
    for (int c = 0; c < 3; ++c) {
      sumLi[c] += li[c], sumLc[c] += s.constant[c];
      sumL[c] += l[c], sumL2[c] += double(l[c]) * l[c];
    }
  }
  if (n == 1) {
    r.Li = RGB(float(sumLi[0]), float(sumLi[1]), float(sumLi[2]));
    r.Lc = RGB(float(sumLc[0]), float(sumLc[1]), float(sumLc[2]));
  } else {
    for (int c = 0; c < 3; ++c) {
      r.Li[c] = float(sumLi[c] / n);
      r.Lc[c] = float(sumLc[c] / n);
      const double mean = sumL[c] / n;
      // Unbiased sample variance of one estimate, divided by n: the variance of the mean.
      r.variance[c] = float(std::max(0.0, sumL2[c] - n * mean * mean) / (double(n - 1) * n));
    }
  }
  r.L = r.Li * r.tau + r.Lc;
  return r;
}

PixelGuide Integrator::Guide(int x, int y, bool wantTau, RayCounts* counts) const {
  const CameraRay cr = camera_.Generate(x, y);
  ++counts->guide;
  SurfaceHit h;
  if (!bvh_.Intersect(cr.origin, cr.dir, 0.f, kInf, &h)) return PixelGuide{};
  return GuideFromHit(cr, h, wantTau, counts);
}

void Integrator::GuideRow(int y, int x0, int x1, bool wantTau, RayCounts* counts, PixelGuide* out) const {
  const size_t n = size_t(std::max(0, x1 - x0));
  std::vector<CameraRay> rays(n);
  std::vector<Vec3> dirs(n);
  // Ray differentials only filter textures: without tau they are not needed.
  camera_.GenerateRow(y, x0, x1, wantTau, rays.data());
  for (size_t i = 0; i < n; ++i) dirs[i] = rays[i].dir;
  std::vector<SurfaceHit> hits(n);
  std::vector<uint8_t> found(n);
  if (n > 0) bvh_.IntersectCoherent(rays[0].origin, dirs, hits, found);
  counts->guide += uint64_t(n);
  for (size_t i = 0; i < n; ++i) out[i] = found[i] ? GuideFromHit(rays[i], hits[i], wantTau, counts) : PixelGuide{};
}

PixelGuide Integrator::GuideFromHit(const CameraRay& cr, SurfaceHit h, bool wantTau, RayCounts* counts) const {
  PixelGuide g;
  if (wantTau && h.light < 0) {
    const Material& m = materials_[size_t(objectMaterial_[size_t(h.object)])];
    if (m.diffuse()) {
      const Differentials diff{cr.origin, cr.dirDx, cr.origin, cr.dirDy};
      g.tau = TauAt(h, m, &diff);
    }
  }
  // Follow the mirror chain: the IDs of what the mirrors show (paper 2.2).
  constexpr int kMaxChain = 65;
  uint32_t objects[kMaxChain], shaders[kMaxChain];
  int n = 0;
  Vec3 dir = cr.dir;
  const uint32_t lightShaderBase = uint32_t(materials_.size()) + 1;
  for (;;) {
    if (h.light >= 0) {
      g.normal = Vec3{0.f, 0.f, 0.f};
      objects[n] = lightId_[size_t(h.light)];
      shaders[n] = lightShaderBase + uint32_t(h.light);
      ++n;
      break;
    }
    const int mat = objectMaterial_[size_t(h.object)];
    g.normal = h.ns;
    objects[n] = objectId_[size_t(h.object)];
    shaders[n] = uint32_t(mat) + 1;
    ++n;
    if (materials_[size_t(mat)].kind != MaterialKind::kMirror || n > cfg_.mirrorDepth || n >= kMaxChain) {
      // A hard shadow's edge is a surface change, and a shadow thinner than
      // the lattice a thin object: the lights the surface sees are part of
      // its identity (the surface shown, at the end of a mirror chain).
      if (cfg_.shadowGuide) {
        if (const uint32_t lit = PointLightVisibility(h, counts)) {
          objects[n - 1] = objects[n - 1] * 2654435761u + lit;
          shaders[n - 1] = shaders[n - 1] * 2654435761u + lit;
        }
      }
      // A highlight smaller than the lattice would hide inside a smooth
      // block: its footprint is a surface of its own (as the AOV path's
      // highlight guide; the top bit stays ChainId's).
      if (cfg_.highlightGuide && InHighlight(h, dir)) {
        objects[n - 1] ^= 0x05EBCA6Bu;
        shaders[n - 1] ^= 0x05EBCA6Bu;
      }
      break;
    }
    Vec3 next = Normalize(Reflect(dir, h.ns));
    if (Dot(next, h.ng) <= 0.f) break;
    ++counts->guide;
    Vec3 org = EmbreeScene::Offset(h.p, h.ng);
    dir = next;
    if (!bvh_.Intersect(org, dir, 0.f, kInf, &h)) {
      g.normal = Vec3{0.f, 0.f, 0.f};
      objects[n] = 0;
      shaders[n] = 0;
      ++n;
      break;
    }
  }
  g.objectId = ChainId(objects, n);
  g.shaderId = ChainId(shaders, n);
  return g;
}

uint32_t Integrator::PointLightVisibility(const SurfaceHit& h, RayCounts* counts) const {
  const Vec3 org = EmbreeScene::Offset(h.p, h.ng);
  uint32_t lit = 0;
  for (size_t l = 0; l < lights_.size() && l < 32; ++l) {
    PointLightRay r;
    if (lights_[l].kind != LightKind::kPoint || !FacesPointLight(h, org, lights_[l], &r)) continue;
    ++counts->guide;
    if (Unoccluded(org, r)) lit |= 1u << l;
  }
  return lit;
}

bool Integrator::InHighlight(const SurfaceHit& h, Vec3 dir) const {
  const Material& m = materials_[size_t(objectMaterial_[size_t(h.object)])];
  if (!m.glossy()) return false;
  const Vec3 org = EmbreeScene::Offset(h.p, h.ng);
  const Vec3 wr = Normalize(Reflect(dir, h.ns));
  RGB glossy;
  constexpr int kGrid = 4;
  // Light from the point `y` of `light`: a point light's intensity, or a
  // rect light's radiance times its cosine at y and a 1/kGrid^2 of its area.
  auto add = [&](Vec3 y, const Light& light) {
    const Vec3 toLight = y - org;
    const float dist = Length(toLight);
    if (!(dist > 0.f)) return;
    const Vec3 wi = toLight / dist;
    RGB intensity = light.intensity;
    if (light.kind != LightKind::kPoint) {
      const float cosL = -Dot(wi, light.normal);
      if (cosL <= 0.f) return;
      intensity = light.radiance * (cosL * light.area / float(kGrid * kGrid));
    }
    const float cosS = Dot(h.ns, wi);
    if (cosS <= 0.f || Dot(h.ng, wi) <= 0.f) return;
    glossy += m.specular * intensity * (cosS / (dist * dist) * PhongLobe(wr, wi, m.exponent));
  };
  for (const Light& light : lights_) {
    if (light.kind == LightKind::kPoint) {
      add(light.position, light);
      continue;
    }
    for (int j = 0; j < kGrid; ++j)
      for (int i = 0; i < kGrid; ++i) add(light.PointAt({(float(i) + 0.5f) / kGrid, (float(j) + 0.5f) / kGrid}), light);
  }
  return glossy.r + glossy.g + glossy.b > kHighlightLevel;
}

bool Integrator::FacesPointLight(const SurfaceHit& h, Vec3 org, const Light& light, PointLightRay* r) const {
  const Vec3 toLight = light.position - org;
  r->dist = Length(toLight);
  if (r->dist <= 0.f) return false;
  r->wi = toLight / r->dist;
  r->cosS = Dot(h.ns, r->wi);
  return !(r->cosS <= 0.f || Dot(h.ng, r->wi) <= 0.f);  // (a NaN normal still traces, as before)
}

bool Integrator::Unoccluded(Vec3 org, const PointLightRay& r) const {
  return !bvh_.Occluded(org, r.wi, 0.f, r.dist * (1.f - 1e-4f));
}

}  // namespace dcm::embree
