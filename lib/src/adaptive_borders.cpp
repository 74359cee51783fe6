// Edge-block borders. The paper evaluates every border pixel; dcm's adaptive
// borders evaluate the ends and the surface changes of each side, bisect the
// gaps whose ends differ and fill the rest along the side, and (supersampled)
// take the crossings of the sides a level adds from the lines beside them.
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <atomic>

#include "engine.h"

namespace dcm::detail {

Status Engine::EvaluateBorders(std::vector<Block>& edges, bool belowElementary, std::vector<EdgeBlock>* eb) {
  eb->resize(edges.size());
  ForEach(edges, [&](Block& b, size_t i) {
    (*eb)[i].block = b;
    BorderLoop(b, &(*eb)[i].border);
    if (!opt_.adaptiveBorders)
      for (Point2i p : (*eb)[i].border) store_.Request(p.x, p.y, SampleReason::kBorder);
  });
  if (opt_.adaptiveBorders) DCM_RETURN_IF_ERROR(EvaluateBordersAdaptively(edges, belowElementary));
  return Flush();
}

Status Engine::EvaluateBordersAdaptively(const std::vector<Block>& edges, bool belowElementary) {
  // The sides of all edge blocks of this level, each once: blocks of one level
  // sit on one lattice, so two sides are equal or share at most an end. A side
  // is a pure function of its own samples, whichever block it borders.
  struct Side {
    Point2i a, step;
    int length;  // pixels - 1
    uint64_t key;  ///< (start pixel, vertical, length) in one integer
  };
  // Images have at most 2^30 pixels, sides at most 256 steps (Validate()).
  auto side = [&](Point2i a, Point2i step, int length) {
    return Side{a, step, length, (uint64_t(store_.Index(a.x, a.y)) << 10) | (uint64_t(step.y) << 9) | uint64_t(length)};
  };
  std::vector<Side> sides;
  for (const Block& b : edges) {
    if (b.x1 == b.x0 || b.y1 == b.y0) {
      for (int y = b.y0; y <= b.y1; ++y)
        for (int x = b.x0; x <= b.x1; ++x) store_.Request(x, y, SampleReason::kBorder);
      continue;
    }
    sides.push_back(side({b.x0, b.y0}, {1, 0}, b.x1 - b.x0));
    sides.push_back(side({b.x0, b.y1}, {1, 0}, b.x1 - b.x0));
    sides.push_back(side({b.x0, b.y0}, {0, 1}, b.y1 - b.y0));
    sides.push_back(side({b.x1, b.y0}, {0, 1}, b.y1 - b.y0));
  }
  tbb::parallel_sort(sides.begin(), sides.end(), [](const Side& l, const Side& r) { return l.key < r.key; });
  sides.erase(std::unique(sides.begin(), sides.end(), [](const Side& l, const Side& r) { return l.key == r.key; }),
              sides.end());
  auto index = [&](const Side& s, int k) { return store_.Index(s.a.x + k * s.step.x, s.a.y + k * s.step.y); };
  const SurfaceTest& surf = store_.surfaces();

  // Interleaved crossings (ReconstructionOptions::crossingFillReach): the
  // sides on the lattice lines this level adds, between two lines of the
  // level above, defer the pixels at their surface changes.
  const bool interleave = belowElementary && settings_.crossingFillReach > 0;
  auto interleaved = [&](const Side& s) {
    const int across = s.step.y ? s.a.x : s.a.y;
    return interleave && across % (2 * s.length) == s.length;
  };
  std::vector<std::vector<int>> deferred(interleave ? sides.size() : 0);  // positions along the side

  // Round 0: the ends, and both pixels of every surface change.
  ForEach(sides, [&](Side& s, size_t si) {
    for (int k = 0; k <= s.length; k += s.length) store_.Request(s.a.x + k * s.step.x, s.a.y + k * s.step.y, SampleReason::kBorder);
    const bool defer = interleaved(s);
    for (int k = 0; k < s.length; ++k)
      if (!surf.SameAdjacent(index(s, k), index(s, k + 1)))
        for (int j : {k, k + 1}) {
          if (defer && j > 0 && j < s.length) deferred[si].push_back(j);
          else store_.Request(s.a.x + j * s.step.x, s.a.y + j * s.step.y, SampleReason::kBorder);
        }
  });
  DCM_RETURN_IF_ERROR(Flush());
  // A deferred pixel on surface S takes the mean of the nearest exact pixels
  // of S on the two neighbouring lines when both exist and agree, and is
  // evaluated otherwise. Those lines are sides of the level above (exact at
  // their surface changes), and the search stays inside the two blocks the
  // side borders: both children of one parent, so a window of the frame on
  // the lattice decides as the whole frame does.
  std::vector<uint8_t> crossingFilled(interleave ? size_t(store_.width()) * size_t(store_.height()) : 0);
  if (interleave) {
    std::atomic<int64_t> filled{0};
    ForEach(sides, [&](Side& s, size_t si) {
      const Point2i across{s.step.y, s.step.x};
      for (int j : deferred[si]) {
        const int64_t ij = index(s, j);
        if (store_.IsExact(ij)) continue;
        int64_t nearest[2] = {-1, -1};
        for (int n = 0; n < 2; ++n) {
          const int sign = n ? 1 : -1;
          const Point2i line{s.a.x + sign * s.length * across.x, s.a.y + sign * s.length * across.y};
          // Beside the last, narrower blocks of a row or column the line
          // lies outside the image.
          if (line.x < 0 || line.y < 0 || line.x >= store_.width() || line.y >= store_.height()) continue;
          for (int d = 0; d <= settings_.crossingFillReach && nearest[n] < 0; ++d)
            for (int k : {j - d, j + d}) {
              if (k < 0 || k > s.length) continue;
              const int64_t ik = store_.Index(line.x + k * s.step.x, line.y + k * s.step.y);
              if (store_.IsExact(ik) && store_.IsFinite(ik) && surf.Same(ik, ij)) {
                nearest[n] = ik;
                break;
              }
            }
        }
        if (nearest[0] >= 0 && nearest[1] >= 0 &&
            !contrast_.Differ(store_.ValueAt(nearest[0]), store_.ValueAt(nearest[1]))) {
          if (record_) record_->Fill(ij, nearest[0], nearest[1], 0.5f);
          store_.SetFilled(ij, Lerp(store_.ValueAt(nearest[0]), store_.ValueAt(nearest[1]), 0.5f));
          crossingFilled[size_t(ij)] = 1;
          ++filled;
        } else {
          store_.Request(s.a.x + j * s.step.x, s.a.y + j * s.step.y, SampleReason::kBorder);
        }
      }
    });
    stats_.crossingsFilled += filled;
    DCM_RETURN_IF_ERROR(Flush());
  }
  // The pixels bisection and the fill start from: exact, or filled crossings.
  auto known = [&](int64_t i) { return store_.IsExact(i) || (interleave && crossingFilled[size_t(i)]); };
  // Bisect every gap whose known ends differ, until none is left. A side
  // that asked for nothing in a round has nothing new in the next (sides
  // share only their ends, exact since round 0): only the others are read.
  std::vector<uint8_t> active(sides.size(), 1);
  for (;;) {
    ForEach(sides, [&](Side& s, size_t i) {
      if (!active[i]) return;
      active[i] = 0;
      int last = 0;
      for (int k = 1; k <= s.length; ++k) {
        if (!known(index(s, k))) continue;
        const bool usable = store_.IsFinite(index(s, last)) && store_.IsFinite(index(s, k));
        if (k > last + 1 &&
            (!usable || contrast_.Differ(store_.ValueAt(index(s, last)), store_.ValueAt(index(s, k))))) {
          const int mid = (last + k) / 2;
          store_.Request(s.a.x + mid * s.step.x, s.a.y + mid * s.step.y, SampleReason::kBorder);
          active[i] = 1;
        }
        last = k;
      }
    });
    if (std::find(active.begin(), active.end(), uint8_t(1)) == active.end()) break;
    DCM_RETURN_IF_ERROR(Flush());
  }
  // Fill the gaps along the side from known pixels of the same surface.
  ForEach(sides, [&](Side& s, size_t) {
    int last = 0;
    for (int k = 1; k <= s.length; ++k) {
      if (!known(index(s, k))) continue;
      const int64_t i0 = index(s, last), i1 = index(s, k);
      const Value v0 = store_.ValueAt(i0), v1 = store_.ValueAt(i1);
      for (int j = last + 1; j < k; ++j) {
        const int64_t ij = index(s, j);
        const bool same0 = surf.Same(ij, i0), same1 = surf.Same(ij, i1);
        const float t = (same0 == same1) ? float(j - last) / float(k - last) : (same0 ? 0.f : 1.f);
        if (record_) record_->Fill(ij, i0, i1, t);
        store_.SetFilled(ij, Lerp(v0, v1, t));
      }
      last = k;
    }
  });
  return Status::Ok();
}

}  // namespace dcm::detail
