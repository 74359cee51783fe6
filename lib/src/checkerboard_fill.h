// Checkerboard refinement (beyond the paper): of the pixels that the
// thin-object test or a fallback wants exact, one colour of a checkerboard is
// evaluated first. A pixel of the other colour is then filled from its exact
// 8-neighbours on its own surface when they bracket it (an opposite pair) and
// all agree with the estimate; otherwise it is evaluated too. A spindle one
// or two pixels wide, or the inside of a fallback block, is mostly smooth
// along its length: every second pixel carries the information there, while
// where the neighbours disagree (a shadow edge across the spindle, a
// highlight) the pixel is still evaluated.
#pragma once

#include "block.h"
#include "contrast_test.h"
#include "interpolation_recorder.h"
#include "sample_store.h"

namespace dcm::detail {

/// The colour of the checkerboard evaluated first: (x + y) even. A finest
/// block's centre is on it (blocks start on even lattice points).
inline bool EvaluatedFirst(int x, int y) { return ((x + y) & 1) == 0; }

/// The estimate of pixel q from its exact 8-neighbours that lie on q's surface
/// and are finite: the mean of each opposite pair of them (exact for a linear
/// ramp), axis pairs weighted 1 and diagonal pairs 1/2.
/// With `test`, false when no opposite pair exists or any of those
/// neighbours differs significantly from the estimate (weighed at its own
/// tau); without, false only when no opposite pair exists. `terms`, when
/// given, receives the neighbours and weights of the estimate.
bool NeighbourEstimate(const SampleStore& store, const ContrastTest& contrast, Point2i q, bool test, Value* out,
                       NeighbourTerms* terms = nullptr);

}  // namespace dcm::detail
