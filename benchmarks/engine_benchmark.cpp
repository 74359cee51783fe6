// The engine alone, provider cost excluded: megapixels reconstructed per
// second of engine time, and peak memory per megapixel.
//
//   build/benchmarks/engine_benchmark --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "analytic_provider.h"
#include "dcm/reconstructor.h"

namespace {

using namespace dcm;

/// Serves precomputed samples: evaluation costs a copy, so the time measured
/// is the engine's.
class TableProvider final : public SampleProvider {
 public:
  TableProvider(int n, const testing::SceneFunction& scene) : n_(n) {
    truth_.reserve(size_t(n) * size_t(n));
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) truth_.push_back(scene(x, y));
  }
  ProviderCapabilities Capabilities() const override {
    ProviderCapabilities c;
    c.width = c.height = n_;
    c.objectId = c.shaderId = c.texture = c.splitRadiance = true;
    c.name = "table";
    return c;
  }
  Status Guides(const Bounds2i& r, const GuideRequest& what, GuideImage* out) override {
    out->region = r;
    const size_t n = size_t(r.area());
    if (what.objectId) out->objectId.resize(n);
    if (what.shaderId) out->shaderId.resize(n);
    if (what.texture) out->texture.resize(n);
    for (size_t i = 0; i < n; ++i) {
      if (what.objectId) out->objectId[i] = truth_[i].objectId;
      if (what.shaderId) out->shaderId[i] = truth_[i].shaderId;
      if (what.texture) out->texture[i] = truth_[i].tau;
    }
    return Status::Ok();
  }
  Status Evaluate(std::span<const Point2i> px, const SampleRequest&, std::span<ExactSample> out) override {
    for (size_t k = 0; k < px.size(); ++k) {
      const testing::PixelTruth& t = truth_[size_t(px[k].y) * size_t(n_) + size_t(px[k].x)];
      out[k].L = t.L();
      out[k].Li = t.Li;
      out[k].Lc = t.Lc;
    }
    return Status::Ok();
  }

 private:
  int n_;
  std::vector<testing::PixelTruth> truth_;
};

long MaxRssKiB() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;
}

void BM_Reconstruct(benchmark::State& state, ReconstructionOptions options) {
  const int n = int(state.range(0));
  options.threads = int(state.range(1));
  TableProvider provider(n, testing::FurnishedScene(n, n));
  const long rssBefore = MaxRssKiB();
  double engine = 0, exact = 0;
  std::map<std::string, double> stages;  // seconds per stage, summed over the iterations
  for (auto _ : state) {
    Reconstruction r;
    const Status s = Reconstruct(provider, options, &r);
    if (!s.ok()) state.SkipWithError(s.message().c_str());
    state.SetIterationTime(r.stats.timeEngineS);
    engine += r.stats.timeEngineS;
    exact = r.stats.exactFraction();
    for (const auto& [name, seconds] : r.stats.stageTimes.Named()) stages[std::string(name)] += seconds;
  }
  // Engine milliseconds per reconstruction, per stage (ReconstructionStats::stageTimes).
  const double perRun = 1e3 / double(std::max<int64_t>(1, int64_t(state.iterations())));
  for (const auto& [name, seconds] : stages) state.counters[name + "_ms"] = seconds * perRun;
  const double mpix = double(n) * n / 1e6;
  state.counters["Mpix/s"] = benchmark::Counter(mpix * double(state.iterations()) / engine);
  state.counters["Mpix/s/thread"] = benchmark::Counter(mpix * double(state.iterations()) / engine / options.threads);
  state.counters["exact%"] = 100 * exact;
  // Peak resident memory added by the reconstruction (the provider's table
  // was allocated before), per megapixel.
  state.counters["MiB/Mpix"] = double(std::max(0L, MaxRssKiB() - rssBefore)) / 1024.0 / mpix;
}

BENCHMARK_CAPTURE(BM_Reconstruct, dcm, ReconstructionOptions{})
    ->Args({2048, 1})->Args({2048, 2})->Args({512, 1})->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Reconstruct, paper, ReconstructionOptions::Paper())
    ->Args({2048, 1})->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Reconstruct, guo, ReconstructionOptions::Guo())
    ->Args({2048, 1})->UseManualTime()->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
