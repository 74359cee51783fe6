// Simple vs complex edge blocks (paper 2.3): the zero-order test counts the
// significant changes along the border, the first-order test compares the
// direction of the discontinuity at its two crossings, the ID test counts the
// surfaces on the border.
#pragma once

#include <span>
#include <vector>

#include "block.h"
#include "contrast_test.h"
#include "sample_store.h"

namespace dcm::detail {

/// Positions k in the closed loop where loop[k] and loop[k+1] differ
/// significantly (a crossing lies between them).
std::vector<int> SignificantChanges(const SampleStore& store, const ContrastTest& contrast,
                                    std::span<const Point2i> loop);

/// Number of surface changes between consecutive pixels of the closed loop.
int SurfaceChanges(const SampleStore& store, std::span<const Point2i> loop);

/// The pixels one step inside the border next to each crossing (two per
/// crossing), which the first-order test evaluates. With `fromGuides`, a
/// crossing that is a surface change needs none: the guides show where the
/// surfaces meet on the inner row.
std::vector<Point2i> FirstOrderProbes(const SampleStore& store, const Block& b, std::span<const Point2i> loop,
                                      std::span<const int> crossings, bool fromGuides);

/// True when the discontinuity has about the same direction at both of its two
/// crossings and along the chord between them (within 40 degrees: one inward
/// pixel step resolves directions to 45 degrees). Needs the probes evaluated.
/// With `fromGuides`, at a crossing that is a surface change the inner row's
/// pixels are compared by surface instead of by value.
bool FirstOrderConsistent(const SampleStore& store, const ContrastTest& contrast, const Block& b,
                          std::span<const Point2i> loop, std::span<const int> crossings, bool fromGuides);

}  // namespace dcm::detail
