// The quality search's rounds on a renderer with a preview: every sample
// rendered is kept with the run of the search it came in (RoundKeeper), and a
// run plans on the preview with the engine's earlier samples in it
// (RunPreview). quality_preview.cpp; apart for its tests.
#pragma once

#include <chrono>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "dcm/quality_preview.h"
#include "dcm/sample_provider.h"
#include "elapsed.h"
#include "guide_cache.h"
#include "sample_mask.h"

namespace dcm::detail {

/// Between the search and the exact provider: keeps every sample rendered
/// (with the run of the search it was rendered in) and renders what a run or
/// a later validation draw asks for in one call each. The first validation
/// draw, which the search makes before its first run whatever the samples,
/// gets preview stand-ins, owed to the first run's first round: that round
/// renders them with the run's pixels and ends the search (Status::Pending),
/// which runs again from the start on exact validation pixels.
class RoundKeeper : public SampleProvider {
 public:
  RoundKeeper(SampleProvider& exact, SampleProvider& preview, QualityRoundStats* stats)
      : exact_(exact), preview_(preview), caps_(exact.Capabilities()), stats_(stats) {
    caps_.threadSafe = false;  // the engine then calls one at a time: the records need no locks
    const size_t n = size_t(caps_.width) * size_t(caps_.height);
    epoch_.assign(n, -1);
    mask_.assign(n, 0);
    owedMark_.assign(n, 0);
    validationOnly_.assign(n, 0);
    samples_.resize(n);
  }

  ProviderCapabilities Capabilities() const override { return caps_; }

  Status Guides(const Bounds2i& region, const GuideRequest& what, GuideImage* out) override {
    return guides_.Get(exact_, region, what, out);
  }

  Status Evaluate(std::span<const Point2i> pixels, const SampleRequest& what, std::span<ExactSample> out) override {
    const uint8_t need = RequestMask(what);
    std::vector<Point2i> unknown;
    for (const Point2i& p : pixels) {
      if (!Has(p, need)) unknown.push_back(p);
      // A run's pixels are the engine's; a validation draw's stay unseen by the runs' previews.
      const size_t k = Index(p);
      validationOnly_[k] = run_ > 0 ? 0 : (epoch_[k] < 0 || validationOnly_[k] ? 1 : 0);
    }
    if (!unknown.empty()) {
      if (run_ == 0 && runs_ > 0) {
        // A validation draw after a run: what the search does next depends
        // on its values, so they are rendered now (to merge them with the
        // next run's round would render that run before the search knows it
        // wants it).
        DCM_RETURN_IF_ERROR(Render(unknown, what));
      } else if (run_ == 0) {
        // The first validation draw, before any run: its preview value stands
        // in (L only: the validation compares L) until the first run's round
        // renders it, whatever the values.
        Owe(unknown, what);
        std::vector<ExactSample> standIn(unknown.size());
        Status st = preview_.Evaluate(unknown, SampleRequest{}, standIn);
        if (!st.ok()) return Status::Error("preview samples: " + st.message());
        size_t k = 0;
        for (size_t i = 0; i < pixels.size(); ++i)
          out[i] = Has(pixels[i], need) ? samples_[Index(pixels[i])] : standIn[k++];
        return Status::Ok();
      } else if (!owed_.empty()) {
        // The search saw stand-ins: render them with this run's pixels, then start it again.
        Owe(unknown, what);
        DCM_RETURN_IF_ERROR(PayOwed());
        roundDue_ = true;
        return Status::Pending("validation pixels rendered with a run's pixels: the search runs again");
      } else {
        DCM_RETURN_IF_ERROR(Render(unknown, what));
      }
    }
    for (size_t i = 0; i < pixels.size(); ++i) out[i] = samples_[Index(pixels[i])];
    return Status::Ok();
  }

  /// The pixels the last render call computed besides those asked for, once.
  void TakeExtraSamples(std::vector<Point2i>* pixels, std::vector<ExactSample>* samples) override {
    *pixels = std::exchange(pendingExtra_, {});
    *samples = std::exchange(pendingExtraSamples_, {});
  }

  /// A new search: no run yet (what was owed is rendered by then).
  void BeginPass() {
    runs_ = 0;
    run_ = 0;
    roundDue_ = false;
  }
  /// The search starts its next run (its first is 1) / ends it.
  void BeginRun() { run_ = ++runs_; }
  void EndRun() { run_ = 0; }
  int CurrentRun() const { return runs_; }

  /// Whether the last search ended because a round rendered what it owed.
  bool RoundDue() const { return roundDue_; }
  bool Owes() const { return !owed_.empty(); }

  /// The exact sample of `p` when it was rendered before run `run` (the
  /// samples a run planned with when it first ran) and a run asked for it,
  /// else false: a pixel only validation draws asked for stays unseen, or
  /// the runs it judges would be pulled toward its value.
  bool Visible(const Point2i& p, int run, const SampleRequest& what, ExactSample* out) const {
    const size_t k = Index(p);
    const uint8_t need = RequestMask(what);
    if (epoch_[k] < 0 || epoch_[k] >= run || validationOnly_[k] || (mask_[k] & need) != need) return false;
    *out = samples_[k];
    return true;
  }

