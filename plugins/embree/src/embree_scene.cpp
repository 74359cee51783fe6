#include "dcm/embree/embree_scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>
#include <string>

#include "dcm/embree/mesh_loader.h"

namespace dcm::embree {
namespace {

/// Keeps the first error Embree reports on a device (user pointer: a std::string).
void OnDeviceError(void* user, RTCError code, const char* message) {
  auto* first = static_cast<std::string*>(user);
  if (first->empty()) *first = "Embree error " + std::to_string(int(code)) + ": " + (message ? message : "");
}

}  // namespace

EmbreeScene::~EmbreeScene() {
  if (scene_) rtcReleaseScene(scene_);
  if (device_) rtcReleaseDevice(device_);
}

Status EmbreeScene::AddMesh(TriangleMesh mesh, int object, int light) {
  if (mesh.indices.empty()) return Status::Ok();
  RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
  // rtcSetNewGeometryBuffer pads the buffer as Embree needs (16-byte reads).
  auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                        3 * sizeof(float), mesh.positions.size()));
  auto* idx = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                             3 * sizeof(uint32_t), mesh.triangleCount()));
  if (!v || !idx) {
    rtcReleaseGeometry(g);
    return Status::Error("Embree: cannot allocate a geometry buffer");
  }
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    v[3 * i] = mesh.positions[i].x;
    v[3 * i + 1] = mesh.positions[i].y;
    v[3 * i + 2] = mesh.positions[i].z;
  }
  std::copy(mesh.indices.begin(), mesh.indices.end(), idx);
  rtcCommitGeometry(g);
  unsigned id = unsigned(geometries_.size());
  rtcAttachGeometryByID(scene_, g, id);
  rtcReleaseGeometry(g);
  geometries_.push_back({std::move(mesh), object, light});
  return Status::Ok();
}

namespace {

/// True when p lies strictly inside the convex solid `mesh` bounds (a box, a
/// tessellated sphere, a capped cylinder): on the centroid's side of every
/// face plane, whatever the winding of the triangles.
bool InsideConvex(const TriangleMesh& mesh, Vec3 p) {
  if (mesh.positions.empty() || mesh.indices.empty()) return false;
  Vec3 c{0.f, 0.f, 0.f};
  for (const Vec3& v : mesh.positions) c = c + v;
  c = c * (1.f / float(mesh.positions.size()));
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const Vec3 a = mesh.positions[mesh.indices[t]], b = mesh.positions[mesh.indices[t + 1]],
               d = mesh.positions[mesh.indices[t + 2]];
    const Vec3 n = Cross(b - a, d - a);
    const float len = Length(n);
    if (!(len > 0.f)) continue;  // a degenerate triangle bounds nothing
    const float sc = Dot(n, c - a) / len, sp = Dot(n, p - a) / len;
    // On a face, or on the other side than the centroid: not inside.
    if (!(sc * sp > 0.f) || std::fabs(sp) < 1e-6f * std::max(1.f, Length(p))) return false;
  }
  return true;
}

/// True when every edge of `mesh` is shared by exactly two triangles (a
/// closed surface; positions compared by index, as the loader merges them).
bool Watertight(const TriangleMesh& mesh) {
  std::map<std::pair<uint32_t, uint32_t>, int> edges;
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3)
    for (int k = 0; k < 3; ++k) {
      uint32_t a = mesh.indices[t + size_t(k)], b = mesh.indices[t + size_t((k + 1) % 3)];
      if (a > b) std::swap(a, b);
      ++edges[{a, b}];
    }
  if (edges.empty()) return false;
  for (const auto& [e, n] : edges)
    if (n != 2) return false;
  return true;
}

/// Number of triangles of `mesh` the ray p + t d (t > 0) crosses
/// (Moeller-Trumbore, in double).
int Crossings(const TriangleMesh& mesh, Vec3 p, const double d[3]) {
  int n = 0;
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const Vec3 a = mesh.positions[mesh.indices[t]], b = mesh.positions[mesh.indices[t + 1]],
               c = mesh.positions[mesh.indices[t + 2]];
    const double e1[3] = {double(b.x) - a.x, double(b.y) - a.y, double(b.z) - a.z};
    const double e2[3] = {double(c.x) - a.x, double(c.y) - a.y, double(c.z) - a.z};
    const double q[3] = {d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2], d[0] * e2[1] - d[1] * e2[0]};
    const double det = e1[0] * q[0] + e1[1] * q[1] + e1[2] * q[2];
    if (std::fabs(det) < 1e-18) continue;
    const double s[3] = {double(p.x) - a.x, double(p.y) - a.y, double(p.z) - a.z};
    const double u = (s[0] * q[0] + s[1] * q[1] + s[2] * q[2]) / det;
    if (u < 0 || u > 1) continue;
    const double r[3] = {s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2], s[0] * e1[1] - s[1] * e1[0]};
    const double v = (d[0] * r[0] + d[1] * r[1] + d[2] * r[2]) / det;
    if (v < 0 || u + v > 1) continue;
    if ((e2[0] * r[0] + e2[1] * r[1] + e2[2] * r[2]) / det > 0) ++n;
  }
  return n;
}

