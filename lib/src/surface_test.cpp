// The object/shader surface test (paper 2.2 and 3.2; creases and tau = 0
// classes are dcm's): the guides turned into which pixels share a surface,
// and the test's use in the smooth/edge classification.
#include "surface_test.h"

#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>
#include <string>
#include <unordered_map>

#include "engine.h"
#include "texture_split.h"

namespace dcm::detail {

void SampleStore::SetGuides(GuideImage guides, ObjectTest test, float creaseAngle, int regionCell) {
  guides_ = std::move(guides);
  if (split_) tau_ = std::move(guides_.texture);
  if (test == ObjectTest::kObjectOrShader && !guides_.objectId.empty() &&
      guides_.shaderId.size() == guides_.objectId.size()) {
    // A surface is an (object, shader) pair: one label per pair, numbered in
    // the order of first appearance (deterministic), instead of the object ID.
    // Neighbours mostly repeat the last pair: look up only the changes.
    std::unordered_map<uint64_t, uint32_t> labels;
    uint64_t lastPair = 0;
    uint32_t lastLabel = 0;
    for (size_t i = 0; i < guides_.objectId.size(); ++i) {
      const uint64_t pair = (uint64_t(guides_.objectId[i]) << 32) | guides_.shaderId[i];
      if (i == 0 || pair != lastPair) {
        lastPair = pair;
        lastLabel = labels.try_emplace(pair, uint32_t(labels.size())).first->second;
      }
      guides_.objectId[i] = lastLabel;
    }
  }
  const uint32_t* obj = (test != ObjectTest::kNone && !guides_.objectId.empty()) ? guides_.objectId.data() : nullptr;
  const uint32_t* shader = (obj && test == ObjectTest::kObjectAndShader && !guides_.shaderId.empty())
                               ? guides_.shaderId.data() : nullptr;
  crease_.clear();
  const std::vector<Vec3f>& normal = guides_.normal;
  if (creaseAngle > 0.f && normal.size() == size_t(width_) * size_t(height_)) {
    // A crease where the angle between unit normals exceeds creaseAngle;
    // a zero or non-finite normal (background, no data) marks none.
    const double cosMax = std::cos(double(creaseAngle) * 3.14159265358979323846 / 180.0);
    auto dot = [&](size_t i, size_t j, double* out) {
      const Vec3f a = normal[i], b = normal[j];
      const double la = std::sqrt(double(a.x) * a.x + double(a.y) * a.y + double(a.z) * a.z);
      const double lb = std::sqrt(double(b.x) * b.x + double(b.y) * b.y + double(b.z) * b.z);
      if (!(la > 1e-12 && lb > 1e-12 && std::isfinite(la) && std::isfinite(lb))) return false;
      *out = (double(a.x) * b.x + double(a.y) * b.y + double(a.z) * b.z) / (la * lb);
      return true;
    };
    crease_.resize(normal.size());
    tbb::parallel_for(0, height_, [&](int y) {
      for (int x = 0; x < width_; ++x) {
        const size_t i = size_t(Index(x, y));
        double d = 0;
        uint8_t marks = 0;
        if (x + 1 < width_ && dot(i, i + 1, &d) && d < cosMax) marks |= 1;
        if (y + 1 < height_ && dot(i, i + size_t(width_), &d) && d < cosMax) marks |= 2;
        crease_[i] = marks;
      }
    });
  }
  tauZero_.clear();
  if (split_ && tau_.size() == size_t(width_) * size_t(height_)) {
    tauZero_.resize(tau_.size());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, tau_.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i < r.end(); ++i) tauZero_[i] = TauZero(tau_[i]) ? 1 : 0;
    });
  }
  regions_ = CellRegions{};
  if (!crease_.empty()) {
    // Per cell: union-find over 4-neighbours of one object (and one tau = 0
    // class) that no crease separates.
    const int e = std::max(1, regionCell);
    regions_.size = e;
    regions_.cellsX = (width_ + e - 1) / e;
    const int cellsY = (height_ + e - 1) / e;
    const size_t perCell = size_t(e + 1) * size_t(e + 1);
    regions_.labels.assign(size_t(regions_.cellsX) * size_t(cellsY) * perCell, 0u);
    tbb::parallel_for(0, cellsY, [&](int cy) {
      for (int cx = 0; cx < regions_.cellsX; ++cx) {
        uint32_t* label = regions_.labels.data() + (size_t(cy) * size_t(regions_.cellsX) + size_t(cx)) * perCell;
        for (size_t k = 0; k < perCell; ++k) label[k] = uint32_t(k);
        auto find = [&](uint32_t k) {
          while (label[k] != k) k = label[k] = label[label[k]];
          return k;
        };
        const int x0 = cx * e, y0 = cy * e;
        const int x1 = std::min(x0 + e, width_ - 1), y1 = std::min(y0 + e, height_ - 1);
        auto join = [&](size_t i, size_t j, uint32_t a, uint32_t b) {
          if (obj && obj[i] != obj[j]) return;
          if (!tauZero_.empty() && tauZero_[i] != tauZero_[j]) return;
          a = find(a), b = find(b);
          if (a != b) label[std::max(a, b)] = std::min(a, b);
        };
        for (int y = y0; y <= y1; ++y)
          for (int x = x0; x <= x1; ++x) {
            const size_t i = size_t(Index(x, y));
            const uint32_t k = uint32_t((y - y0) * (e + 1) + (x - x0));
            if (x < x1 && !(crease_[i] & 1)) join(i, i + 1, k, k + 1);
            if (y < y1 && !(crease_[i] & 2)) join(i, i + size_t(width_), k, k + uint32_t(e + 1));
          }
        for (size_t k = 0; k < perCell; ++k) label[k] = find(uint32_t(k));
      }
    });
  }
  surfaces_ = SurfaceTest(obj, shader, crease_.empty() ? nullptr : crease_.data(), width_,
                          tauZero_.empty() ? nullptr : tauZero_.data(), regions_.labels.empty() ? nullptr : &regions_);
}

