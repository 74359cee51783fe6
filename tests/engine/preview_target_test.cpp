// A PSNR target judged by the preview's estimate: the ladder stops at the
// first threshold whose estimated lower bound reaches the target, renders
// each pixel once, and refuses a preview that cannot tell.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "dcm/preview_correction.h"
#include "dcm/preview_target.h"
#include "planning_provider.h"
#include "run_helpers.h"

namespace dcm::testing {
namespace {

constexpr int M = 128;

/// Counts what the exact provider is asked for: each pixel at most once.
class CountingProvider : public SampleProvider {
 public:
  explicit CountingProvider(SampleProvider& inner) : inner_(inner), asked_(size_t(M) * M, 0) {}
  ProviderCapabilities Capabilities() const override { return inner_.Capabilities(); }
  Status Guides(const Bounds2i& r, const GuideRequest& w, GuideImage* out) override { return inner_.Guides(r, w, out); }
  Status Evaluate(std::span<const Point2i> pixels, const SampleRequest& what, std::span<ExactSample> out) override {
    ++calls;
    for (const Point2i& p : pixels) maxAsked = std::max(maxAsked, int(++asked_[size_t(p.y) * M + size_t(p.x)]));
    pixelsAsked += int64_t(pixels.size());
    return inner_.Evaluate(pixels, what, out);
  }
  int calls = 0, maxAsked = 0;
  int64_t pixelsAsked = 0;

