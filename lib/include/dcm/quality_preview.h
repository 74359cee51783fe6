// Quality goals (a PSNR target, a budget of exact pixels) for renderers whose
// rounds cost a latency (a Blender render call, a POV-Ray process): every run
// of the quality search (dcm/quality_target.h) is planned on a cheap preview
// (dcm/round_schedule.h), and the validation pixels are rendered in the same
// round as the next run's exact pixels.
#pragma once

#include <cstdint>
#include <vector>

#include "dcm/quality_target.h"
#include "dcm/round_schedule.h"

namespace dcm {

/// What the rounds of ReconstructToQualityWithPreview cost.
struct QualityRoundStats {
  int rounds = 0;                       ///< calls to the exact provider
  std::vector<int64_t> pixelsPerRound;  ///< pixels evaluated in each call
  /// Searches run: two when the first validation draw was rendered with the
  /// first run's pixels (the search then runs again, on its exact values).
  int passes = 0;
  int64_t renderedPixels = 0;   ///< distinct pixels the exact provider evaluated
  int64_t previewStandIns = 0;  ///< pixels of the result left at their preview value
  double timeExactS = 0;        ///< in the exact provider's Evaluate()
};

/// ReconstructToQuality (same goal, same report) where each run of the search
/// is ReconstructWithPreview with `schedule` (its rounds, at most
/// schedule.maxRounds): a run plans on `preview`, where it also sees the exact
/// samples rendered before it, and renders what it chose in one call per
/// round; pixels it still wants after its rounds keep their preview value,
/// and the estimate, made at exactly rendered validation pixels, sees their
/// error. The first validation draw, which comes before any run, is rendered
/// in the first run's first call: the search sees the draw's preview values
/// until then and runs again from the start once the call is made (engine
/// runs cost little next to a round; no pixel is rendered twice). Later draws
/// (where the estimate's bound falls short, and the last, independent one)
/// decide what the search does next and are a call each. The result is what
/// ReconstructToQuality gives with such runs: its estimate comes from exact
/// validation pixels only. `exact` must give a pixel the same sample whatever
/// it is asked with, and `preview` must not depend on what `exact` rendered.
Status ReconstructToQualityWithPreview(SampleProvider& exact, SampleProvider& preview,
                                       const ReconstructionOptions& options, const QualityGoal& goal,
                                       const PreviewScheduleOptions& schedule, Reconstruction* out,
                                       QualityReport* report, QualityRoundStats* stats = nullptr);

}  // namespace dcm
