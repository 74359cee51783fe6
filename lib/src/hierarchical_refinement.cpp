// Hierarchical refinement (paper 2.1) with the smooth/edge classification
// (2.2): each level's blocks are smooth (bilinear from their corners) or edge
// blocks; smooth blocks are refined by dcm's centre probe or, as the paper
// does, always.
#include "engine.h"

namespace dcm::detail {

bool Engine::IsSmooth(const Block& b) const {
  const Point2i p[4] = {{b.x0, b.y0}, {b.x1, b.y0}, {b.x0, b.y1}, {b.x1, b.y1}};
  for (Point2i c : p)
    if (!store_.IsFinite(store_.Index(c.x, c.y))) return false;  // never interpolate from it
  const Value corners[4] = {At(p[0]), At(p[1]), At(p[2]), At(p[3])};
  return !contrast_.IsEdge(corners) && !HasSurfaceChange(b);
}

Status Engine::ClassifySmoothOrEdge(std::vector<Block>& classify, int size, bool finest, std::vector<Block>* edges,
                                    std::vector<Block>* nextClassify, std::vector<Block>* splitSmooth) {
  const int W = store_.width(), H = store_.height();
  const SmoothRefinement refinement = settings_.smoothRefinement;
  ForEach(classify, [&](Block& b, size_t) { RequestCorners(b); });
  DCM_RETURN_IF_ERROR(Flush());
  std::vector<uint8_t> smooth(classify.size());
  ForEach(classify, [&](Block& b, size_t i) { smooth[i] = IsSmooth(b); });
  std::vector<Block> probe;
  for (size_t i = 0; i < classify.size(); ++i) {
    const Block& b = classify[i];
    if (!smooth[i]) {
      edges->push_back(b);
    } else if (finest || (b.width() <= 1 && b.height() <= 1) || refinement == SmoothRefinement::kNever) {
      smoothLeaves_.push_back(MakeLeaf(b, BlockType::kSmooth));
    } else if (refinement == SmoothRefinement::kAlways) {
      ChildBlocks(b, size / 2, W, H, nextClassify);
      splitSmooth->push_back(b);
    } else {
      probe.push_back(b);
    }
  }
  // Smoothness by prediction: the centre (a corner of the children) must
  // match the bilinear interpolation of the corners.
  if (!probe.empty()) {
    ForEach(probe, [&](Block& b, size_t) { store_.Request(b.Centre().x, b.Centre().y, SampleReason::kCorner); });
    DCM_RETURN_IF_ERROR(Flush());
    std::vector<uint8_t> split(probe.size());
    ForEach(probe, [&](Block& b, size_t i) {
      split[i] = !store_.IsFinite(store_.Index(b.Centre().x, b.Centre().y)) ||
                 contrast_.Misses(At(b.Centre()), Bilinear(store_, b, b.Centre()));
    });
    for (size_t i = 0; i < probe.size(); ++i) {
      if (split[i]) {
        ChildBlocks(probe[i], size / 2, W, H, nextClassify);
        splitSmooth->push_back(probe[i]);
      } else {
        smoothLeaves_.push_back(MakeLeaf(probe[i], BlockType::kSmooth));
      }
    }
  }
  return Status::Ok();
}

void Engine::WriteSmooth(const Leaf& leaf) {
  const Block& b = leaf.block;
  // A smooth leaf owns [x0, x1) x [y0, y1), and its last column and row at the
  // image border: leaves partition the image, so no pixel is written twice.
  const int xe = (b.x1 == store_.width() - 1 || b.x1 == b.x0) ? b.x1 : b.x1 - 1;
  const int ye = (b.y1 == store_.height() - 1 || b.y1 == b.y0) ? b.y1 : b.y1 - 1;
  // Bilinear as two linear steps in double (exact for linear ramps up to the
  // final rounding to float); the six channels are (a, b) of Value.
  double c[4][6];
  const Point2i corners[4] = {{b.x0, b.y0}, {b.x1, b.y0}, {b.x0, b.y1}, {b.x1, b.y1}};
  for (int k = 0; k < 4; ++k) {
    const Value v = At(corners[k]);
    for (int ch = 0; ch < 3; ++ch) c[k][ch] = v.a[ch], c[k][3 + ch] = v.b[ch];
  }
  const double sx = b.x1 > b.x0 ? 1.0 / (b.x1 - b.x0) : 0.0, sy = b.y1 > b.y0 ? 1.0 / (b.y1 - b.y0) : 0.0;
  // The channel count as a constant: the loops over channels unroll.
  auto fill = [&]<int channels>() {
    for (int y = b.y0; y <= ye; ++y) {
      const double v = (y - b.y0) * sy;
      double left[channels], right[channels];
      for (int ch = 0; ch < channels; ++ch) {
        left[ch] = v == 0 ? c[0][ch] : (1 - v) * c[0][ch] + v * c[2][ch];
        right[ch] = v == 0 ? c[1][ch] : (1 - v) * c[1][ch] + v * c[3][ch];
      }
      for (int x = b.x0; x <= xe; ++x) {
        const int64_t i = store_.Index(x, y);
        if (store_.IsExact(i) || store_.IsFilled(i)) continue;
        const double u = (x - b.x0) * sx;
        float f[6] = {};
        for (int ch = 0; ch < channels; ++ch) f[ch] = float(u == 0 ? left[ch] : (1 - u) * left[ch] + u * right[ch]);
        Value out;
        out.a = RGB{f[0], f[1], f[2]};
        out.b = RGB{f[3], f[4], f[5]};
        store_.SetInterpolated(i, out);
      }
    }
  };
  // (L_i, L_c) or L
  if (settings_.split) fill.template operator()<6>();
  else fill.template operator()<3>();
}

void Engine::WritePreview(int level, std::vector<Block>& splitSmooth, std::vector<EdgeBlock>& edges) {
  ForEach(smoothLeaves_, [&](Leaf& l, size_t) { WriteSmooth(l); });
  ForEach(splitSmooth, [&](Block& b, size_t) { WriteSmooth(MakeLeaf(b, BlockType::kSmooth)); });
  ForEach(edges, [&](EdgeBlock& e, size_t) {
    WriteSmooth(MakeLeaf(e.block, BlockType::kSmooth));  // where the oriented pass skips a pixel
    InterpolateOriented(MakeLeaf(e.block, BlockType::kComplexEdge, e.direction.index), OrientedPass::kPreview);
  });
  ForEach(orientedLeaves_, [&](Leaf& l, size_t) { InterpolateOriented(l, OrientedPass::kPreview); });
  opt_.onLevel(level, store_.width(), store_.height(), store_.radiance());
}

}  // namespace dcm::detail
