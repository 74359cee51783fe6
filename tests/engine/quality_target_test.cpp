// Reconstruction to a PSNR target or a budget (dcm/quality_target.h): the
// target is met, the budget is never exceeded, each pixel is evaluated once,
// and the estimate lies within its stated uncertainty of the truth.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <span>
#include <utility>
#include <vector>

#include <tbb/task_arena.h>

#include "dcm/downsample.h"
#include "dcm/quality_target.h"
#include "noisy_provider.h"
#include "run_helpers.h"
#include "threshold_sweep.h"

namespace dcm::testing {
namespace {

struct Outcome {
  Reconstruction rec;
  QualityReport report;
  double truePsnr = 0;
};

Outcome RunGoal(AnalyticProvider& provider, const ReconstructionOptions& o, const QualityGoal& goal) {
  Outcome r;
  const Status st = ReconstructToQuality(provider, o, goal, &r.rec, &r.report);
  EXPECT_TRUE(st.ok()) << st.message();
  int w = 0, h = 0;
  const std::vector<RGB> full = provider.FullRender();
  const std::vector<RGB> ref = BoxDownsample(full, r.rec.workWidth, r.rec.workHeight, o.downsample, &w, &h);
  r.truePsnr = DisplayPsnr(r.rec.image, ref);
  std::printf("target %.1f budget %.3f: estimate %.2f [%.2f, %.2f], true %.2f dB, exact %.2f %% (%d runs, threshold %g)\n",
              goal.targetPsnr, goal.budget, r.report.estimate.psnr, r.report.estimate.low, r.report.estimate.high,
              r.truePsnr, 100 * r.report.exactFraction(), r.report.runs, r.report.threshold);
  return r;
}

TEST(QualityTarget, EstimateOfAConstantErrorIsExact) {
  const PsnrEstimate e = EstimatePsnr({1e-4, 1e-4, 1e-4}, {1, 2, 3});
  EXPECT_NEAR(e.psnr, 40.0, 1e-9);
  EXPECT_NEAR(e.low, 40.0, 1e-9);
  EXPECT_NEAR(e.high, 40.0, 1e-9);
  // A spread widens the interval around the weighted mean (1e-4 + 3e-4) / 2.
  const PsnrEstimate s = EstimatePsnr({1e-4, 3e-4}, {1, 1});
  EXPECT_NEAR(s.psnr, 10 * std::log10(1 / 2e-4), 1e-9);
  EXPECT_LT(s.low, s.psnr);
  EXPECT_GT(s.high, s.psnr);
  EXPECT_TRUE(std::isnan(EstimatePsnr({}, {}).psnr));
  // Noise-corrected errors whose mean is negative: the point estimate is
  // +inf, its lower bound that of an error of 0 plus the spread, finite
  // (the spread of these terms is all the estimate knows).
  for (double total : {0.0, 3.0}) {
    const PsnrEstimate n = EstimatePsnr({-3e-4, 1e-4, -1e-4}, {1, 1, 1}, total);
    EXPECT_TRUE(std::isinf(n.psnr)) << total;
    EXPECT_TRUE(std::isfinite(n.low)) << total;
    EXPECT_GT(n.low, 30.0) << total;
  }
}

TEST(QualityTarget, EffectivePixelsCountThoseThatCarryTheEstimate) {
  // Kish: (sum w d)^2 / sum (w d)^2 over the positive errors.
  EXPECT_NEAR(EstimatePsnr({1e-4, 1e-4, 1e-4, 1e-4}, {1, 1, 1, 1}).effective, 4.0, 1e-12);
  EXPECT_NEAR(EstimatePsnr({1e-2, 0, 0, 0, 0, 0}, {1, 1, 1, 1, 1, 1}).effective, 1.0, 1e-12);
  // Weights count as the pixels they stand for; negative (noise-corrected) errors carry nothing.
  EXPECT_NEAR(EstimatePsnr({1e-4, 2e-4, -1e-4}, {2, 1, 1}, 4).effective, 2.0, 1e-12);
  EXPECT_TRUE(std::isinf(EstimatePsnr({0, 0}, {1, 1}).effective));
}

/// A smooth ramp with `spots` bright 3x3 highlights, each inside a 16-pixel
/// block away from its corners and centre, on the same surface: the lattice
/// misses them and most of the error sits in their few pixels.
SceneFunction SpottedRamp(int n, int spots) {
  return [n, spots](int x, int y) {
    PixelTruth t;
    t.Li = RGB{0.2f + 0.3f * float(x) / float(n), 0.25f, 0.2f + 0.2f * float(y) / float(n)};
    for (int k = 0; k < spots; ++k) {
      // Spread over the image by a fixed low-discrepancy sequence.
      const int bx = int(std::fmod(0.618034 * (k + 1), 1.0) * double(n / 16)), by = int(double(k) * double(n / 16) / spots);
      const int cx = bx * 16 + 4, cy = by * 16 + 11;
      if (std::abs(x - cx) <= 1 && std::abs(y - cy) <= 1) t.Li += RGB::Gray(0.6f);
    }
    return t;
  };
}

TEST(QualityTarget, FewPixelErrorsAreEstimatedWithoutBias) {
  // Twelve 3x3 highlights no threshold finds: the whole error sits in 108 of
  // 65 536 pixels, where the result shows no detail, so the importance draw
  // gives them only its uniform share (1 - kProxyShare = 0.2): a draw of 656
  // pixels misses them all with probability about
  // exp(-656 * 0.2 * 108 / 65536) = 0.8, errs high, and its interval cannot
  // cover the truth. What holds whatever the proxy is unbiasedness: the mean
  // over seeds of the estimated MSE is the true MSE of the result the search
  // judged. The result then keeps the validation pixels it interpolated (a
  // draw that hits a spot also removes it), which makes the estimate
  // conservative by what they remove: here a few of the spots' 108 pixels,
  // far less than the estimate's own spread. So the mean over seeds of the
  // estimated less the delivered MSE lies within 3 standard errors of 0.
  const int n = 256, seeds = 20;
  double sum = 0, sumSq = 0, trueSum = 0, estSum = 0;
  for (int seed = 1; seed <= seeds; ++seed) {
    AnalyticProvider provider(n, n, SpottedRamp(n, 12));
    QualityGoal goal;
    goal.targetPsnr = 40;
    goal.seed = uint64_t(seed) * 7919;
    const Outcome r = RunGoal(provider, ReconstructionOptions{}, goal);
    const double mse = std::pow(10.0, -r.report.estimate.psnr / 10), trueMse = std::pow(10.0, -r.truePsnr / 10);
    sum += mse - trueMse;
    sumSq += (mse - trueMse) * (mse - trueMse);
    trueSum += trueMse;
    estSum += mse;
  }
  const double mean = sum / seeds, se = std::sqrt((sumSq / seeds - mean * mean) / (seeds - 1));
  std::printf("mean true MSE %.3g, mean estimate %.3g (standard error of the difference %.2g)\n", trueSum / seeds,
              estSum / seeds, se);
  EXPECT_NEAR(mean, 0.0, 3 * se);
}

TEST(QualityTarget, EstimateIsWithinItsIntervalWhereTheErrorIsNearDetail) {
  // The furnished scene's error is by its edges, its thin line and its
  // highlight, which the result shows: the importance draw finds it, and the
  // stated 90 % interval covers the truth. Over 20 validation seeds, at least
  // 15 (binomial(20, 0.9): fewer in 1.1 %; the choice of the stopping run
  // on earlier draws takes a little from the nominal 0.9).
  const int n = 256, seeds = 20;
  int covered = 0, within = 0;
  for (int seed = 1; seed <= seeds; ++seed) {
    AnalyticProvider provider(n, n, FurnishedScene(n, n));
    QualityGoal goal;
    goal.targetPsnr = 40;
    goal.seed = uint64_t(seed) * 7919;
    const Outcome r = RunGoal(provider, ReconstructionOptions{}, goal);
    covered += r.truePsnr >= r.report.estimate.low && r.truePsnr <= r.report.estimate.high;
    within += std::fabs(r.truePsnr - r.report.estimate.psnr) <= 1.5;
  }
  std::printf("interval covers %d of %d; estimate within 1.5 dB on %d\n", covered, seeds, within);
  EXPECT_GE(covered, 15);
}

TEST(QualityTarget, TargetIsMetWithEachPixelEvaluatedOnce) {
  const int N = 256;
  for (double target : {35.0, 40.0}) {
    AnalyticProvider provider(N, N, FurnishedScene(N, N));
    QualityGoal goal;
    goal.targetPsnr = target;
    const Outcome r = RunGoal(provider, ReconstructionOptions{}, goal);
    EXPECT_TRUE(r.report.targetReached);
    // The lower bound reached the target; the truth may sit below the bound
    // by chance (5 %) but not by more than the issue's 0.5 dB.
    EXPECT_GE(r.truePsnr, target - 0.5);
    // The truth within the stated 90 % interval, widened by 0.25 dB for the
    // choice of the stopping run on the same validation pixels.
    EXPECT_GE(r.truePsnr, r.report.estimate.low - 0.25);
    EXPECT_LE(r.truePsnr, r.report.estimate.high + 0.25);
    EXPECT_EQ(provider.MaxEvaluationsOfOnePixel(), 1);
    EXPECT_EQ(provider.TotalEvaluations(), r.report.exactPixels);
    EXPECT_LT(r.report.exactFraction(), 1.0);
  }
}

TEST(QualityTarget, BudgetIsNeverExceeded) {
  const int N = 256;
  for (double budget : {0.03, 0.08, 0.2}) {
    AnalyticProvider provider(N, N, FurnishedScene(N, N));
    QualityGoal goal;
    goal.budget = budget;
    const Outcome r = RunGoal(provider, ReconstructionOptions{}, goal);
    EXPECT_LE(provider.TotalEvaluations(), int64_t(budget * N * N));
    EXPECT_EQ(provider.TotalEvaluations(), r.report.exactPixels);
    // The budget was used: more than half of it (the bisection stops within
    // a factor 0.85^(1/8) of the threshold the budget allows).
    EXPECT_GT(r.report.exactFraction(), budget / 2);
    EXPECT_TRUE(std::isfinite(r.report.estimate.low));
  }
}

// What a budget buys against what a user who knew the best global threshold
// for the same exact fraction would get: the best run of a sweep of
// thresholds within that fraction, and the sweep interpolated in log fraction
// between its points (which credits a fraction between two runs with a
// quality no threshold may deliver).
TEST(QualityTarget, BudgetBuysWhatTheThresholdSweepBuysAtTheSameFraction) {
  const int N = 256;
  // The issue asks for 0.5 dB of the sweep at the same fraction. The
  // validation takes a twentieth of the budget, placed at random rather than
  // where the lattice needs it: about 0.4 dB where the sweep gains 5.3 dB per
  // doubling of the pixels (3 % to 5 %). A search that stopped short of the
  // budget, or left the pixels of the runs it abandoned out of the result,
  // lost 1.7 to 3.7 dB. Interpolated, 0.75 dB (0.25 for where the sweep's
  // steps of x0.9 straddle a jump).
  constexpr double kTolerance = 0.5, kInterpolatedTolerance = 0.75;
  AnalyticProvider sweepProvider(N, N, FurnishedScene(N, N));
  const std::vector<RGB> full = sweepProvider.FullRender();
  std::vector<std::pair<double, double>> sweep;  // (exact fraction, true PSNR)
  for (double t = 1.0; t > 0.004; t *= 0.9) {
    ReconstructionOptions o;
    o.contrastThreshold = float(t);
    Reconstruction rec;
    ASSERT_TRUE(Reconstruct(sweepProvider, o, &rec).ok());
    sweep.push_back({rec.stats.exactFraction(), DisplayPsnr(rec.image, full)});
  }
  std::sort(sweep.begin(), sweep.end());
  for (double budget : {0.03, 0.05, 0.08, 0.12, 0.2}) {
    AnalyticProvider provider(N, N, FurnishedScene(N, N));
    QualityGoal goal;
    goal.budget = budget;
    const Outcome r = RunGoal(provider, ReconstructionOptions{}, goal);
    const double frontier = SweepPsnrAt(sweep, r.report.exactFraction());
    std::printf("  the sweep at %.2f %%: %.2f dB interpolated, %.2f dB by the best threshold within it\n",
                100 * r.report.exactFraction(), frontier, SweepBestWithin(sweep, r.report.exactFraction()));
    EXPECT_GE(r.truePsnr, SweepBestWithin(sweep, r.report.exactFraction()) - kTolerance) << "budget " << budget;
    EXPECT_GE(r.truePsnr, frontier - kInterpolatedTolerance) << "budget " << budget;
    // Spent: what is left buys less than the smallest step of the threshold.
    EXPECT_GT(r.report.exactFraction(), 0.9 * budget) << "budget " << budget;
  }
}

TEST(QualityTarget, BudgetBelowTheCoarsestRunIsAnErrorWithinTheBudget) {
  // 1 % of 256^2 (655 pixels): the coarsest run alone needs about 1000 (the
  // corners of the 16-pixel blocks, their centre probes, the blocks they split).
  const int N = 256;
  AnalyticProvider provider(N, N, FurnishedScene(N, N));
  QualityGoal goal;
  goal.budget = 0.01;
  Reconstruction rec;
  QualityReport report;
  const Status st = ReconstructToQuality(provider, ReconstructionOptions{}, goal, &rec, &report);
  EXPECT_FALSE(st.ok());
  EXPECT_TRUE(st.overBudget()) << st.message();  // what a caller whose budget is only a bound may drop
  EXPECT_NE(st.message().find("--budget"), std::string::npos) << st.message();
  EXPECT_LE(provider.TotalEvaluations(), int64_t(0.01 * N * N));
}

TEST(QualityTarget, UnreachableTargetReportsWhatTheBudgetReached) {
  const int N = 256;
  AnalyticProvider provider(N, N, FurnishedScene(N, N));
  QualityGoal goal;
  goal.targetPsnr = 70;
  goal.budget = 0.05;
  const Outcome r = RunGoal(provider, ReconstructionOptions{}, goal);
  EXPECT_FALSE(r.report.targetReached);
  EXPECT_TRUE(r.report.budgetBound);
  EXPECT_LE(provider.TotalEvaluations(), int64_t(0.05 * N * N));
}

TEST(QualityTarget, ConfirmingDrawsThatFindTheTargetMissedSpendTheBudget) {
  // A ramp, which every run reconstructs exactly, with an error that hides
  // from the search: every run above the threshold tHidden is off by 0.05 at
  // each pixel nobody had evaluated before it ran, so the search's own
  // validation pixels see no error and each confirming draw, made after the
  // run, sees it. Without a budget the
  // descent stops after kMaxConfirmations (3) runs and says the target was
  // missed; with one, it goes on until the budget binds, here until a run
  // below tHidden meets the target.
  const int N = 256;
  const double tHidden = 0.14 * std::pow(0.7, 4);  // below what three runs from the default reach
  for (double budget : {0.0, 0.5}) {
    AnalyticProvider provider(N, N, SpottedRamp(N, 0));
    QualityGoal goal;
    goal.targetPsnr = 40;
    goal.budget = budget;
    double lowestThreshold = 1;
    goal.reconstruct = [&](SampleProvider& p, const ReconstructionOptions& o, Reconstruction* out,
                           std::vector<Point2i>* pending) {
      std::vector<uint8_t> seen(size_t(N) * N);
      for (int y = 0; y < N; ++y)
        for (int x = 0; x < N; ++x) seen[size_t(y) * N + size_t(x)] = provider.EvaluationsOf(x, y) > 0;
      DCM_RETURN_IF_ERROR(Reconstruct(p, o, out, pending));
      const double t = double(*o.contrastThreshold);
      lowestThreshold = std::min(lowestThreshold, t);
      if (t > tHidden)
        for (size_t i = 0; i < seen.size(); ++i)
          if (!seen[i] && provider.EvaluationsOf(int(i % N), int(i / N)) == 0) out->image[i] += RGB::Gray(0.05f);
      return Status::Ok();
    };
    const Outcome r = RunGoal(provider, ReconstructionOptions{}, goal);
    if (budget == 0) {
      EXPECT_FALSE(r.report.targetReached);
      EXPECT_EQ(r.report.runs, 3);  // the first run and one after each of the first two confirming draws
      EXPECT_GT(lowestThreshold, tHidden);
    } else {
      EXPECT_TRUE(r.report.targetReached);
      EXPECT_LT(lowestThreshold, tHidden);
      EXPECT_GE(r.truePsnr, goal.targetPsnr - 0.5);
      EXPECT_LE(provider.TotalEvaluations(), int64_t(budget * N * N));
    }
  }
}

TEST(QualityTarget, APlateauEndsTheDescentOnlyWithoutABudget) {
  // Twelve highlights no threshold finds, one of them under a validation
  // pixel that carries the estimate alone: the lower bound stops rising
  // while the pixels grow. Without a budget the descent stops there
  // (a few per cent of the pixels); with one, the budget ends it: spent
  // within the last run's share (60 % of what was left, then the bisection).
  const int n = 256;
  const double budget = 0.15;
  for (double b : {0.0, budget}) {
    AnalyticProvider provider(n, n, SpottedRamp(n, 12));
    QualityGoal goal;
    goal.targetPsnr = 40;
    goal.budget = b;
    goal.seed = 8 * 7919;  // a seed whose search sees a highlight: "not reached" either way
    const Outcome r = RunGoal(provider, ReconstructionOptions{}, goal);
    EXPECT_FALSE(r.report.targetReached);
    if (b == 0) {
      EXPECT_LT(r.report.exactFraction(), 0.1);
    } else {
      EXPECT_TRUE(r.report.budgetBound);
      EXPECT_GT(r.report.exactFraction(), 0.6 * budget);
      // Each pixel once, also where the descent reached the full evaluation,
      // which asks for L alone, and the runs after it asked for L_i and L_c.
      EXPECT_EQ(provider.MaxEvaluationsOfOnePixel(), 1);
      EXPECT_LE(provider.TotalEvaluations(), int64_t(budget * n * n));
    }
  }
}

TEST(QualityTarget, APlateauOfSpreadErrorDoesNotEndTheDescent) {
  // Sixty highlights no threshold finds: the lower bound stops rising while
  // the pixels grow, as with twelve (above), but here about ten validation
  // pixels carry the estimate, not one: the error is spread over the image,
  // and what a target asked for needs is spent. Only the full evaluation
  // finds these highlights; the descent goes on to it and meets the target.
  const int n = 256;
  AnalyticProvider provider(n, n, SpottedRamp(n, 60));
  QualityGoal goal;
  goal.targetPsnr = 40;
  goal.seed = 8 * 7919;  // the seed of the twelve above
  const Outcome r = RunGoal(provider, ReconstructionOptions{}, goal);
  EXPECT_TRUE(r.report.targetReached);
  EXPECT_LT(r.report.threshold, 0) << "the full evaluation";
  EXPECT_GE(r.truePsnr, 40.0);
  EXPECT_EQ(provider.MaxEvaluationsOfOnePixel(), 1);
}

TEST(QualityTarget, WithNoisySamplesAPlateauEndsTheDescent) {
  // The sixty highlights above under noise of known variance: the error is
  // as spread, but the bound's plateau is now the exact samples' own noise
  // as much as the highlights, and more exact pixels at the same samples per
  // pixel do not lower it: the descent stops there, far from the full
  // evaluation, and says the target is not reached.
  const int n = 256;
  AnalyticProvider exact(n, n, SpottedRamp(n, 60));
  NoiseModel noise;
  noise.relative = 0.05f;
  noise.absolute = 0.002f;
  NoisyProvider noisy(exact, noise);
  QualityGoal goal;
  goal.targetPsnr = 40;
  goal.seed = 8 * 7919;
  Reconstruction rec;
  QualityReport report;
  ASSERT_TRUE(ReconstructToQuality(noisy, ReconstructionOptions{}, goal, &rec, &report).ok());
  EXPECT_FALSE(report.targetReached);
  EXPECT_GT(report.threshold, 0) << "not the full evaluation";
  EXPECT_LT(report.exactFraction(), 0.2);
}

TEST(QualityTarget, ABudgetFromTheThresholdSearchesAsWithoutOneUntilItBinds) {
  // budgetFromThreshold: where the search ends within the budget it is the
  // search without one, run for run (the first at the options' threshold);
  // a plain budget starts 16x coarser and ends elsewhere. Where the budget
  // binds, it is never exceeded and says so.
  const int N = 256;
  auto run = [&](double target, double budget, bool fromThreshold) {
    AnalyticProvider provider(N, N, FurnishedScene(N, N));
    QualityGoal goal;
    goal.targetPsnr = target;
    goal.budget = budget;
    goal.budgetFromThreshold = fromThreshold;
    Outcome r = RunGoal(provider, ReconstructionOptions{}, goal);
    EXPECT_EQ(provider.MaxEvaluationsOfOnePixel(), 1);
    if (budget > 0) {
      EXPECT_LE(provider.TotalEvaluations(), int64_t(budget * N * N));
    }
    return r;
  };
  const Outcome free = run(40, 0, false), bounded = run(40, 0.35, true), plain = run(40, 0.35, false);
  ASSERT_TRUE(free.report.targetReached);
  EXPECT_TRUE(bounded.report.targetReached);
  EXPECT_FALSE(bounded.report.budgetBound);
  EXPECT_EQ(bounded.report.runs, free.report.runs);
  EXPECT_EQ(bounded.report.threshold, free.report.threshold);
  EXPECT_EQ(bounded.report.exactPixels, free.report.exactPixels);
  EXPECT_EQ(bounded.rec.image, free.rec.image);
  EXPECT_NE(plain.report.exactPixels, free.report.exactPixels);
  // A budget below what the target needs: spent, never passed, bound.
  const Outcome tight = run(70, 0.1, true);
  EXPECT_FALSE(tight.report.targetReached) << tight.report.estimate.psnr;
  EXPECT_TRUE(tight.report.budgetBound) << tight.report.exactFraction();
  EXPECT_GT(tight.report.exactFraction(), 0.5 * 0.1);
}

TEST(QualityTarget, ABudgetCountsTheSamePixelsOnAnyNumberOfThreads) {
  // A run the budget refuses evaluates none of the request it refused (the
  // cache admits each of the engine's requests whole, before its batches):
  // what was spent, and so every later run within what is left, does not
  // depend on how many threads share the batches, how large they are, nor
  // on which came first. (Admitted batch by batch, the same searches spent
  // 3274 to 3276 and 13083 to 13105 pixels over these runs.)
  const int N = 256;
  for (double budget : {0.05, 0.2}) {
    std::vector<int64_t> spent;
    std::vector<std::vector<RGB>> images;
    for (int threads : {1, 2, 3, 4, 8}) {
      AnalyticProvider provider(N, N, FurnishedScene(N, N));
      QualityGoal goal;
      goal.targetPsnr = 70;  // beyond reach: the budget binds
      goal.budget = budget;
      ReconstructionOptions o;
      o.batchSize = threads == 1 ? 16 : 4096;  // on one thread, many small batches in order
      Outcome r;
      tbb::task_arena arena(threads);
      arena.execute([&] { r = RunGoal(provider, o, goal); });
      EXPECT_TRUE(r.report.budgetBound);
      EXPECT_EQ(provider.TotalEvaluations(), r.report.exactPixels);
      spent.push_back(r.report.exactPixels);
      images.push_back(r.rec.image);
    }
    for (size_t k = 1; k < spent.size(); ++k) {
      EXPECT_EQ(spent[k], spent[0]) << "budget " << budget << ", thread count #" << k;
      EXPECT_TRUE(images[k] == images[0]) << "budget " << budget << ", thread count #" << k;
    }
  }
}

TEST(QualityTarget, SupersampledTargetIsMetAtOutputResolution) {
  const int N = 256;
  AnalyticProvider provider(N, N, FurnishedScene(N, N));
  ReconstructionOptions o;
  o.downsample = 2;
  QualityGoal goal;
  goal.targetPsnr = 45;
  const Outcome r = RunGoal(provider, o, goal);
  EXPECT_EQ(r.rec.width, N / 2);
  EXPECT_TRUE(r.report.targetReached);
  EXPECT_GE(r.truePsnr, goal.targetPsnr - 0.5);
  EXPECT_EQ(provider.MaxEvaluationsOfOnePixel(), 1);
}

// The validation pixels were evaluated exactly and count in the exact
// pixels: where the result interpolated them, it keeps their exact values
// (SampleReason::kValidation), in the working image and, at 4x, in the
// output pixel's box mean, at no extra evaluation.
TEST(QualityTarget, ValidationPixelsKeepTheirExactValues) {
  const int N = 256;
  for (int s : {1, 2}) {
    AnalyticProvider provider(N, N, FurnishedScene(N, N));
    ReconstructionOptions o;
    o.downsample = s;
    QualityGoal goal;
    goal.targetPsnr = s == 1 ? 40 : 45;
    const Outcome r = RunGoal(provider, o, goal);
    const std::vector<RGB> full = provider.FullRender();
    int64_t kept = 0;
    for (size_t k = 0; k < r.rec.sampleMap.size(); ++k) {
      if (r.rec.sampleMap[k] != SampleReason::kValidation) continue;
      ++kept;
      ASSERT_EQ(r.rec.workImage[k], full[k]) << k;
    }
    EXPECT_GT(kept, 0);
    EXPECT_EQ(r.rec.stats.byReason[size_t(SampleReason::kValidation)], kept);
    // Every kept pixel was evaluated once, by the validation: no extra cost.
    EXPECT_EQ(provider.MaxEvaluationsOfOnePixel(), 1);
    EXPECT_EQ(provider.TotalEvaluations(), r.report.exactPixels);
    // The output is the box mean of the working image, kept pixels included,
    // and an output pixel whose box holds only exact samples now has no error.
    int w = 0, h = 0;
    EXPECT_EQ(BoxDownsample(r.rec.workImage, r.rec.workWidth, r.rec.workHeight, s, &w, &h), r.rec.image);
    const std::vector<RGB> ref = BoxDownsample(full, r.rec.workWidth, r.rec.workHeight, s, &w, &h);
    int64_t exactBoxes = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        bool all = true, validation = false;
        for (int wy = y * s; wy < (y + 1) * s; ++wy)
          for (int wx = x * s; wx < (x + 1) * s; ++wx) {
            const SampleReason why = r.rec.sampleMap[size_t(wy) * size_t(r.rec.workWidth) + size_t(wx)];
            all = all && HoldsExactSample(why);
            validation = validation || why == SampleReason::kValidation;
          }
        if (!all || !validation) continue;
        ++exactBoxes;
        ASSERT_EQ(r.rec.image[size_t(y) * size_t(w) + size_t(x)], ref[size_t(y) * size_t(w) + size_t(x)]) << x << "," << y;
      }
    EXPECT_GT(exactBoxes, 0);
  }
  // With noisy samples a kept exact value could be worse than the denoised
  // interpolation: none is kept.
  AnalyticProvider exact(N, N, FurnishedScene(N, N));
  NoiseModel noise;
  noise.relative = 0.05f;
  noise.absolute = 0.002f;
  NoisyProvider noisy(exact, noise);
  QualityGoal goal;
  goal.budget = 0.15;
  Reconstruction rec;
  QualityReport report;
  ASSERT_TRUE(ReconstructToQuality(noisy, ReconstructionOptions{}, goal, &rec, &report).ok());
  EXPECT_EQ(rec.stats.byReason[size_t(SampleReason::kValidation)], 0);
}

// A budget's search makes several runs, some refused part way; every pixel
// any of them evaluated counts in the budget, so each is in the result with
// its exact value, not only those of the run the result came from.
TEST(QualityTarget, EveryPixelTheSearchPaidForIsKept) {
  const int N = 256;
  for (int s : {1, 2}) {
    AnalyticProvider provider(N, N, FurnishedScene(N, N));
    ReconstructionOptions o;
    o.downsample = s;
    QualityGoal goal;
    goal.budget = 0.05;
    const Outcome r = RunGoal(provider, o, goal);
    ASSERT_GT(r.report.runs, 1);
    const std::vector<RGB> full = provider.FullRender();
    int64_t evaluated = 0;
    for (int y = 0; y < N; ++y)
      for (int x = 0; x < N; ++x) {
        if (provider.EvaluationsOf(x, y) == 0) continue;
        ++evaluated;
        const size_t k = size_t(y) * size_t(N) + size_t(x);
        ASSERT_TRUE(HoldsExactSample(r.rec.sampleMap[k])) << x << "," << y << " s " << s;
        ASSERT_EQ(r.rec.workImage[k], full[k]) << x << "," << y;
      }
    EXPECT_EQ(evaluated, r.report.exactPixels);
    // Runs the result did not come from left pixels of their own.
    EXPECT_GT(r.rec.stats.byReason[size_t(SampleReason::kRendered)], 0) << "s " << s;
    int64_t exact = 0;
    for (int k = 0; k < kSampleReasonCount; ++k)
      if (HoldsExactSample(SampleReason(k))) exact += r.rec.stats.byReason[size_t(k)];
    EXPECT_EQ(exact, evaluated);
    int w = 0, h = 0;
    EXPECT_EQ(BoxDownsample(r.rec.workImage, N, N, s, &w, &h), r.rec.image);
  }
}

TEST(QualityTarget, ProgressiveLevelsCarryAnEstimate) {
  const int N = 128;
  AnalyticProvider provider(N, N, FurnishedScene(N, N));
  ReconstructionOptions o;
  int calls = 0;
  o.onLevel = [&](int, int, int, const std::vector<RGB>&) { ++calls; };
  QualityGoal goal;
  goal.targetPsnr = 35;
  const Outcome r = RunGoal(provider, o, goal);
  ASSERT_FALSE(r.report.levels.empty());
  EXPECT_GE(calls, int(r.report.levels.size()));
  // Each level refines the one before: its estimate is no worse (the same
  // validation pixels, more exact samples).
  for (size_t k = 1; k < r.report.levels.size(); ++k)
    EXPECT_GE(r.report.levels[k].estimate.psnr, r.report.levels[k - 1].estimate.psnr - 0.5) << "level " << k;
}

/// A noisy run: the result's PSNR against the noise-free image and the noisy
/// full render's, beside what the report estimates.
struct NoisyOutcome {
  QualityReport report;
  double truePsnr = 0;        ///< the result against the converged (noise-free) image
  double trueRenderPsnr = 0;  ///< the noisy full render against it
};

NoisyOutcome RunNoisy(NoiseModel noise, const ReconstructionOptions& o, QualityGoal goal, int n = 256) {
  AnalyticProvider exact(n, n, FurnishedScene(n, n));
  NoisyProvider noisy(exact, noise);
  NoisyOutcome r;
  Reconstruction rec;
  const Status st = ReconstructToQuality(noisy, o, goal, &rec, &r.report);
  EXPECT_TRUE(st.ok()) << st.message();
  int w = 0, h = 0;
  const std::vector<RGB> truth = BoxDownsample(exact.FullRender(), n, n, o.downsample, &w, &h);
  r.truePsnr = DisplayPsnr(rec.image, truth);
  r.trueRenderPsnr = DisplayPsnr(BoxDownsample(noisy.NoisyFullRender(), n, n, o.downsample, &w, &h), truth);
  const PsnrEstimate &e = r.report.estimate, &m = r.report.renderEstimate;
  std::printf("noise %.3f+%.3f seed %u: estimate %.2f [%.2f, %.2f] true %.2f; render %.2f [%.2f, %.2f] true %.2f; "
              "target %.2f, exact %.2f %%\n",
              noise.relative, noise.absolute, noise.seed, e.psnr, e.low, e.high, r.truePsnr, m.psnr, m.low, m.high,
              r.trueRenderPsnr, r.report.targetPsnr, 100 * r.report.exactFraction());
  return r;
}

bool Within(double truth, const PsnrEstimate& e) { return truth >= e.low && truth <= e.high; }

TEST(QualityTarget, NoisyEstimateIsAgainstTheConvergedImage) {
  // Gaussian noise of a known, reported variance; a budget only, so that no
  // choice of the search depends on the validation pixels and each stated
  // 90 % interval covers its truth with probability about 0.9. Of 10
  // independent noise and validation seeds, at least 7 must cover it: with
  // a coverage of 0.9 fewer happen with probability 1.3 % (binomial).
  for (int downsample : {1, 2}) {
    int estimateCovered = 0, renderCovered = 0;
    for (uint32_t seed = 1; seed <= 10; ++seed) {
      ReconstructionOptions o;
      o.downsample = downsample;
      QualityGoal goal;
      goal.budget = 0.15;
      goal.seed = 1000 + seed;
      const NoisyOutcome r = RunNoisy({0.05f, 0.002f, seed}, o, goal);
      EXPECT_TRUE(r.report.againstConverged);
      estimateCovered += Within(r.truePsnr, r.report.estimate);
      renderCovered += Within(r.trueRenderPsnr, r.report.renderEstimate);
    }
    EXPECT_GE(estimateCovered, 7) << "downsample " << downsample;
    EXPECT_GE(renderCovered, 7) << "downsample " << downsample;
  }
}

/// The furnished scene, 128², noisy samples (with their variance or not),
/// searched to `target` with `second` as the validation's second judge.
QualityReport SearchWithSecondJudge(bool variance, double target, std::function<PsnrEstimate()> second) {
  const int n = 128;
  AnalyticProvider exact(n, n, FurnishedScene(n, n));
  NoisyProvider noisy(exact, {0.05f, 0.002f, 1, variance});
  QualityGoal goal;
  goal.targetPsnr = target;
  goal.secondEstimate = std::move(second);
  Reconstruction rec;
  QualityReport report;
  EXPECT_TRUE(ReconstructToQuality(noisy, ReconstructionOptions{}, goal, &rec, &report).ok());
  return report;
}

TEST(QualityTarget, ASecondJudgeBelowTheTargetKeepsTheSearchGoing) {
  // Noisy samples with their variance, a target the validation meets at the
  // first run: a second estimate whose lower bound falls short of it for the
  // first two runs holds the search to a third; one with no opinion (NaN), or
  // any second estimate where the samples carry no variance (the validation
  // is then against the full render, the second against the converged
  // image), changes nothing.
  const double target = 30;
  for (bool variance : {true, false}) {
    int calls = 0;
    auto run = [&](std::function<PsnrEstimate()> second) {
      return SearchWithSecondJudge(variance, target, std::move(second));
    };
    const QualityReport alone = run({});
    ASSERT_TRUE(alone.targetReached);
    ASSERT_EQ(alone.runs, 1) << "the validation alone meets the target at once";
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const QualityReport noOpinion = run([&] { return PsnrEstimate{nan, nan, nan}; });
    EXPECT_EQ(noOpinion.runs, 1);
    EXPECT_TRUE(noOpinion.targetReached);
    const QualityReport judged = run([&] {
      const double low = ++calls <= 2 ? target - 5 : target + 5;
      return PsnrEstimate{low + 1, low, low + 2};
    });
    EXPECT_TRUE(judged.targetReached);
    if (variance) {
      EXPECT_EQ(judged.runs, 3);
      EXPECT_EQ(judged.secondEstimate.low, target + 5);
    } else {
      EXPECT_EQ(judged.runs, 1);
      EXPECT_TRUE(std::isnan(judged.secondEstimate.low));
    }
  }
}

TEST(QualityTarget, TheLowerOfTwoJudgesIsReported) {
  // Noisy samples with their variance and a second judge that does not hold
  // the search back (its lower bound at the target): the runs are the same,
  // and the report carries the lower point estimate of the two, each judge's
  // own kept beside it.
  const double target = 30;
  auto run = [&](std::function<PsnrEstimate()> second) { return SearchWithSecondJudge(true, target, std::move(second)); };
  const QualityReport alone = run({});
  const double v = alone.estimate.psnr;
  ASSERT_GT(v, target + 1) << "room below the validation's estimate for a lower judge at the target";
  EXPECT_EQ(alone.estimateSource, EstimateSource::kValidation);
  for (double offset : {-1.0, +1.0}) {
    const PsnrEstimate judge{v + offset, target, v + offset + 1};
    const QualityReport both = run([&] { return judge; });
    EXPECT_EQ(both.runs, alone.runs);
    EXPECT_EQ(both.validationEstimate.psnr, v);
    EXPECT_EQ(both.secondEstimate.psnr, judge.psnr);
    if (offset < 0) {
      EXPECT_EQ(both.estimate.psnr, judge.psnr);
      EXPECT_EQ(both.estimate.low, judge.low);
      EXPECT_EQ(both.estimateSource, EstimateSource::kPreview);
    } else {
      EXPECT_EQ(both.estimate.psnr, v);
      EXPECT_EQ(both.estimateSource, EstimateSource::kValidation);
    }
  }
}

TEST(QualityTarget, WithoutVarianceTheEstimateIsAgainstTheFullRender) {
  // The same noisy samples without their variance: the estimate keeps its
  // meaning, the PSNR against the noisy full render, and reports no render
  // estimate (the same 7 of 10 as above).
  int covered = 0;
  for (uint32_t seed = 1; seed <= 10; ++seed) {
    const int n = 256;
    AnalyticProvider exact(n, n, FurnishedScene(n, n));
    NoisyProvider noisy(exact, {0.05f, 0.002f, seed, /*reportVariance=*/false});
    QualityGoal goal;
    goal.budget = 0.15;
    goal.seed = 1000 + seed;
    Reconstruction rec;
    QualityReport report;
    ASSERT_TRUE(ReconstructToQuality(noisy, ReconstructionOptions{}, goal, &rec, &report).ok());
    EXPECT_FALSE(report.againstConverged);
    EXPECT_TRUE(std::isnan(report.renderEstimate.psnr));
    covered += Within(DisplayPsnr(rec.image, noisy.NoisyFullRender()), report.estimate);
  }
  EXPECT_GE(covered, 7);
}

TEST(QualityTarget, TargetRenderIsAtLeastAsCloseAsTheFullRender) {
  // --target-psnr render: the target is the render's estimated PSNR against
  // the converged image. The result reaches it within the issue's 0.5 dB of
  // the truth, at an exact fraction below the whole image.
  for (float relative : {0.05f, 0.15f}) {
    QualityGoal goal;
    goal.targetRender = true;
    const NoisyOutcome r = RunNoisy({relative, 0.002f, 7}, ReconstructionOptions{}, goal);
    EXPECT_TRUE(r.report.targetReached);
    // The target is the first draw's render estimate: within the render's
    // interval of the truth, widened by 0.5 dB for that draw's own spread.
    EXPECT_GE(r.report.targetPsnr, r.report.renderEstimate.low - 0.5);
    EXPECT_LE(r.report.targetPsnr, r.report.renderEstimate.high + 0.5);
    EXPECT_GE(r.truePsnr, r.trueRenderPsnr - 0.5);
    EXPECT_LT(r.report.exactFraction(), 1.0);
  }
}

/// Reports each sample's variance times `factor`: a provider whose pooled
/// variance is biased at the pixels it is asked for (pooled over exact
/// pixels that gather at edges, dcm blender's).
class ScaledVarianceProvider final : public SampleProvider {
 public:
  ScaledVarianceProvider(SampleProvider& p, float factor) : p_(p), factor_(factor) {}
  ProviderCapabilities Capabilities() const override { return p_.Capabilities(); }
  Status Guides(const Bounds2i& region, const GuideRequest& what, GuideImage* out) override {
    return p_.Guides(region, what, out);
  }
  Status Evaluate(std::span<const Point2i> pixels, const SampleRequest& what, std::span<ExactSample> out) override {
    DCM_RETURN_IF_ERROR(p_.Evaluate(pixels, what, out));
    for (ExactSample& e : out) e.variance = e.variance * factor_;
    return Status::Ok();
  }