 private:
  SampleProvider& inner_;
  std::vector<uint8_t> asked_;
};

/// The truth plus Gaussian noise of sd `sd`, with that variance.
ImagePreviewProvider NoisyPreview(const std::vector<RGB>& truth, float sd, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.f, sd);
  std::vector<RGB> L = truth, var(truth.size(), RGB::Gray(sd * sd));
  for (RGB& v : L) v = {v.r + noise(rng), v.g + noise(rng), v.b + noise(rng)};
  return ImagePreviewProvider(M, M, M, M, std::move(L), {}, {}, std::move(var));
}

/// The full render's own display PSNR against the truth where each pixel
/// keeps `share` of the preview's variance sd^2: the truth plus noise of that
/// variance (another draw than the preview's).
double RenderPsnrTruth(const std::vector<RGB>& truth, float sd, double share) {
  std::mt19937 rng(101);
  std::normal_distribution<float> noise(0.f, float(sd * std::sqrt(share)));
  std::vector<RGB> L = truth;
  for (RGB& v : L) v = {v.r + noise(rng), v.g + noise(rng), v.b + noise(rng)};
  return DisplayPsnr(L, truth);
}

/// The render's own PSNR as reported at the end (the share through the
/// display at the result's values) lies within 0.2 dB of the truth and
/// closer than `scaled`, the preview's display noise scaled by the share,
/// which the display's curve bends by 0.2-0.4 dB at these noise levels.
/// 0.2 dB: one draw of noise over 128^2 pixels varies the truth by about
/// 0.03 dB, the estimate's values by as little.
void ExpectRenderPsnrNearTheTruth(double reported, double scaled, double truth) {
  EXPECT_NEAR(reported, truth, 0.2);
  EXPECT_LT(std::abs(reported - truth), std::abs(scaled - truth))
      << "reported " << reported << ", from the preview's display noise " << scaled;
}

QualityGoal Goal(double targetPsnr, double budget = 0) {
  QualityGoal g;
  g.targetPsnr = targetPsnr;
  g.budget = budget;
  return g;
}

ReconstructionOptions Options() {
  ReconstructionOptions o;
  o.textureSplit = false;
  return o;
}

TEST(PreviewTarget, TheTargetIsReachedAndEstimatedHonestlyRenderingEachPixelOnce) {
  // The analytic furnished scene, its preview the truth plus noise of sd
  // 0.01 (its own PSNR about 40 dB), exact samples noise-free. 36 dB is
  // reached at the ladder's first run (about 40.6 dB true), 42 after a few.
  AnalyticProvider truth(M, M, FurnishedScene(M, M));
  const std::vector<RGB> ref = truth.FullRender();
  double lastFraction = 0;
  for (double target : {36.0, 42.0}) {
    ImagePreviewProvider preview = NoisyPreview(ref, 0.01f, 3);
    PreviewScheduleOptions schedule;
    ASSERT_TRUE(CanTargetFromPreview(preview, schedule));
    CountingProvider exact(truth);
    Reconstruction r;
    QualityReport report;
    PreviewTargetStats stats;
    const Status s = ReconstructToTargetFromPreview(exact, preview, Options(), Goal(target), schedule, &r, &report, &stats);
    ASSERT_TRUE(s.ok()) << s.message();
    const double psnr = DisplayPsnr(r.image, ref);
    ASSERT_TRUE(report.targetReached) << target << " dB: estimated " << report.estimate.low;
    EXPECT_EQ(report.estimateSource, EstimateSource::kPreview);
    EXPECT_GE(report.estimate.low, target);
    // The bounds: the truth at least the target less 0.5 dB, the
    // estimate within 1.5 dB of it.
    EXPECT_GE(psnr, target - 0.5) << "estimated " << report.estimate.psnr;
    EXPECT_NEAR(report.estimate.psnr, psnr, 1.5);
    // Each pixel rendered once, and every one counted in the cost.
    EXPECT_EQ(exact.maxAsked, 1);
    EXPECT_EQ(exact.pixelsAsked, report.exactPixels);
    EXPECT_EQ(exact.calls, stats.rounds);
    EXPECT_EQ(r.stats.exactPixels, report.exactPixels);
    // The ladder steps down, each run finer than the one before, and stops
    // at the first whose bound reaches the target.
    for (size_t k = 1; k < stats.thresholds.size(); ++k) {
      EXPECT_LT(stats.thresholds[k], stats.thresholds[k - 1]);
      EXPECT_LT(stats.estimates[k - 1].low, target) << "run " << k - 1 << " had reached it";
    }
    EXPECT_EQ(report.threshold, stats.thresholds.back());
    // A higher target costs at least as many exact pixels.
    EXPECT_GE(report.exactFraction(), lastFraction) << target << " dB";
    lastFraction = report.exactFraction();
  }
}

TEST(PreviewTarget, ATargetFarBelowTheStartStartsWhereThePreviewPredictsIt) {
  // A clean preview (sd 0.002, its own PSNR about 54 dB) judges the plans
  // well. 30 dB lies far below what the ladder's start (three times the
  // default threshold) gives: the ladder climbs an octave at a time while
  // the preview predicts the first round's result 1 dB above the target and
  // the plan shrinks, and starts there, with fewer exact pixels than the
  // start would render, still at the target in truth. 50 dB: no climb.
  AnalyticProvider truth(M, M, FurnishedScene(M, M));
  const std::vector<RGB> ref = truth.FullRender();
  const double start = 3 * double(0.14f);  // kStartFactor times the final-resolution default (a float)
  for (double target : {30.0, 50.0}) {
    ImagePreviewProvider preview = NoisyPreview(ref, 0.002f, 9);
    PreviewScheduleOptions schedule;
    CountingProvider exact(truth);
    Reconstruction r;
    QualityReport report;
    PreviewTargetStats stats;
    const Status s = ReconstructToTargetFromPreview(exact, preview, Options(), Goal(target), schedule, &r, &report, &stats);
    ASSERT_TRUE(s.ok()) << s.message();
    ASSERT_FALSE(stats.predictions.empty()) << target << " dB";
    EXPECT_DOUBLE_EQ(stats.predictions.front().threshold, 2 * start);
    // The climb: each accepted prediction passed by the margin with fewer
    // pixels than the one below it; the one that ended it did not.
    double climbed = start;
    int64_t fewest = INT64_MAX;
    for (const PreviewTargetStats::Prediction& p : stats.predictions) {
      if (p.estimate.low >= target + 1 && p.pixels < fewest) {
        EXPECT_EQ(climbed, p.threshold / 2) << "a prediction past one that failed";
        climbed = p.threshold;
        fewest = p.pixels;
      }
    }
    EXPECT_EQ(stats.thresholds.front(), climbed) << target << " dB";
    EXPECT_EQ(exact.maxAsked, 1);
    const double psnr = DisplayPsnr(r.image, ref);
    EXPECT_TRUE(report.targetReached);
    EXPECT_GE(psnr, target) << target << " dB: estimated " << report.estimate.psnr;
    // What the start alone would have rendered (the ladder's first run, as before the climb).
    CountingProvider atStart(truth);
    PreviewScheduleOptions first = schedule;
    first.stopAtPsnr = target;
    ReconstructionOptions o = Options();
    o.contrastThreshold = float(start);
    Reconstruction startRun;
    ASSERT_TRUE(ReconstructWithPreview(atStart, preview, o, first, &startRun).ok());
    if (target == 30) {
      EXPECT_GT(climbed, start);
      EXPECT_LT(report.exactPixels, atStart.pixelsAsked);
    } else {
      EXPECT_EQ(climbed, start) << "the preview predicted " << stats.predictions.front().estimate.low;
      EXPECT_GE(report.exactPixels, atStart.pixelsAsked);
    }
    std::printf("target %.0f dB: start %.2f, %lld exact pixels (the start: %lld), %.2f dB true, estimated %.2f; "
                "predicted at %.2f: %.2f dB\n",
                target, climbed, static_cast<long long>(report.exactPixels),
                static_cast<long long>(atStart.pixelsAsked), psnr, report.estimate.psnr,
                stats.predictions.front().threshold, stats.predictions.front().estimate.psnr);
  }
}

TEST(PreviewTarget, ATargetTheLadderCannotReachIsReportedNotReached) {
  // 80 dB on a scene whose interpolation errs well above it: every run of
  // the ladder is made, and the result says the target is missed.
  AnalyticProvider truth(M, M, FurnishedScene(M, M));
  const std::vector<RGB> ref = truth.FullRender();
  ImagePreviewProvider preview = NoisyPreview(ref, 0.01f, 4);
  Reconstruction r;
  QualityReport report;
  PreviewTargetStats stats;
  ASSERT_TRUE(ReconstructToTargetFromPreview(truth, preview, Options(), Goal(80), {}, &r, &report, &stats).ok());
  EXPECT_FALSE(report.targetReached);
  EXPECT_LT(report.estimate.low, 80);
  EXPECT_GE(stats.thresholds.size(), 3u) << "the ladder stops only at its end or a plateau";
  EXPECT_EQ(r.image.size(), ref.size());
}

TEST(PreviewTarget, ATargetBeyondTheRendersOwnNoiseIsSearchedForUnlessADefaultGoal) {
  // Exact samples said to keep half the preview's variance (sd 0.01: about
  // 40 + 3 dB with every pixel exact): 45 dB lies beyond what the render
  // itself would reach, as the preview estimates it before the first round.
  AnalyticProvider truth(M, M, FurnishedScene(M, M));
  const std::vector<RGB> ref = truth.FullRender();
  ImagePreviewProvider preview = NoisyPreview(ref, 0.01f, 6);
  PreviewScheduleOptions schedule;
  schedule.exactVarianceShare = 0.5;
  const double defaultThreshold = double(ResolveSettings(Options(), truth.Capabilities()).contrastThreshold);
  // A default goal (searchBeyondRender false): one run at the default
  // threshold, reported not reached, with the limit.
  QualityGoal asDefault = Goal(45);
  asDefault.searchBeyondRender = false;
  Reconstruction one;
  QualityReport oneReport;
  PreviewTargetStats stats;
  ASSERT_TRUE(ReconstructToTargetFromPreview(truth, preview, Options(), asDefault, schedule, &one, &oneReport, &stats).ok());
  EXPECT_TRUE(stats.beyondRender);
  EXPECT_NEAR(stats.renderPsnrAtStart, PreviewNoisePsnr(preview) + 10 * std::log10(2.0), 1e-9);
  ExpectRenderPsnrNearTheTruth(stats.renderPsnr, stats.renderPsnrAtStart, RenderPsnrTruth(ref, 0.01f, 0.5));
  EXPECT_LT(stats.renderPsnr, 45 + 0.5);
  ASSERT_EQ(stats.thresholds.size(), 1u);
  EXPECT_EQ(stats.thresholds[0], defaultThreshold);
  EXPECT_FALSE(oneReport.targetReached);
  EXPECT_EQ(oneReport.renderEstimate.psnr, stats.renderPsnr);
  // Asked for (the default of QualityGoal): that estimate of the limit can
  // err low, so the ladder runs from its coarse start as for any target,
  // until it reaches the target, stops rising or ends, and buys more.
  Reconstruction r;
  QualityReport report;
  ASSERT_TRUE(ReconstructToTargetFromPreview(truth, preview, Options(), Goal(45), schedule, &r, &report, &stats).ok());
  EXPECT_TRUE(stats.beyondRender);
  ASSERT_GE(stats.thresholds.size(), 2u);
  EXPECT_GT(stats.thresholds[0], defaultThreshold);
  const size_t n = stats.estimates.size();
  const bool plateau = n >= 3 && stats.estimates[n - 1].psnr < stats.estimates[n - 2].psnr + 0.1 &&
                       stats.estimates[n - 2].psnr < stats.estimates[n - 3].psnr + 0.1;
  EXPECT_TRUE(report.targetReached || plateau || n == 7) << n << " runs, last " << stats.estimates.back().psnr;
  EXPECT_GT(report.exactFraction(), oneReport.exactFraction());
  EXPECT_GT(report.estimate.psnr, oneReport.estimate.psnr);
  for (size_t i = 0; i < n; ++i)
    std::printf("run %zu: threshold %.4f, estimated %.2f dB\n", i, stats.thresholds[i], stats.estimates[i].psnr);
  // Not reached, the run kept is the one estimated best: here the exact
  // samples' assumed noise makes the finest runs estimate worse, so it is
  // an earlier run, whose result holds fewer exact pixels than were rendered.
  const auto top = std::max_element(stats.estimates.begin(), stats.estimates.end(),
                                    [](const PsnrEstimate& a, const PsnrEstimate& b) { return a.psnr < b.psnr; });
  EXPECT_EQ(report.estimate.psnr, top->psnr);
  EXPECT_EQ(report.threshold, stats.thresholds[size_t(top - stats.estimates.begin())]);
  if (top + 1 != stats.estimates.end()) {
    const auto exactInResult = std::count_if(r.sampleMap.begin(), r.sampleMap.end(),
                                             [](SampleReason s) {
                                               return s != SampleReason::kInterpolated && s != SampleReason::kPreviewStandIn;
                                             });
    EXPECT_LT(exactInResult, report.exactPixels);
  }
  // 35 dB leaves room: not beyond.
  ASSERT_TRUE(ReconstructToTargetFromPreview(truth, preview, Options(), Goal(35), schedule, &r, &report, &stats).ok());
  EXPECT_FALSE(stats.beyondRender);
  EXPECT_GT(stats.thresholds[0], defaultThreshold);
}

TEST(PreviewTarget, ARoundTheTargetDoesNotNeedIsNotRendered) {
  // The rounds after the first ask for the pixels whose choice the exact
  // values changed. Where the result without such a round, its pixels left at
  // their preview value, already estimates at the target, the round's render
  // call buys nothing: the run stops with that very result.
  AnalyticProvider truth(M, M, FurnishedScene(M, M));
  const std::vector<RGB> ref = truth.FullRender();
  ImagePreviewProvider preview = NoisyPreview(ref, 0.01f, 8);
  auto run = [&](int maxRounds, double stopAtPsnr, Reconstruction* r, PreviewScheduleStats* stats) {
    CountingProvider exact(truth);
    PreviewScheduleOptions schedule;
    schedule.maxRounds = maxRounds;
    schedule.stopAtPsnr = stopAtPsnr;
    ASSERT_TRUE(ReconstructWithPreview(exact, preview, Options(), schedule, r, stats).ok());
    EXPECT_EQ(exact.calls, stats->rounds);
  };
  Reconstruction all, one, stopped, unreachable;
  PreviewScheduleStats allStats, oneStats, stoppedStats, unreachableStats;
  run(3, 0, &all, &allStats);
  ASSERT_GE(allStats.rounds, 2) << "the scene must want a second round";
  run(1, 0, &one, &oneStats);
  ASSERT_GT(oneStats.previewStandIns, 0);
  // The round's pixels are taken at a display error of 0.1 each besides the
  // estimate: the target that the first round's result meets so.
  const double met = -10 * std::log10(std::pow(10.0, -oneStats.correction.estimate.low / 10) +
                                      double(oneStats.previewStandIns) / (double(M) * M) * 0.01);
  ASSERT_LT(met, oneStats.correction.estimate.low);
  // A little more: the round is rendered.
  Reconstruction more;
  PreviewScheduleStats moreStats;
  run(3, met + 0.01, &more, &moreStats);
  EXPECT_GE(moreStats.rounds, 2);
  // That target: one round, the first round's result bit for bit.
  run(3, met - 1e-9, &stopped, &stoppedStats);
  EXPECT_EQ(stoppedStats.rounds, 1);
  EXPECT_TRUE(stoppedStats.stoppedAtTarget);
  EXPECT_EQ(stoppedStats.previewStandIns, oneStats.previewStandIns);
  EXPECT_EQ(stopped.image, one.image);
  EXPECT_GE(stoppedStats.correction.estimate.low, oneStats.correction.estimate.low);
  // A target no result meets: every round, as without one.
  run(3, 99, &unreachable, &unreachableStats);
  EXPECT_EQ(unreachableStats.rounds, allStats.rounds);
  EXPECT_FALSE(unreachableStats.stoppedAtTarget);
  EXPECT_EQ(unreachable.image, all.image);
  std::printf("%d rounds without a target; one at %.2f dB (estimated %.2f, low %.2f, %lld stand-ins)\n",
              allStats.rounds, met, oneStats.correction.estimate.psnr, oneStats.correction.estimate.low,
              static_cast<long long>(oneStats.previewStandIns));
}

TEST(PreviewTarget, AShareMeasuredOnTheRoundsReplacesTheRatioOfSamples) {
  // The ratio of samples says the exact pixels keep half the preview's
  // variance; the rounds measure a tenth of that (as a stratified sampler's
  // faster convergence would). The limit is decided before any round with
  // the ratio, and reported with the measurement: 10 dB apart.
  AnalyticProvider truth(M, M, FurnishedScene(M, M));
  CountingProvider exact(truth);
  ImagePreviewProvider preview = NoisyPreview(truth.FullRender(), 0.01f, 6);
  PreviewScheduleOptions schedule;
  schedule.exactVarianceShare = 0.5;
  schedule.measuredExactVarianceShare = [&exact] { return exact.calls > 0 ? 0.05 : std::nan(""); };
  EXPECT_EQ(ExactVarianceShare(schedule), 0.5) << "nothing measured yet";
  Reconstruction r;
  QualityReport report;
  PreviewTargetStats stats;
  QualityGoal goal = Goal(45);
  goal.searchBeyondRender = false;  // one run each: the same pixels, two estimates
  ASSERT_TRUE(ReconstructToTargetFromPreview(exact, preview, Options(), goal, schedule, &r, &report, &stats).ok());
  EXPECT_EQ(ExactVarianceShare(schedule), 0.05);
  const double own = PreviewNoisePsnr(preview);
  EXPECT_NEAR(stats.renderPsnrAtStart, own + 10 * std::log10(2.0), 1e-9);
  EXPECT_TRUE(stats.beyondRender) << "decided on the ratio: " << stats.renderPsnrAtStart;
  ExpectRenderPsnrNearTheTruth(stats.renderPsnr, own + 10 * std::log10(20.0),  // at the measured share
                               RenderPsnrTruth(truth.FullRender(), 0.01f, 0.05));
  EXPECT_EQ(report.renderEstimate.psnr, stats.renderPsnr);
  // The exact pixels' share of the estimated error shrinks with their noise.
  PreviewScheduleOptions assumed;
  assumed.exactVarianceShare = 0.5;
  Reconstruction r2;
  QualityReport report2;
  ASSERT_TRUE(ReconstructToTargetFromPreview(truth, preview, Options(), goal, assumed, &r2, &report2).ok());
  // The same run (the correction weighs the exact samples' noise at each share; the pixels are the same).
  EXPECT_EQ(r2.sampleMap, r.sampleMap) << "the same run";
  EXPECT_GT(report.estimate.psnr, report2.estimate.psnr);
  // Neither zero nor a negative or non-finite measurement replaces the ratio.
  for (double bad : {0.0, -1.0, HUGE_VAL}) {
    schedule.measuredExactVarianceShare = [bad] { return bad; };
    EXPECT_EQ(ExactVarianceShare(schedule), 0.5) << bad;
  }
}

/// The truth plus Gaussian noise of sd `sd` * 2^(halvings / 2), fixed per
/// pixel and halving: a renderer's exact pixels at 1/2^halvings of their
/// samples (without the variance capability: the engine takes them as clean).
class HalvingProvider : public SampleProvider {
 public:
  HalvingProvider(SampleProvider& truth, float sd) : truth_(truth), sd_(sd) {}
  ProviderCapabilities Capabilities() const override { return truth_.Capabilities(); }
  Status Guides(const Bounds2i& r, const GuideRequest& w, GuideImage* out) override { return truth_.Guides(r, w, out); }
  Status Evaluate(std::span<const Point2i> pixels, const SampleRequest& what, std::span<ExactSample> out) override {
    DCM_RETURN_IF_ERROR(truth_.Evaluate(pixels, what, out));
    const float sd = sd_ * std::sqrt(float(1 << halvings));
    for (size_t i = 0; i < pixels.size(); ++i) {
      std::mt19937 rng(uint32_t(pixels[i].y * M + pixels[i].x) * 16u + uint32_t(halvings));
      std::normal_distribution<float> noise(0.f, sd);
      out[i].L = {out[i].L.r + noise(rng), out[i].L.g + noise(rng), out[i].L.b + noise(rng)};
    }
    return Status::Ok();
  }
  int halvings = 0;
  int calls = 0;  ///< of the halving callback

