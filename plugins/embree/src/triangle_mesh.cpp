#include "dcm/embree/triangle_mesh.h"

#include <cmath>

namespace dcm::embree {
namespace {

void AddQuad(TriangleMesh* m, Vec3 p0, Vec3 p1, Vec3 p2, Vec3 p3, Vec3 n) {
  uint32_t base = uint32_t(m->positions.size());
  for (Vec3 p : {p0, p1, p2, p3}) {
    m->positions.push_back(p);
    m->normals.push_back(n);
  }
  m->uvs.insert(m->uvs.end(), {Vec2{0.f, 0.f}, Vec2{1.f, 0.f}, Vec2{1.f, 1.f}, Vec2{0.f, 1.f}});
  m->indices.insert(m->indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
}

TriangleMesh Box(Vec3 a, Vec3 b) {
  TriangleMesh m;
  // Each face counter-clockwise seen from outside.
  AddQuad(&m, {a.x, a.y, b.z}, {b.x, a.y, b.z}, {b.x, b.y, b.z}, {a.x, b.y, b.z}, {0, 0, 1});   // +z
  AddQuad(&m, {b.x, a.y, a.z}, {a.x, a.y, a.z}, {a.x, b.y, a.z}, {b.x, b.y, a.z}, {0, 0, -1});  // -z
  AddQuad(&m, {b.x, a.y, b.z}, {b.x, a.y, a.z}, {b.x, b.y, a.z}, {b.x, b.y, b.z}, {1, 0, 0});   // +x
  AddQuad(&m, {a.x, a.y, a.z}, {a.x, a.y, b.z}, {a.x, b.y, b.z}, {a.x, b.y, a.z}, {-1, 0, 0});  // -x
  AddQuad(&m, {a.x, b.y, b.z}, {b.x, b.y, b.z}, {b.x, b.y, a.z}, {a.x, b.y, a.z}, {0, 1, 0});   // +y
  AddQuad(&m, {a.x, a.y, a.z}, {b.x, a.y, a.z}, {b.x, a.y, b.z}, {a.x, a.y, b.z}, {0, -1, 0});  // -y
  return m;
}

TriangleMesh Sphere(Vec3 c, float r, int segments) {
  TriangleMesh m;
  int nPhi = segments > 0 ? segments : 64;
  int nTheta = std::max(2, nPhi / 2);
  for (int j = 0; j <= nTheta; ++j) {
    float theta = kPi * float(j) / float(nTheta);
    for (int i = 0; i <= nPhi; ++i) {
      float phi = 2.f * kPi * float(i) / float(nPhi);
      Vec3 n{std::sin(theta) * std::cos(phi), std::cos(theta), -std::sin(theta) * std::sin(phi)};
      m.positions.push_back(c + n * r);
      m.normals.push_back(n);
      m.uvs.push_back({float(i) / float(nPhi), 1.f - float(j) / float(nTheta)});
    }
  }
  uint32_t row = uint32_t(nPhi + 1);
  for (uint32_t j = 0; j < uint32_t(nTheta); ++j) {
    for (uint32_t i = 0; i < uint32_t(nPhi); ++i) {
      uint32_t a = j * row + i, b = a + 1, cc = a + row, d = cc + 1;
      if (j != 0) m.indices.insert(m.indices.end(), {a, cc, b});
      if (j + 1 != uint32_t(nTheta)) m.indices.insert(m.indices.end(), {b, cc, d});
    }
  }
  return m;
}

TriangleMesh Cylinder(Vec3 from, Vec3 to, float r, bool caps, int segments) {
  TriangleMesh m;
  int n = segments > 0 ? segments : 32;
  Vec3 axis = to - from;
  Frame f(Normalize(axis));
  for (int i = 0; i <= n; ++i) {
    float phi = 2.f * kPi * float(i) / float(n);
    Vec3 dir = f.s * std::cos(phi) + f.t * std::sin(phi);
    for (int k = 0; k < 2; ++k) {
      m.positions.push_back((k ? to : from) + dir * r);
      m.normals.push_back(dir);
      m.uvs.push_back({float(i) / float(n), float(k)});
    }
  }
  for (uint32_t i = 0; i < uint32_t(n); ++i) {
    uint32_t a = 2 * i, b = a + 1, c = a + 2, d = a + 3;
    m.indices.insert(m.indices.end(), {a, c, b, b, c, d});
  }
  if (caps) {
    for (int k = 0; k < 2; ++k) {
      Vec3 centre = k ? to : from;
      Vec3 nrm = k ? f.n : -f.n;
      uint32_t base = uint32_t(m.positions.size());
      m.positions.push_back(centre);
      m.normals.push_back(nrm);
      m.uvs.push_back({0.5f, 0.5f});
      for (int i = 0; i < n; ++i) {
        float phi = 2.f * kPi * float(i) / float(n);
        float cs = std::cos(phi), sn = std::sin(phi);
        m.positions.push_back(centre + (f.s * cs + f.t * sn) * r);
        m.normals.push_back(nrm);
        m.uvs.push_back({0.5f + 0.5f * cs, 0.5f + 0.5f * sn});
      }
      for (uint32_t i = 0; i < uint32_t(n); ++i) {
        uint32_t a = base + 1 + i, b = base + 1 + (i + 1) % uint32_t(n);
        if (k) m.indices.insert(m.indices.end(), {base, a, b});
        else m.indices.insert(m.indices.end(), {base, b, a});
      }
    }
  }
  return m;
}

Vec3 RotateXYZ(Vec3 v, Vec3 deg) {
  const float k = kPi / 180.f;
  float cx = std::cos(deg.x * k), sx = std::sin(deg.x * k);
  float cy = std::cos(deg.y * k), sy = std::sin(deg.y * k);
  float cz = std::cos(deg.z * k), sz = std::sin(deg.z * k);
  v = {v.x, cx * v.y - sx * v.z, sx * v.y + cx * v.z};
  v = {cy * v.x + sy * v.z, v.y, -sy * v.x + cy * v.z};
  v = {cz * v.x - sz * v.y, sz * v.x + cz * v.y, v.z};
  return v;
}

}  // namespace

TriangleMesh MakeParallelogram(Vec3 origin, Vec3 edgeU, Vec3 edgeV) {
  TriangleMesh m;
  AddQuad(&m, origin, origin + edgeU, origin + edgeU + edgeV, origin + edgeV,
          Normalize(Cross(edgeU, edgeV)));
  return m;
}

TriangleMesh TessellateShape(const ObjectDesc& o) {
  switch (o.shape) {
    case ShapeKind::kQuad: return MakeParallelogram(o.origin, o.edgeU, o.edgeV);
    case ShapeKind::kBox: return Box(o.boxMin, o.boxMax);
    case ShapeKind::kSphere: return Sphere(o.center, o.radius, o.segments);
    case ShapeKind::kCylinder: return Cylinder(o.from, o.to, o.radius, o.caps, o.segments);
    case ShapeKind::kMesh: break;
  }
  return {};
}

void ApplyTransform(const TransformDesc& t, TriangleMesh* mesh) {
  if (t.scale == Vec3{1.f, 1.f, 1.f} && t.rotateDeg == Vec3{} && t.translate == Vec3{}) return;
  for (Vec3& p : mesh->positions) p = RotateXYZ(p * t.scale, t.rotateDeg) + t.translate;
  Vec3 inv{1.f / t.scale.x, 1.f / t.scale.y, 1.f / t.scale.z};
  for (Vec3& n : mesh->normals) n = Normalize(RotateXYZ(n * inv, t.rotateDeg));
  // A mirroring scale (odd number of negative factors) flips the winding.
  if (t.scale.x * t.scale.y * t.scale.z < 0.f) {
    for (size_t i = 0; i + 2 < mesh->indices.size(); i += 3) std::swap(mesh->indices[i + 1], mesh->indices[i + 2]);
  }
}

}  // namespace dcm::embree
