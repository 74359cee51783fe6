// --target-psnr and --budget (dcm/quality_target.h) on a traced scene that
// chose nothing: no constant of the quality loop was set on it (docs/TUNING.md,
// "Quality targets"), so it checks that the estimate carries to other content.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "common/metrics.h"
#include "dcm/quality_target.h"
#include "threshold_sweep.h"
#include "test_scenes.h"

namespace dcm::embree {
namespace {

using testing::MakeProvider;

// Two area lights of different colours over a checker-textured floor, glossy
// spheres, a thin rod and a box: soft and hard shadow edges, highlights and
// texture at final resolution (128x128). Also the scene of QT64 and QT16
// (docs/TUNING.md) and of render_goal_cli_test.cpp.
std::string HeldOutScene() {
  std::ifstream in(std::string(DCM_TEST_DATA_DIR) + "/heldout_scene.json");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(QualityTargetRender, HeldOutSceneMeetsItsTargetAndNeverExceedsItsBudget) {
  auto p = MakeProvider(HeldOutScene());
  ASSERT_TRUE(p);
  ReconstructionOptions o;
  o.threads = 2;
  Reconstruction full;
  ReconstructionOptions fo = o;
  fo.fullEvaluation = true;
  ASSERT_TRUE(Reconstruct(*p, fo, &full).ok());

  for (double target : {40.0, 46.0}) {
    QualityGoal goal;
    goal.targetPsnr = target;
    Reconstruction rec;
    QualityReport report;
    const Status st = ReconstructToQuality(*p, o, goal, &rec, &report);
    ASSERT_TRUE(st.ok()) << st.message();
    const double truth = toolkit::Compare(rec.image, full.image, rec.width, rec.height).psnr;
    std::printf("target %.0f: estimate %.2f [%.2f, %.2f], true %.2f dB, exact %.2f %% in %d runs\n", target,
                report.estimate.psnr, report.estimate.low, report.estimate.high, truth,
                100 * report.exactFraction(), report.runs);
    // The tolerance: the truth at most 0.5 dB below the target (the
    // 95 % lower bound reached it; the truth may fall below it by chance).
    EXPECT_TRUE(report.targetReached);
    EXPECT_GE(truth, target - 0.5);
    EXPECT_LT(report.exactFraction(), 1.0);
  }
  // The frontier a user who knew the right threshold would reach: a sweep of
  // global thresholds, (exact fraction, true PSNR).
  std::vector<std::pair<double, double>> sweep;
  for (double t = 1.0; t > 0.005; t *= 0.85) {
    ReconstructionOptions so = o;
    so.contrastThreshold = float(t);
    Reconstruction rec;
    ASSERT_TRUE(Reconstruct(*p, so, &rec).ok());
    sweep.push_back({rec.stats.exactFraction(), toolkit::Compare(rec.image, full.image, rec.width, rec.height).psnr});
  }
  std::sort(sweep.begin(), sweep.end());
  // The coarsest run (threshold 1) takes 5.0 %: a budget of 5 % leaves no
  // room for its validation and is refused, so the smaller budget is 6 %.
  for (double budget : {0.06, 0.12}) {
    QualityGoal goal;
    goal.budget = budget;
    Reconstruction rec;
    QualityReport report;
    const Status st = ReconstructToQuality(*p, o, goal, &rec, &report);
    ASSERT_TRUE(st.ok()) << st.message();
    const double truth = toolkit::Compare(rec.image, full.image, rec.width, rec.height).psnr;
    std::printf("budget %.2f: exact %.2f %%, estimate %.2f dB, true %.2f dB; the sweep at that fraction %.2f dB "
                "interpolated, %.2f dB by the best threshold within it\n",
                budget, 100 * report.exactFraction(), report.estimate.psnr, truth,
                dcm::testing::SweepPsnrAt(sweep, report.exactFraction()),
                dcm::testing::SweepBestWithin(sweep, report.exactFraction()));
    // Never exceeded: the budget counts every pixel evaluated, validation included.
    EXPECT_LE(report.exactPixels, int64_t(budget * double(report.totalPixels)));
    EXPECT_EQ(rec.stats.exactPixels, report.exactPixels);
  }
}

}  // namespace
}  // namespace dcm::embree