 private:
  SampleProvider& truth_;
  float sd_;
};

TEST(PreviewTarget, ExactPixelsTakeFewerSamplesWhereAFullRenderAtAsFewWouldStillLeaveTheTargetItsMargin) {
  // A preview of sd 0.01 (about 40 dB) and exact pixels at 1/64 of its
  // variance (a render of 64 times its samples: about 58 dB with every pixel
  // exact). Each halving of the exact samples adds that render's own squared
  // error once more; a goal allows the halvings whose sum stays within a
  // fifth of its own squared error (1 - 10^-0.1), never noisier than the preview.
  AnalyticProvider truth(M, M, FurnishedScene(M, M));
  const std::vector<RGB> ref = truth.FullRender();
  ImagePreviewProvider preview = NoisyPreview(ref, 0.01f, 8);
  auto expected = [](double renderPsnr, double target, double share, int most) {
    int j = 0;
    while (j < most && share * double(2 << j) <= 1 &&
           double((2 << j) - 1) * std::pow(10.0, -renderPsnr / 10) <= (1 - std::pow(10.0, -0.1)) * std::pow(10.0, -target / 10))
      ++j;
    return j;
  };
  for (const auto& [target, most] : std::vector<std::pair<double, int>>{{36, 8}, {36, 2}, {47, 8}}) {
    HalvingProvider exact(truth, 0.01f / 8);
    PreviewScheduleOptions schedule;
    schedule.exactVarianceShare = 1.0 / 64;
    schedule.maxExactSampleHalvings = most;
    schedule.halveExactSamples = [&exact](int j) {
      ++exact.calls;
      exact.halvings = j;
      return Status::Ok();
    };
    Reconstruction r;
    QualityReport report;
    PreviewTargetStats stats;
    ASSERT_TRUE(ReconstructToTargetFromPreview(exact, preview, Options(), Goal(target), schedule, &r, &report, &stats).ok());
    EXPECT_NEAR(stats.renderPsnrAtStart, PreviewNoisePsnr(preview) + 10 * std::log10(64.0), 1e-9);
    const int j = expected(stats.renderPsnrAtStart, target, 1.0 / 64, most);
    EXPECT_EQ(stats.exactSampleHalvings, j) << target << " dB, at most " << most;
    EXPECT_EQ(exact.calls, j > 0 ? 1 : 0);
    EXPECT_EQ(exact.halvings, j);
    // 36 dB leaves room for at least two (the render about 53 dB from the
    // converged image, display-referred); 47 dB, within reach of the render,
    // for none: a fifth of its squared error is less than the render's.
    EXPECT_FALSE(stats.beyondRender);
    std::printf("target %.0f dB, at most %d: %d halvings (the render %.2f dB)\n", target, most, j,
                stats.renderPsnrAtStart);
    if (target == 36) EXPECT_GE(j, 2);
    else EXPECT_EQ(j, 0);
    // The noisier exact pixels still give the target (less the 0.5
    // dB) and an estimate within 1.5 dB of the truth, the render's own
    // noise reported for all of the samples.
    const double psnr = DisplayPsnr(r.image, ref);
    if (report.targetReached) {
      EXPECT_GE(psnr, target - 0.5) << "estimated " << report.estimate.psnr;
    }
    EXPECT_NEAR(report.estimate.psnr, psnr, 1.5);
    ExpectRenderPsnrNearTheTruth(stats.renderPsnr, stats.renderPsnrAtStart, RenderPsnrTruth(ref, 0.01f, 1.0 / 64));
  }
}

TEST(PreviewTarget, ABudgetIsNeverExceededAndBuysWhatAThresholdBuysAtItsFraction) {
  // A budget alone: one run at the threshold its plan on the preview affords.
  // The bounds: never above the budget, and the PSNR within 0.5 dB of
  // a sweep of single thresholds at the same exact fraction; the estimate
  // within 1.5 dB of the truth, as for a target.
  AnalyticProvider truth(M, M, FurnishedScene(M, M));
  const std::vector<RGB> ref = truth.FullRender();
  const double total = double(M) * M;
  // The sweep: preview-planned runs at global thresholds from 1 down by x0.7.
  std::vector<double> sweepFraction, sweepPsnr;
  for (double t = 1; t > 0.004; t *= 0.7) {
    ImagePreviewProvider preview = NoisyPreview(ref, 0.01f, 7);
    ReconstructionOptions o = Options();
    o.contrastThreshold = float(t);
    Reconstruction r;
    ASSERT_TRUE(ReconstructWithPreview(truth, preview, o, {}, &r).ok());
    sweepFraction.push_back(r.stats.exactFraction());
    sweepPsnr.push_back(DisplayPsnr(r.image, ref));
  }
  for (double budget : {0.06, 0.1, 0.2}) {
    ImagePreviewProvider preview = NoisyPreview(ref, 0.01f, 7);
    CountingProvider exact(truth);
    Reconstruction r;
    QualityReport report;
    PreviewTargetStats stats;
    const Status s = ReconstructToTargetFromPreview(exact, preview, Options(), Goal(0, budget), {}, &r, &report, &stats);
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_LE(exact.pixelsAsked, budget * total) << budget;
    EXPECT_LE(report.exactPixels, budget * total) << budget;
    EXPECT_EQ(r.stats.exactPixels, report.exactPixels);
    EXPECT_EQ(exact.maxAsked, 1);
    ASSERT_EQ(stats.thresholds.size(), 1u) << "one run";
    EXPECT_TRUE(report.targetReached) << "no target";
    EXPECT_TRUE(report.budgetBound) << budget;
    EXPECT_EQ(report.estimateSource, EstimateSource::kPreview);
    EXPECT_EQ(report.validationPixels, 0);
    const double psnr = DisplayPsnr(r.image, ref);
    EXPECT_NEAR(report.estimate.psnr, psnr, 1.5) << budget;
    // The sweep at this fraction, interpolated in log fraction between the
    // runs around it.
    const double f = report.exactFraction();
    double atFraction = NAN;
    for (size_t k = 1; k < sweepFraction.size(); ++k)
      if (sweepFraction[k - 1] <= f && f <= sweepFraction[k]) {
        const double a = sweepFraction[k] > sweepFraction[k - 1]
                             ? std::log(f / sweepFraction[k - 1]) / std::log(sweepFraction[k] / sweepFraction[k - 1])
                             : 0;
        atFraction = sweepPsnr[k - 1] + a * (sweepPsnr[k] - sweepPsnr[k - 1]);
      }
    ASSERT_FALSE(std::isnan(atFraction)) << "the sweep spans " << f;
    std::printf("budget %.2f: %.2f %% exact, threshold %.4f, %.2f dB (estimated %.2f), the sweep %.2f dB\n", budget,
                100 * f, report.threshold, psnr, report.estimate.psnr, atFraction);
    EXPECT_GE(psnr, atFraction - 0.5) << "budget " << budget << ", " << f << " exact";
    // Most of the budget is spent: the plan may ask for 0.9 of it.
    EXPECT_GE(report.exactPixels, 0.6 * budget * total) << budget;
  }
}

TEST(PreviewTarget, WithATargetTheBudgetEndsTheLadderWhereItBinds) {
  // 60 dB is beyond this scene's interpolation at 10 % exact: the ladder runs
  // until a run would pass the budget, which then becomes the finest within it.
  AnalyticProvider truth(M, M, FurnishedScene(M, M));
  const std::vector<RGB> ref = truth.FullRender();
  ImagePreviewProvider preview = NoisyPreview(ref, 0.01f, 8);
  CountingProvider exact(truth);
  Reconstruction r;
  QualityReport report;
  PreviewTargetStats stats;
  ASSERT_TRUE(ReconstructToTargetFromPreview(exact, preview, Options(), Goal(60, 0.1), {}, &r, &report, &stats).ok());
  EXPECT_FALSE(report.targetReached);
  EXPECT_TRUE(report.budgetBound);
  EXPECT_LE(exact.pixelsAsked, 0.1 * M * M);
  EXPECT_EQ(exact.maxAsked, 1);
  for (size_t k = 1; k < stats.thresholds.size(); ++k) EXPECT_LT(stats.thresholds[k], stats.thresholds[k - 1]);
  // The same target without a budget spends more.
  ImagePreviewProvider preview2 = NoisyPreview(ref, 0.01f, 8);
  QualityReport free;
  ASSERT_TRUE(ReconstructToTargetFromPreview(truth, preview2, Options(), Goal(60), {}, &r, &free).ok());
  EXPECT_GT(free.exactPixels, report.exactPixels);
}

TEST(PreviewTarget, ABudgetBelowTheCoarsestPlanIsAnErrorBeforeAnyPixelIsRendered) {
  AnalyticProvider truth(M, M, FurnishedScene(M, M));
  ImagePreviewProvider preview = NoisyPreview(truth.FullRender(), 0.01f, 9);
  CountingProvider exact(truth);
  Reconstruction r;
  QualityReport report;
  const Status s = ReconstructToTargetFromPreview(exact, preview, Options(), Goal(0, 0.001), {}, &r, &report);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("--budget"), std::string::npos) << s.message();
  EXPECT_EQ(exact.calls, 0);
  QualityGoal render;
  render.targetRender = true;
  render.budget = 0.1;
  EXPECT_FALSE(ReconstructToTargetFromPreview(exact, preview, Options(), render, {}, &r, &report).ok());
}

