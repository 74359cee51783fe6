// The sample store's flush (lib/src/sample_store.h): a provider that bounds
// what it evaluates admits or refuses an engine's request whole, before any
// of its (concurrent) batches run.
#include <gtest/gtest.h>

#include <span>

#include "analytic_provider.h"
#include "sample_store.h"

namespace dcm::detail {
namespace {

/// The analytic scene, admitting requests of at most `limit` pixels.
class BoundedProvider final : public testing::AnalyticProvider {
 public:
  BoundedProvider(int n, int64_t limit) : AnalyticProvider(n, n, testing::FurnishedScene(n, n)), limit_(limit) {}
  Status Admit(std::span<const Point2i> pixels, const SampleRequest&) override {
    ++admits_;
    return int64_t(pixels.size()) <= limit_ ? Status::Ok() : Status::OverBudget("over the limit");
  }
  int admits() const { return admits_; }

 private:
  int64_t limit_;
  int admits_ = 0;
};

Status FlushAll(SampleStore* store, SampleProvider& provider, int n) {
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) store->Request(x, y, SampleReason::kCorner);
  ReconstructionStats stats;
  // Batches of 64, in parallel: many concurrent Evaluate() calls per request.
  return store->Flush(provider, SampleRequest{}, 64, /*parallel=*/true, &stats, nullptr);
}

TEST(SampleStore, ARefusedRequestEvaluatesNothing) {
  const int n = 64;
  SampleStore store(n, n, /*split=*/false);
  BoundedProvider provider(n, n * n - 1);
  const Status st = FlushAll(&store, provider, n);
  EXPECT_TRUE(st.overBudget()) << st.message();
  EXPECT_EQ(provider.admits(), 1);
  EXPECT_EQ(provider.TotalEvaluations(), 0);
  for (int64_t i = 0; i < int64_t(n) * n; ++i) ASSERT_FALSE(store.IsExact(i)) << i;
}

TEST(SampleStore, AnAdmittedRequestIsEvaluatedWhole) {
  const int n = 64;
  SampleStore store(n, n, /*split=*/false);
  BoundedProvider provider(n, n * n);
  ASSERT_TRUE(FlushAll(&store, provider, n).ok());
  EXPECT_EQ(provider.admits(), 1);
  EXPECT_EQ(provider.TotalEvaluations(), int64_t(n) * n);
  // Pixels already exact are not asked again, nor admitted.
  ASSERT_TRUE(FlushAll(&store, provider, n).ok());
  EXPECT_EQ(provider.admits(), 1);
  EXPECT_EQ(provider.TotalEvaluations(), int64_t(n) * n);
}

}  // namespace
}  // namespace dcm::detail