  /// Renders the owed pixels in one call.
  Status PayOwed() {
    std::vector<Point2i> owed = std::exchange(owed_, {});
    for (const Point2i& p : owed) owedMark_[Index(p)] = 0;
    const SampleRequest what = owedRequest_;
    owedRequest_ = {};
    return Render(owed, what);
  }

 private:
  size_t Index(const Point2i& p) const { return size_t(p.y) * size_t(caps_.width) + size_t(p.x); }
  bool Has(const Point2i& p, uint8_t need) const {
    const size_t k = Index(p);
    return epoch_[k] >= 0 && (mask_[k] & need) == need;
  }

  void Owe(const std::vector<Point2i>& pixels, const SampleRequest& what) {
    owedRequest_.split |= what.split;
    owedRequest_.variance |= what.variance;
    for (const Point2i& p : pixels) {
      uint8_t& mark = owedMark_[Index(p)];
      if (!mark) {
        mark = 1;
        owed_.push_back(p);
      }
    }
  }

  /// One call to the exact provider; the samples keep the run they came in
  /// (outside a run: the last run started, so that the next run sees them).
  Status Render(const std::vector<Point2i>& pixels, const SampleRequest& asked) {
    // Everything asked for so far: the engine's runs and the validation may
    // ask for different parts (the split, the variance), and a pixel is
    // rendered once.
    request_.split |= asked.split;
    request_.variance |= asked.variance;
    const SampleRequest what = request_;
    std::vector<ExactSample> got(pixels.size());
    const auto start = std::chrono::steady_clock::now();
    DCM_RETURN_IF_ERROR(exact_.Evaluate(pixels, what, got));
    stats_->timeExactS += SecondsSince(start);
    ++stats_->rounds;
    stats_->pixelsPerRound.push_back(int64_t(pixels.size()));
    const int epoch = run_ > 0 ? run_ : runs_;
    for (size_t i = 0; i < pixels.size(); ++i) {
      const size_t k = Index(pixels[i]);
      if (epoch_[k] < 0) {
        ++stats_->renderedPixels;
        epoch_[k] = epoch;
      }
      samples_[k] = got[i];
      mask_[k] = RequestMask(what);
    }
    // The pixels the call computed besides are kept as rendered (never
    // rendered again) and passed on once, to the cache above.
    std::vector<Point2i> extra;
    std::vector<ExactSample> extraSamples;
    exact_.TakeExtraSamples(&extra, &extraSamples);
    pendingExtra_.clear();
    pendingExtraSamples_.clear();
    for (size_t i = 0; i < extra.size() && i < extraSamples.size(); ++i) {
      const Point2i p = extra[i];
      if (p.x < 0 || p.y < 0 || p.x >= caps_.width || p.y >= caps_.height || epoch_[Index(p)] >= 0) continue;
      const size_t k = Index(p);
      epoch_[k] = epoch;
      samples_[k] = extraSamples[i];
      mask_[k] = RequestMask(what);
      pendingExtra_.push_back(p);
      pendingExtraSamples_.push_back(extraSamples[i]);
    }
    return Status::Ok();
  }

  SampleProvider& exact_;
  SampleProvider& preview_;
  ProviderCapabilities caps_;
  QualityRoundStats* stats_;
  GuideCache guides_;
  std::vector<int32_t> epoch_;  ///< per pixel: the run it was rendered in, -1 not rendered
  std::vector<uint8_t> mask_;   ///< what its sample holds (RequestMask)
  std::vector<ExactSample> samples_;
  std::vector<Point2i> owed_;
  std::vector<uint8_t> owedMark_;
  std::vector<uint8_t> validationOnly_;  ///< per pixel: asked for by validation draws only
  SampleRequest owedRequest_;
  SampleRequest request_;  ///< the union of the requests rendered
  std::vector<Point2i> pendingExtra_;  ///< the last call's extra pixels, for TakeExtraSamples
  std::vector<ExactSample> pendingExtraSamples_;
  int runs_ = 0, run_ = 0;
  bool roundDue_ = false;
};

/// The preview a run plans on: the exact samples earlier runs asked for
/// (RoundKeeper::Visible), the preview elsewhere. What a run sees does not depend on how
/// often the search was run again.
class RunPreview : public SampleProvider {
 public:
  RunPreview(const RoundKeeper& keeper, SampleProvider& preview, int run)
      : keeper_(keeper), preview_(preview), run_(run) {}
  ProviderCapabilities Capabilities() const override { return preview_.Capabilities(); }
  Status Guides(const Bounds2i& region, const GuideRequest& what, GuideImage* out) override {
    return preview_.Guides(region, what, out);
  }
  Status Evaluate(std::span<const Point2i> pixels, const SampleRequest& what, std::span<ExactSample> out) override {
    DCM_RETURN_IF_ERROR(preview_.Evaluate(pixels, what, out));
    ExactSample s;
    for (size_t i = 0; i < pixels.size(); ++i)
      if (keeper_.Visible(pixels[i], run_, what, &s)) out[i] = s;
    return Status::Ok();
  }

 private:
  const RoundKeeper& keeper_;
  SampleProvider& preview_;
  int run_;
};

}  // namespace dcm::detail