bool SurfaceTest::ChangeInCell(int x0, int y0, int x1, int y1) const {
  // The cell's labels, row-major from its origin (ox, oy), stride e + 1.
  const uint32_t* cell = nullptr;
  int ox = 0, oy = 0, stride = 0;
  if (regionLabels_) {
    const int e = regionSize_, cx = x0 / e, cy = y0 / e;
    cell = regionLabels_ + size_t(cy * regionCellsX_ + cx) * size_t((e + 1) * (e + 1));
    ox = cx * e, oy = cy * e, stride = e + 1;
  }
  // Same() and no crease between i and j; `li`, `lj` index the cell's labels.
  auto same = [&](int64_t i, int64_t j, int li, int lj, uint8_t creaseBit) {
    if (tauZero_ && tauZero_[i] != tauZero_[j]) return false;
    const bool surface = (!objectId_ || objectId_[i] == objectId_[j]) ? (!cell || cell[li] == cell[lj])
                                                                       : (shaderId_ && shaderId_[i] == shaderId_[j]);
    return surface && !(crease_ && (crease_[std::min(i, j)] & creaseBit));
  };
  for (int y = y0; y <= y1; ++y) {
    const int64_t row = int64_t(y) * width_;
    const int lrow = (y - oy) * stride - ox;
    for (int x = x0; x <= x1; ++x) {
      const int64_t i = row + x;
      const int li = lrow + x;
      if (x < x1 && !same(i, i + 1, li, li + 1, 1)) return true;
      if (y < y1 && !same(i, i + width_, li, li + stride, 2)) return true;
    }
  }
  return false;
}

Status Engine::LoadGuides() {
  GuideRequest want;
  want.objectId = settings_.objectIds;
  want.shaderId = settings_.shaderIds;
  want.texture = settings_.split;
  want.normal = settings_.normals;
  stats_.usedObjectId = want.objectId;
  stats_.usedShaderId = want.shaderId;
  stats_.usedSplit = settings_.split;
  stats_.usedSupersampledRules = settings_.supersampledRules;
  stats_.usedNormals = want.normal;
  if (!want.objectId && !want.texture && !want.normal) {
    store_.SetGuides({}, ObjectTest::kNone);
    return Status::Ok();
  }
  const Bounds2i all{{0, 0}, {caps_.width, caps_.height}};
  GuideImage g;
  const auto t0 = std::chrono::steady_clock::now();
  DCM_RETURN_IF_ERROR(provider_.Guides(all, want, &g));
  stats_.timeGuidesS += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const size_t n = size_t(all.area());
  auto check = [&](bool wanted, size_t size, const char* name) {
    if (wanted && size != n)
      return Status::Error(std::string("provider '") + caps_.name + "' returned " + std::to_string(size) + " " +
                           name + " guide values for " + std::to_string(n) + " pixels");
    return Status::Ok();
  };
  DCM_RETURN_IF_ERROR(check(want.objectId, g.objectId.size(), "object ID"));
  DCM_RETURN_IF_ERROR(check(want.shaderId, g.shaderId.size(), "shader ID"));
  DCM_RETURN_IF_ERROR(check(want.texture, g.texture.size(), "texture"));
  DCM_RETURN_IF_ERROR(check(want.normal, g.normal.size(), "normal"));
  if (want.texture) RequestNonFiniteTau(g.texture, store_);
  store_.SetGuides(std::move(g), settings_.objectTest, settings_.creaseAngle, block_);
  return Status::Ok();
}

bool Engine::HasSurfaceChange(const Block& b) const {
  const SurfaceTest& s = store_.surfaces();
  if (!s.enabled()) return false;
  if (s.HoldsInOneCell(b.x0, b.y0, b.x1, b.y1)) return s.ChangeInCell(b.x0, b.y0, b.x1, b.y1);
  for (int y = b.y0; y <= b.y1; ++y)
    for (int x = b.x0; x <= b.x1; ++x) {
      const int64_t i = store_.Index(x, y);
      if (x < b.x1 && !s.SameAdjacent(i, i + 1)) return true;
      if (y < b.y1 && !s.SameAdjacent(i, i + store_.width())) return true;
    }
  return false;
}

}  // namespace dcm::detail
