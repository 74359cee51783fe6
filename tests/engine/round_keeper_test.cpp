// The quality search's rounds on a preview (lib/src/round_keeper.h): a run
// plans on the preview with the exact samples the engine asked for before
// it, and never with a validation draw's, which must stay unseen by the runs
// it judges.
#include <gtest/gtest.h>

#include <vector>

#include "analytic_provider.h"
#include "round_keeper.h"

namespace dcm::testing {
namespace {

TEST(RoundKeeper, ARunSeesTheEnginesEarlierSamplesAndNoValidationPixel) {
  const int N = 16;
  const RGB truth = RGB::Gray(0.5f), previewValue = RGB::Gray(0.6f);
  AnalyticProvider exact(N, N, Constant(truth));
  ImagePreviewProvider preview(N, N, N, N, std::vector<RGB>(size_t(N) * N, previewValue));
  QualityRoundStats stats;
  detail::RoundKeeper keeper(exact, preview, &stats);
  const Point2i engine{3, 4}, validation{9, 10};
  ExactSample s[2];
  auto seenBy = [&](int run) {
    detail::RunPreview view(keeper, preview, run);
    const Point2i both[2] = {engine, validation};
    EXPECT_TRUE(view.Evaluate(both, {}, s).ok());
  };
  keeper.BeginPass();
  keeper.BeginRun();  // run 1 asks for a pixel
  ASSERT_TRUE(keeper.Evaluate(std::span(&engine, 1), {}, std::span(s, 1)).ok());
  keeper.EndRun();
  // A validation draw after run 1, rendered at once.
  ASSERT_TRUE(keeper.Evaluate(std::span(&validation, 1), {}, std::span(s, 1)).ok());
  EXPECT_EQ(s[0].L, truth);
  keeper.BeginRun();  // run 2
  seenBy(2);
  EXPECT_EQ(s[0].L, truth) << "the engine's sample of run 1";
  EXPECT_EQ(s[1].L, previewValue) << "a validation pixel stays unseen";
  // Run 2 asks for the validation pixel itself: from then on it is the engine's.
  ASSERT_TRUE(keeper.Evaluate(std::span(&validation, 1), {}, std::span(s, 1)).ok());
  keeper.EndRun();
  keeper.BeginRun();  // run 3
  seenBy(3);
  EXPECT_EQ(s[1].L, truth);
  EXPECT_EQ(exact.MaxEvaluationsOfOnePixel(), 1);
}

}  // namespace
}  // namespace dcm::testing