TEST(PreviewTarget, ABudgetThatHoldsTheCoarsestPlanButNotItsShareIsSpentNotRefused) {
  // The coarsest plan (threshold 16, on the preview): a budget between it and
  // it over 0.9 (the share a first run's plan may take) is a budget that a
  // single threshold's run fits; the run takes the whole of it and never
  // passes it. One pixel fewer than the plan is refused before any render.
  AnalyticProvider truth(M, M, FurnishedScene(M, M));
  const std::vector<RGB> ref = truth.FullRender();
  const double total = double(M) * M;
  int64_t coarsest = 0;
  {
    ImagePreviewProvider preview = NoisyPreview(ref, 0.01f, 10);
    PlanningProvider planning(truth, preview);
    ReconstructionOptions o = Options();
    o.contrastThreshold = 16.f;
    Reconstruction dry;
    double engineS = 0;
    ASSERT_TRUE(Plan(planning, o, &dry, &coarsest, &engineS).ok());
  }
  ASSERT_GT(coarsest, 0);
  // 5 % above the plan: its share, 0.945 of the plan, holds less than the plan.
  const int64_t pixels = coarsest + int64_t(0.05 * double(coarsest));
  ASSERT_LT(0.9 * double(pixels), double(coarsest));
  for (int64_t budgetPixels : {pixels, coarsest - 1}) {
    ImagePreviewProvider preview = NoisyPreview(ref, 0.01f, 10);
    CountingProvider exact(truth);
    Reconstruction r;
    QualityReport report;
    // The budget as a fraction whose pixels round down to budgetPixels.
    const double budget = (double(budgetPixels) + 0.5) / total;
    const Status s = ReconstructToTargetFromPreview(exact, preview, Options(), Goal(0, budget), {}, &r, &report);
    std::printf("coarsest plan %lld pixels, budget %lld: %s, %lld exact\n", static_cast<long long>(coarsest),
                static_cast<long long>(budgetPixels), s.ok() ? "spent" : s.message().c_str(),
                static_cast<long long>(report.exactPixels));
    if (budgetPixels < coarsest) {
      EXPECT_FALSE(s.ok());
      EXPECT_NE(s.message().find("--budget"), std::string::npos) << s.message();
      EXPECT_EQ(exact.calls, 0);
      continue;
    }
    ASSERT_TRUE(s.ok()) << s.message();
    EXPECT_LE(exact.pixelsAsked, budgetPixels);
    EXPECT_LE(report.exactPixels, budgetPixels);
    EXPECT_GE(report.exactPixels, coarsest) << "the coarsest plan's first round is rendered";
    EXPECT_TRUE(report.budgetBound);
  }
}

