// Reconstructs an EXR of AOVs (dcm's generic channel names) in-process with
// the installed AOV provider and engine, and prints what the install test
// checks: the exact fraction, the error against the full beauty, the
// provider's error for a missing file.
//   dcm_cxx_consumer AOVS.exr
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "dcm/aov/aov_provider.h"
#include "dcm/reconstructor.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: dcm_cxx_consumer AOVS.exr\n");
    return 2;
  }
  dcm::aov::AovOptions options;
  if (!dcm::aov::ParsePreset("generic", &options.preset).ok()) return 1;

  std::unique_ptr<dcm::aov::AovProvider> missing;
  const dcm::Status bad = dcm::aov::AovProvider::Open({"no-such-file.exr"}, options, &missing);
  std::printf("missing file: %s\n", bad.ok() ? "opened?" : bad.message().c_str());

  std::unique_ptr<dcm::aov::AovProvider> provider;
  dcm::Status st = dcm::aov::AovProvider::Open({argv[1]}, options, &provider);
  if (!st.ok()) {
    std::fprintf(stderr, "error: %s\n", st.message().c_str());
    return 1;
  }
  dcm::Reconstruction r;
  st = dcm::Reconstruct(*provider, dcm::ReconstructionOptions{}, &r);
  if (!st.ok()) {
    std::fprintf(stderr, "error: %s\n", st.message().c_str());
    return 1;
  }
  const std::vector<dcm::RGB>& truth = provider->Beauty();
  double err = 0;
  for (size_t i = 0; i < truth.size(); ++i)
    err += (std::fabs(r.image[i].r - truth[i].r) + std::fabs(r.image[i].g - truth[i].g) +
            std::fabs(r.image[i].b - truth[i].b)) / 3.0;
  std::printf("size %dx%d\nexact fraction %.4f\nmean abs error %.6f\nOK\n", r.width, r.height,
              r.stats.exactFraction(), err / double(truth.size()));
  return 0;
}