/// True when p lies inside the closed (watertight) mesh: an odd number of
/// crossings along at least two of three skew directions (one ray may graze
/// an edge and count it twice or not at all).
bool InsideClosedMesh(const TriangleMesh& mesh, Vec3 p) {
  if (!Watertight(mesh)) return false;
  const double dirs[3][3] = {{0.5773, 0.5774, 0.5775}, {-0.6123, 0.3536, 0.7071}, {0.2673, -0.8018, 0.5345}};
  int odd = 0;
  for (const auto& d : dirs) odd += Crossings(mesh, p, d) % 2;
  return odd >= 2;
}

const char* ShapeName(ShapeKind k) {
  switch (k) {
    case ShapeKind::kBox: return "box";
    case ShapeKind::kSphere: return "sphere";
    case ShapeKind::kCylinder: return "cylinder";
    case ShapeKind::kMesh: return "closed mesh";
    default: return "object";
  }
}

}  // namespace

Status EmbreeScene::Build(const Scene& scene, std::unique_ptr<EmbreeScene>* out) {
  std::unique_ptr<EmbreeScene> s(new EmbreeScene());
  s->device_ = rtcNewDevice(nullptr);
  if (!s->device_) return Status::Error("Embree: cannot create a device");
  rtcSetDeviceErrorFunction(s->device_, OnDeviceError, &s->deviceError_);
  s->scene_ = rtcNewScene(s->device_);
  rtcSetSceneBuildQuality(s->scene_, RTC_BUILD_QUALITY_HIGH);
  const std::string prefix = scene.file.empty() ? "" : scene.file + ": ";
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const ObjectDesc& o = scene.objects[i];
    TriangleMesh mesh;
    if (o.shape == ShapeKind::kMesh) {
      DCM_RETURN_IF_ERROR(LoadMeshFile(o.file, prefix + o.path + ".file", &mesh));
    } else {
      mesh = TessellateShape(o);
    }
    ApplyTransform(o.transform, &mesh);
    // A camera inside a closed solid sees only its inside: almost certainly a
    // mistake in the scene (the solid hides everything else).
    const bool closedConvex = o.shape == ShapeKind::kBox || o.shape == ShapeKind::kSphere ||
                              (o.shape == ShapeKind::kCylinder && o.caps);
    if ((closedConvex && InsideConvex(mesh, scene.camera.position)) ||
        (o.shape == ShapeKind::kMesh && InsideClosedMesh(mesh, scene.camera.position))) {
      const Vec3 c = scene.camera.position;
      return Status::Error(prefix + "camera.position (" + std::to_string(c.x) + ", " + std::to_string(c.y) + ", " +
                           std::to_string(c.z) + ") is inside " + o.path + " (a " + ShapeName(o.shape) +
                           "): every camera ray would start inside it");
    }
    DCM_RETURN_IF_ERROR(s->AddMesh(std::move(mesh), int(i), -1));
  }
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const LightDesc& l = scene.lights[i];
    if (l.kind == LightKind::kRect && l.visible) {
      DCM_RETURN_IF_ERROR(s->AddMesh(MakeParallelogram(l.origin, l.edgeU, l.edgeV), -1, int(i)));
    }
  }
  rtcCommitScene(s->scene_);
  rtcSetDeviceErrorFunction(s->device_, nullptr, nullptr);
  if (!s->deviceError_.empty()) return Status::Error(prefix + s->deviceError_);
  *out = std::move(s);
  return Status::Ok();
}

size_t EmbreeScene::triangleCount() const {
  size_t n = 0;
  for (const auto& g : geometries_) n += g.mesh.triangleCount();
  return n;
}

Vec3 EmbreeScene::Offset(Vec3 p, Vec3 n) {
  // Relative to the magnitude of the coordinates: float spacing grows with it.
  float m = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z), 1.f});
  return p + n * (2e-5f * m);
}

