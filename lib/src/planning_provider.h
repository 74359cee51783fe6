// The provider a preview-planned run plans on (round_schedule.cpp) and the two
// halves of such a run, shared with the target search on the preview's
// estimate (preview_target.cpp), whose runs keep one planner across thresholds.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "dcm/reconstructor.h"
#include "dcm/round_schedule.h"
#include "dcm/sample_provider.h"
#include "guide_cache.h"

namespace dcm {

/// The display-referred squared error of a PSNR (peak 1).
inline double Mse(double psnr) { return std::pow(10.0, -psnr / 10); }

/// What the engine sees during planning: the exact provider's guides (asked
/// once per region and kind), exact samples where they are known, preview
/// samples elsewhere; it records the pixels asked for that are not known.
class PlanningProvider : public SampleProvider {
 public:
  PlanningProvider(SampleProvider& exact, SampleProvider& preview)
      : exact_(exact), preview_(preview), caps_(exact.Capabilities()) {
    // Calls come from one thread: the records below need no locks, and the
    // engine's work between calls is small next to a round of a slow renderer.
    caps_.threadSafe = false;
    const size_t n = size_t(caps_.width) * size_t(caps_.height);
    known_.assign(n, 0);
    wanted_.assign(n, 0);
    samples_.resize(n);
  }

  ProviderCapabilities Capabilities() const override { return caps_; }

  Status Guides(const Bounds2i& region, const GuideRequest& what, GuideImage* out) override {
    return guides_.Get(exact_, region, what, out);
  }

  Status Evaluate(std::span<const Point2i> pixels, const SampleRequest& what,
                  std::span<ExactSample> out) override {
    request_.split |= what.split;
    request_.variance |= what.variance;
    missing_.clear();
    for (size_t i = 0; i < pixels.size(); ++i) {
      const size_t k = Index(pixels[i]);
      if (known_[k]) {
        out[i] = samples_[k];
      } else {
        missing_.push_back(i);
        if (!wanted_[k]) {
          wanted_[k] = 1;
          wantedList_.push_back(pixels[i]);
        }
      }
    }
    if (missing_.empty()) return Status::Ok();
    std::vector<Point2i> ask(missing_.size());
    std::vector<ExactSample> got(missing_.size());
    for (size_t j = 0; j < missing_.size(); ++j) ask[j] = pixels[missing_[j]];
    Status s = preview_.Evaluate(ask, what, got);
    if (!s.ok()) return Status::Error("preview samples: " + s.message());
    for (size_t j = 0; j < missing_.size(); ++j) out[missing_[j]] = got[j];
    return Status::Ok();
  }

  /// Pixels asked for in this run that are not known exactly; clears the record.
  std::vector<Point2i> TakeWanted() {
    for (const Point2i& p : wantedList_) wanted_[Index(p)] = 0;
    return std::exchange(wantedList_, {});
  }

  /// Marks the interpolated pixels of `rec` that a round evaluated as exact
  /// (SampleReason::kRendered): they were paid for. Their values stay until
  /// FillRendered(). Returns how many.
  int64_t MarkRendered(Reconstruction* rec) const {
    int64_t kept = 0;
    for (size_t k = 0; k < known_.size(); ++k) kept += MarkOne(rec, k);
    return Counted(rec, kept);
  }

  /// MarkRendered() for `only` of the pixels.
  int64_t MarkRendered(Reconstruction* rec, std::span<const Point2i> only) const {
    int64_t kept = 0;
    for (const Point2i& p : only) kept += MarkOne(rec, Index(p));
    return Counted(rec, kept);
  }

  /// Gives the pixels MarkRendered() marked their exact values.
  void FillRendered(Reconstruction* rec) const {
    for (size_t k = 0; k < known_.size(); ++k)
      if (rec->sampleMap[k] == SampleReason::kRendered) rec->workImage[k] = samples_[k].L;
  }

  /// Whether working pixel p has been evaluated exactly.
  bool Known(const Point2i& p) const { return known_[Index(p)] != 0; }

  /// Working pixels evaluated exactly so far.
  int64_t KnownCount() const { return known_.size() - std::count(known_.begin(), known_.end(), uint8_t(0)); }