 private:
  SampleProvider& p_;
  float factor_;
};

TEST(QualityTarget, ValidationWeighsEachPixelsOwnVariance) {
  // The engine sees a variance 4x the truth; the validation asks for each
  // pixel's own (QualityGoal::ownVariance) and estimates the render as
  // without the bias. 4x is 6 dB: the estimate from the scaled variance
  // misses the render's true PSNR by about that, from its own by less than
  // 1 dB (the 90 % intervals of NoisyEstimateIsAgainstTheConvergedImage are
  // about 1 dB wide at this noise).
  constexpr int n = 256;
  AnalyticProvider exact(n, n, FurnishedScene(n, n));
  NoisyProvider noisy(exact, {0.05f, 0.002f, 3});
  const double trueRender = DisplayPsnr(noisy.NoisyFullRender(), exact.FullRender());
  for (bool own : {false, true}) {
    ScaledVarianceProvider scaled(noisy, 4.f);
    QualityGoal goal;
    goal.budget = 0.15;
    if (own)
      goal.ownVariance = [&noisy](std::span<const Point2i> pixels, std::span<RGB> variance) {
        std::vector<ExactSample> s(pixels.size());
        ASSERT_TRUE(noisy.Evaluate(pixels, SampleRequest{false, true}, s).ok());
        for (size_t i = 0; i < s.size(); ++i) variance[i] = s[i].variance;
      };
    Reconstruction rec;
    QualityReport report;
    const Status st = ReconstructToQuality(scaled, ReconstructionOptions{}, goal, &rec, &report);
    ASSERT_TRUE(st.ok()) << st.message();
    const double error = report.renderEstimate.psnr - trueRender;
    std::printf("own %d: render estimated %.2f, true %.2f\n", int(own), report.renderEstimate.psnr, trueRender);
    if (own) EXPECT_LT(std::fabs(error), 1.0);
    else EXPECT_LT(error, -4.0);
  }
}

TEST(QualityTarget, TargetRenderNeedsVarianceAndNoOtherTarget) {
  AnalyticProvider plain(64, 64, FurnishedScene(64, 64));
  Reconstruction rec;
  QualityReport report;
  QualityGoal goal;
  goal.targetRender = true;
  Status st = ReconstructToQuality(plain, ReconstructionOptions{}, goal, &rec, &report);
  EXPECT_FALSE(st.ok());
  EXPECT_NE(st.message().find("--target-psnr render"), std::string::npos) << st.message();
  EXPECT_NE(st.message().find("variance"), std::string::npos) << st.message();
  EXPECT_EQ(plain.TotalEvaluations(), 0);
  goal.targetPsnr = 40;
  st = goal.Validate();
  EXPECT_FALSE(st.ok());
  EXPECT_NE(st.message().find("--target-psnr render"), std::string::npos) << st.message();
  goal.targetPsnr = 0;
  goal.budget = 0.2;  // with a budget: whichever binds first
  EXPECT_TRUE(goal.Validate().ok());
}

TEST(QualityTarget, BadGoalsNameTheFlag) {
  AnalyticProvider provider(64, 64, FurnishedScene(64, 64));
  Reconstruction rec;
  QualityReport report;
  auto message = [&](QualityGoal g) {
    const Status st = ReconstructToQuality(provider, ReconstructionOptions{}, g, &rec, &report);
    EXPECT_FALSE(st.ok());
    return st.message();
  };
  QualityGoal g;
  g.targetPsnr = 120;
  EXPECT_NE(message(g).find("--target-psnr"), std::string::npos);
  g.targetPsnr = -1;
  EXPECT_NE(message(g).find("--target-psnr"), std::string::npos);
  g = {};
  g.budget = 1.5;
  EXPECT_NE(message(g).find("--budget"), std::string::npos);
  g.budget = 1e-6;  // not even the validation fits
  EXPECT_NE(message(g).find("--budget"), std::string::npos);
  EXPECT_NE(message(QualityGoal{}).find("neither"), std::string::npos);
}

}  // namespace
}  // namespace dcm::testing