namespace {
RTCRayHit MakeRayHit(Vec3 org, Vec3 dir, float tnear, float tfar) {
  RTCRayHit rh;
  rh.ray.org_x = org.x; rh.ray.org_y = org.y; rh.ray.org_z = org.z;
  rh.ray.dir_x = dir.x; rh.ray.dir_y = dir.y; rh.ray.dir_z = dir.z;
  rh.ray.tnear = tnear;
  rh.ray.tfar = tfar;
  rh.ray.mask = 0xffffffffu;
  rh.ray.flags = 0;
  rh.ray.time = 0.f;
  rh.ray.id = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  return rh;
}
}  // namespace

bool EmbreeScene::Intersect(Vec3 org, Vec3 dir, float tnear, float tfar, SurfaceHit* hit) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh = MakeRayHit(org, dir, tnear, tfar);
  rtcIntersect1(scene_, &ctx, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  Shade(rh, dir, hit);
  return true;
}

void EmbreeScene::IntersectCoherent(Vec3 org, std::span<const Vec3> dirs, std::span<SurfaceHit> hits,
                                    std::span<uint8_t> found) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  std::vector<RTCRayHit> rays(dirs.size());
  for (size_t i = 0; i < dirs.size(); ++i) rays[i] = MakeRayHit(org, dirs[i], 0.f, std::numeric_limits<float>::infinity());
  rtcIntersect1M(scene_, &ctx, rays.data(), unsigned(rays.size()), sizeof(RTCRayHit));
  for (size_t i = 0; i < dirs.size(); ++i) {
    found[i] = rays[i].hit.geomID != RTC_INVALID_GEOMETRY_ID;
    if (found[i]) Shade(rays[i], dirs[i], &hits[i]);
  }
}

void EmbreeScene::Shade(const RTCRayHit& rh, Vec3 dir, SurfaceHit* hit) const {
  const Geometry& g = geometries_[rh.hit.geomID];
  const TriangleMesh& m = g.mesh;
  const uint32_t i0 = m.indices[3 * rh.hit.primID], i1 = m.indices[3 * rh.hit.primID + 1],
                 i2 = m.indices[3 * rh.hit.primID + 2];
  const float b1 = rh.hit.u, b2 = rh.hit.v, b0 = 1.f - b1 - b2;
  const Vec3 p0 = m.positions[i0], p1 = m.positions[i1], p2 = m.positions[i2];
  hit->t = rh.ray.tfar;
  hit->p = p0 * b0 + p1 * b1 + p2 * b2;
  Vec3 ng = Normalize(Cross(p1 - p0, p2 - p0));
  Vec3 ns = m.normals.empty() ? ng : Normalize(m.normals[i0] * b0 + m.normals[i1] * b1 + m.normals[i2] * b2);
  if (Dot(ns, ng) < 0.f) ns = -ns;  // vertex normals agree with the winding only up to sign
  hit->front = Dot(ng, dir) < 0.f;
  if (!hit->front) {
    ng = -ng;
    ns = -ns;
  }
  hit->ng = ng;
  hit->ns = ns;

  Vec2 t0{0.f, 0.f}, t1{1.f, 0.f}, t2{0.f, 1.f};
  if (!m.uvs.empty()) {
    t0 = m.uvs[i0];
    t1 = m.uvs[i1];
    t2 = m.uvs[i2];
  }
  hit->uv = t0 * b0 + t1 * b1 + t2 * b2;
  // dp/du and dp/dv from the triangle's edges in position and uv (pbrt 3.6.2).
  Vec2 d02 = t0 - t2, d12 = t1 - t2;
  Vec3 dp02 = p0 - p2, dp12 = p1 - p2;
  float det = d02.x * d12.y - d02.y * d12.x;
  if (std::abs(det) < 1e-12f) {
    Frame f(ng);
    hit->dpdu = f.s;
    hit->dpdv = f.t;
  } else {
    float inv = 1.f / det;
    hit->dpdu = (dp02 * d12.y - dp12 * d02.y) * inv;
    hit->dpdv = (dp12 * d02.x - dp02 * d12.x) * inv;
  }
  hit->object = g.object;
  hit->light = g.light;
}

bool EmbreeScene::Occluded(Vec3 org, Vec3 dir, float tnear, float tfar) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRay ray;
  ray.org_x = org.x; ray.org_y = org.y; ray.org_z = org.z;
  ray.dir_x = dir.x; ray.dir_y = dir.y; ray.dir_z = dir.z;
  ray.tnear = tnear;
  ray.tfar = tfar;
  ray.mask = 0xffffffffu;
  ray.flags = 0;
  ray.time = 0.f;
  rtcOccluded1(scene_, &ctx, &ray);
  return ray.tfar < 0.f;  // set to -inf when occluded
}

}  // namespace dcm::embree