  /// Evaluates `pixels` with the exact provider in one call and keeps them,
  /// and the pixels it computed exactly besides (TakeExtraSamples) that are not
  /// known yet, while fewer than `maxKnown` pixels are known (0: no bound):
  /// later runs get them without a call, and the result keeps them.
  Status EvaluateExactly(const std::vector<Point2i>& pixels, int64_t maxKnown = 0) {
    std::vector<ExactSample> got(pixels.size());
    Status s = exact_.Evaluate(pixels, request_, got);
    if (!s.ok()) return s;
    for (size_t i = 0; i < pixels.size(); ++i) {
      const size_t k = Index(pixels[i]);
      samples_[k] = got[i];
      known_[k] = 1;
    }
    std::vector<Point2i> extra;
    std::vector<ExactSample> extraSamples;
    exact_.TakeExtraSamples(&extra, &extraSamples);
    int64_t known = maxKnown > 0 ? KnownCount() : 0;
    for (size_t i = 0; i < extra.size() && i < extraSamples.size() && (maxKnown <= 0 || known < maxKnown); ++i) {
      const Point2i p = extra[i];
      if (p.x < 0 || p.y < 0 || p.x >= caps_.width || p.y >= caps_.height) continue;
      const size_t k = Index(p);
      if (known_[k]) continue;
      samples_[k] = extraSamples[i];
      known_[k] = 1;
      ++known;
    }
    return Status::Ok();
  }

 private:
  /// Marks pixel k rendered where a round evaluated it and `rec` interpolated
  /// it. A non-finite sample stays out, as the engine keeps it out of its neighbours.
  bool MarkOne(Reconstruction* rec, size_t k) const {
    if (!known_[k] || rec->sampleMap[k] != SampleReason::kInterpolated || !IsFinite(samples_[k].L)) return false;
    rec->sampleMap[k] = SampleReason::kRendered;
    return true;
  }
  static int64_t Counted(Reconstruction* rec, int64_t kept) {
    rec->stats.byReason[size_t(SampleReason::kInterpolated)] -= kept;
    rec->stats.byReason[size_t(SampleReason::kRendered)] += kept;
    rec->stats.exactPixels += kept;
    return kept;
  }

  size_t Index(const Point2i& p) const { return size_t(p.y) * size_t(caps_.width) + size_t(p.x); }

  SampleProvider& exact_;
  SampleProvider& preview_;
  ProviderCapabilities caps_;
  SampleRequest request_;
  GuideCache guides_;
  std::vector<uint8_t> known_, wanted_;
  std::vector<ExactSample> samples_;
  std::vector<Point2i> wantedList_;
  std::vector<size_t> missing_;
};

/// The schedule's options in range, and a preview of the image's size that
/// splits the radiance where the provider does (ReconstructWithPreview's
/// preconditions); the message names what is wrong.
Status CheckPreviewSchedule(SampleProvider& exact, SampleProvider& preview, const ReconstructionOptions& options,
                            const PreviewScheduleOptions& schedule);

/// Runs the engine on `planning` and evaluates what it asks for that is not
/// known, one call per round, until nothing is asked, `schedule.maxRounds`
/// calls were made, a round would evaluate fewer than
/// `schedule.minRoundShare` of the pixels (not the first of all: `roundsBefore`
/// calls made on `planning` by earlier runs), or the result without that round
/// reaches `schedule.stopAtPsnr` (as PreviewScheduleOptions::stopAtPsnr says);
/// what is still asked becomes a
/// preview stand-in. Then finishes the run: the rendered pixels kept (not with
/// noisy samples), the interpolated ones corrected toward `preview` where it
/// carries a variance, the rendered values filled in. Counts into `stats`
/// (rounds, pixels, stand-ins, times, the correction and its estimate).
Status PlanRenderAndFinish(PlanningProvider& planning, SampleProvider& preview, const ReconstructionOptions& options,
                           const PreviewScheduleOptions& schedule, int roundsBefore, Reconstruction* out,
                           PreviewScheduleStats* stats);

/// The engine run at `options` on what `planning` knows, as a plan (no
/// progress, no progressive level): `pixels` it asks for that are not known
/// (their record cleared). Adds its time to `engineS`.
Status Plan(PlanningProvider& planning, ReconstructionOptions options, Reconstruction* out, int64_t* pixels,
            double* engineS);

/// The preview's estimate of a run at `options` whose first round is rendered
/// and no other, made before anything is: the engine run on what `planning`
/// knows, the `pixels` it asks for counted at the exact share of the preview's
/// noise though they hold the preview's values, finished as PlanRenderAndFinish
/// finishes a run. The interpolation from those noisier values errs more than
/// from the rendered ones, and a later round only adds exact pixels: so it
/// tends to err low (docs/QUALITY.md, *A coarser start*). Where the plan asks
/// for `fewerThan` pixels or more, no estimate is made (NaN). Nothing is
/// rendered; the record of wanted pixels is cleared. Adds the engine's time
/// to `engineS`.
Status PredictFirstRound(PlanningProvider& planning, SampleProvider& preview, const ReconstructionOptions& options,
                         const PreviewScheduleOptions& schedule, int64_t fewerThan, PsnrEstimate* estimate,
                         int64_t* pixels, double* engineS);

}  // namespace dcm
