// The object/shader surface test (paper 2.2 and 3.2; creases and tau = 0
// classes are dcm's): the guides turned into which pixels share a surface,
// and the test's use in the smooth/edge classification.
#include "surface_test.h"

#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>
#include <string>
#include <unordered_map>

#include "elapsed.h"
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
    // In parallel over fixed chunks of pixels: each chunk numbers its own pairs
    // in its order of first appearance, the chunks' lists taken in order
    // number them as one scan of the frame would, and each chunk then maps
    // its numbers to those. Neighbours mostly repeat the last pair: look up
    // only the changes.
    constexpr size_t kChunk = size_t(1) << 15;
    const size_t pixels = guides_.objectId.size(), chunks = (pixels + kChunk - 1) / kChunk;
    std::vector<std::vector<uint64_t>> firsts(chunks);  // each chunk's pairs, in order
    tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
      const size_t begin = c * kChunk, end = std::min(pixels, begin + kChunk);
      std::unordered_map<uint64_t, uint32_t> local;
      uint64_t lastPair = 0;
      uint32_t lastLabel = 0;
      for (size_t i = begin; i < end; ++i) {
        const uint64_t pair = (uint64_t(guides_.objectId[i]) << 32) | guides_.shaderId[i];
        if (i == begin || pair != lastPair) {
          lastPair = pair;
          const auto [it, added] = local.try_emplace(pair, uint32_t(local.size()));
          if (added) firsts[c].push_back(pair);
          lastLabel = it->second;
        }
        guides_.objectId[i] = lastLabel;
      }
    });
    std::unordered_map<uint64_t, uint32_t> labels;
    std::vector<std::vector<uint32_t>> global(chunks);  // per chunk: its numbers to the frame's
    for (size_t c = 0; c < chunks; ++c) {
      global[c].reserve(firsts[c].size());
      for (uint64_t pair : firsts[c]) global[c].push_back(labels.try_emplace(pair, uint32_t(labels.size())).first->second);
    }
    tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
      const size_t begin = c * kChunk, end = std::min(pixels, begin + kChunk);
      const uint32_t* map = global[c].data();
      for (size_t i = begin; i < end; ++i) guides_.objectId[i] = map[guides_.objectId[i]];
    });
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
      const RGB* tau = tau_.data();
      uint8_t* zero = tauZero_.data();
      for (size_t i = r.begin(); i < r.end(); ++i) zero[i] = uint8_t(TauZero(tau[i]));
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
  changes_ = AdjacentChanges{};
  if (surfaces_.enabled()) {
    changes_ = surfaces_.BuildChanges(width_, height_);
    surfaces_ = SurfaceTest(obj, shader, crease_.empty() ? nullptr : crease_.data(), width_,
                            tauZero_.empty() ? nullptr : tauZero_.data(), regions_.labels.empty() ? nullptr : &regions_,
                            &changes_);
  }
}

namespace {
/// Some bit of [lo, hi] (lo <= hi) is set in the row of 64-bit words.
bool AnyBit(const uint64_t* row, int lo, int hi) {
  const int w0 = lo >> 6, w1 = hi >> 6;
  const uint64_t first = ~uint64_t(0) << (lo & 63), last = ~uint64_t(0) >> (63 - (hi & 63));
  if (w0 == w1) return (row[w0] & first & last) != 0;
  if (row[w0] & first) return true;
  for (int w = w0 + 1; w < w1; ++w)
    if (row[w]) return true;
  return (row[w1] & last) != 0;
}
}  // namespace

bool SurfaceTest::ChangeIn(int x0, int y0, int x1, int y1) const {
  if (changesRight_) {
    const size_t words = size_t(changesWords_);
    for (int y = y0; y <= y1; ++y) {
      if (x1 > x0 && AnyBit(changesRight_ + size_t(y) * words, x0, x1 - 1)) return true;
      if (y < y1 && AnyBit(changesBelow_ + size_t(y) * words, x0, x1)) return true;
    }
    return false;
  }
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x) {
      const int64_t i = int64_t(y) * width_ + x;
      if (x < x1 && !SameAdjacent(i, i + 1)) return true;
      if (y < y1 && !SameAdjacent(i, i + width_)) return true;
    }
  return false;
}

AdjacentChanges SurfaceTest::BuildChanges(int width, int height) const {
  AdjacentChanges c;
  c.words = (width + 63) / 64;
  c.right.assign(size_t(c.words) * size_t(height), 0);
  c.below.assign(size_t(c.words) * size_t(height), 0);
  tbb::parallel_for(0, height, [&](int y) {
    // SameAdjacent of 4-neighbours is: the same tau = 0 class, the same
    // object or (with shader IDs) the same shader, and no crease between
    // them; the cell regions join every such pair (AdjacentChanges). Each
    // condition over the row in its own loop, which the compiler vectorises.
    thread_local std::vector<uint8_t> differs;
    differs.resize(size_t(width + 7) / 8 * 8);
    const int64_t row = int64_t(y) * width;
    auto pass = [&](int64_t offset, int count, uint8_t creaseBit, uint64_t* out) {
      uint8_t* d = differs.data();
      std::fill(differs.begin(), differs.end(), uint8_t(0));
      if (tauZero_) {
        const uint8_t* t = tauZero_ + row;
        for (int x = 0; x < count; ++x) d[x] |= uint8_t(t[x] != t[x + offset]);
      }
      if (objectId_) {
        const uint32_t* o = objectId_ + row;
        if (shaderId_) {
          const uint32_t* s = shaderId_ + row;
          for (int x = 0; x < count; ++x) d[x] |= uint8_t((o[x] != o[x + offset]) & (s[x] != s[x + offset]));
        } else {
          for (int x = 0; x < count; ++x) d[x] |= uint8_t(o[x] != o[x + offset]);
        }
      }
      if (crease_) {
        const uint8_t* k = crease_ + row;
        for (int x = 0; x < count; ++x) d[x] |= uint8_t((k[x] & creaseBit) != 0);
      }
      // Eight flags (bytes of 0 or 1) at a time: the multiplication gathers
      // the low bit of byte j into bit 56 + j.
      for (int x = 0; x < count; x += 8) {
        uint64_t eight = 0;
        for (int j = 0; j < 8; ++j) eight |= uint64_t(d[x + j]) << (8 * j);
        out[x >> 6] |= ((eight * 0x0102040810204080ull) >> 56) << (x & 63);
      }
    };
    pass(1, width - 1, 1, c.right.data() + size_t(y) * size_t(c.words));
    if (y + 1 < height) pass(width, width, 2, c.below.data() + size_t(y) * size_t(c.words));
  });
  return c;
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
  stats_.timeGuidesS += SecondsSince(t0);
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
  return s.enabled() && s.ChangeIn(b.x0, b.y0, b.x1, b.y1);
}

}  // namespace dcm::detail
