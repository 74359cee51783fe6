// Quality goals for renderers whose rounds cost a latency: the quality search
// with preview-planned runs, validation pixels rendered with the next round.
#include "dcm/quality_preview.h"

#include <limits>
#include <new>
#include <utility>

#include "round_keeper.h"

namespace dcm {

using detail::RoundKeeper;
using detail::RunPreview;

Status ReconstructToQualityWithPreview(SampleProvider& exact, SampleProvider& preview,
                                       const ReconstructionOptions& options, const QualityGoal& goal,
                                       const PreviewScheduleOptions& schedule, Reconstruction* out,
                                       QualityReport* report, QualityRoundStats* stats) {
  QualityRoundStats local;
  QualityRoundStats& s = stats ? *stats : local;
  s = QualityRoundStats{};
  const ProviderCapabilities caps = exact.Capabilities();
  if (caps.width <= 0 || caps.height <= 0) return Status::Error("the provider's image is empty");
  try {
    RoundKeeper keeper(exact, preview, &s);
    QualityGoal g = goal;
    constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
    PsnrEstimate lastEstimate{kNaN, kNaN, kNaN};
    // The correction's estimate of each run, from every pixel, is the validation's second judge.
    if (!g.secondEstimate) g.secondEstimate = [&] { return lastEstimate; };
    g.reconstruct = [&](SampleProvider& provider, const ReconstructionOptions& o, Reconstruction* rec,
                        std::vector<Point2i>*) {
      keeper.BeginRun();
      RunPreview view(keeper, preview, keeper.CurrentRun());
      PreviewScheduleStats runStats;
      const Status st = ReconstructWithPreview(provider, view, o, schedule, rec, &runStats);
      lastEstimate = runStats.correction.estimate;
      keeper.EndRun();
      return st;
    };
    for (;;) {
      keeper.BeginPass();
      ++s.passes;
      Reconstruction rec;
      QualityReport rep;
      const Status st = ReconstructToQuality(keeper, options, g, &rec, &rep);
      if (st.pending() && keeper.RoundDue()) continue;
      DCM_RETURN_IF_ERROR(st);
      if (keeper.Owes()) {
        // The last validation draw, which no run followed: a round of its own.
        DCM_RETURN_IF_ERROR(keeper.PayOwed());
        continue;
      }
      s.previewStandIns = rec.stats.byReason[size_t(SampleReason::kPreviewStandIn)];
      *out = std::move(rec);
      *report = std::move(rep);
      return Status::Ok();
    }
  } catch (const std::bad_alloc&) {
    return Status::Error("out of memory in the quality search on a preview");
  }
}

}  // namespace dcm