TEST(PreviewTarget, APreviewThatCannotTellIsRefusedWithTheReason) {
  AnalyticProvider truth(M, M, FurnishedScene(M, M));
  const std::vector<RGB> ref = truth.FullRender();
  std::string why;
  // sd 0.2: the preview's own PSNR about 15 dB, below the 25 the estimate needs.
  ImagePreviewProvider noisy = NoisyPreview(ref, 0.2f, 5);
  EXPECT_FALSE(CanTargetFromPreview(noisy, {}, &why));
  EXPECT_NE(why.find("too noisy"), std::string::npos) << why;
  ImagePreviewProvider clean = NoisyPreview(ref, 0.01f, 5);
  EXPECT_TRUE(CanTargetFromPreview(clean, {}, &why)) << why;
  // Out of range and without a preview variance: errors naming what.
  Reconstruction r;
  QualityReport report;
  EXPECT_FALSE(ReconstructToTargetFromPreview(truth, clean, Options(), Goal(0), {}, &r, &report).ok());
  ImagePreviewProvider noVariance(M, M, M, M, ref);
  const Status s = ReconstructToTargetFromPreview(truth, noVariance, Options(), Goal(30), {}, &r, &report);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("variance"), std::string::npos) << s.message();
}

}  // namespace
}  // namespace dcm::testing
