// Exact fraction and error of each method on the analytic furnished scene,
// as a Markdown table (docs/ENGINE.md):
//
//   build/benchmarks/analytic_study [size]
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

#include "analytic_provider.h"
#include "dcm/reconstructor.h"

using namespace dcm;

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 256;
  std::vector<std::pair<std::string, ReconstructionOptions>> methods = {
      {"dcm (default)", ReconstructionOptions{}},
      {"paper (Scheel 2001)", ReconstructionOptions::Paper()},
      {"guo (1998)", ReconstructionOptions::Guo()}};
  ReconstructionOptions noAdaptive;
  noAdaptive.adaptiveBorders = false;
  methods.push_back({"dcm, full borders", noAdaptive});
  ReconstructionOptions noProbe;
  noProbe.finestCentreProbe = false;
  methods.push_back({"dcm, no finest centre probe", noProbe});
  ReconstructionOptions block8;
  block8.elementaryBlock = 8;
  methods.push_back({"dcm, 8-pixel elementary blocks", block8});
  ReconstructionOptions always;
  always.smoothRefinement = SmoothRefinement::kAlways;
  methods.push_back({"dcm, smooth blocks always split", always});

  std::printf("Analytic furnished scene %dx%d (tests/support/analytic_provider.cpp)\n\n", n, n);
  std::printf("| method | threshold | exact %% | PSNR dB | corner | border | probes | lazy | thin | fallback |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& [name, base] : methods)
    for (float t : {0.03f, 0.06f, 0.1f, 0.12f, 0.14f, 0.15f, 0.25f}) {
      testing::AnalyticProvider provider(n, n, testing::FurnishedScene(n, n));
      ReconstructionOptions o = base;
      o.contrastThreshold = t;
      Reconstruction r;
      const Status s = Reconstruct(provider, o, &r);
      if (!s.ok()) {
        std::fprintf(stderr, "%s\n", s.message().c_str());
        return 1;
      }
      const auto pct = [&](SampleReason reason) {
        return 100.0 * double(r.stats.byReason[size_t(reason)]) / double(r.stats.totalPixels);
      };
      std::printf("| %s | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2f |\n", name.c_str(), t,
                  100 * r.stats.exactFraction(), testing::DisplayPsnr(r.image, provider.FullRender()),
                  pct(SampleReason::kCorner), pct(SampleReason::kBorder),
                  pct(SampleReason::kFirstOrderProbe) + pct(SampleReason::kCentreProbe),
                  pct(SampleReason::kLazyCentre), pct(SampleReason::kThinObject), pct(SampleReason::kFallback));
    }
  return 0;
}
