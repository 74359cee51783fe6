// PipeProvider::FetchPreview: the child's preview as a provider of stand-in
// samples. Apart from pipe_provider.cpp, which reads the protocol alone (and is
// what fuzz/fuzz_pipe builds), because it needs the engine's round schedule.
#include <memory>
#include <utility>
#include <vector>

#include "dcm/noise_estimate.h"
#include "dcm/pipe/pipe_provider.h"
#include "dcm/round_schedule.h"

namespace dcm::pipe {

Status PipeProvider::FetchPreview(const SampleRequest& what, std::unique_ptr<SampleProvider>* out,
                                  int varianceRadius, std::vector<RGB>* ownVariance,
                                  std::vector<RGB>* textureCovariance) {
  std::vector<ExactSample> s;
  DCM_RETURN_IF_ERROR(Preview(Bounds2i{{0, 0}, {caps_.width, caps_.height}}, what, &s, textureCovariance));
  const bool split = what.split && caps_.splitRadiance;
  const bool variance = what.variance && caps_.variance;
  std::vector<RGB> L(s.size()), Li, Lc, var;
  if (split) {
    Li.resize(s.size());
    Lc.resize(s.size());
  }
  if (variance) var.resize(s.size());
  for (size_t i = 0; i < s.size(); ++i) {
    L[i] = s[i].L;
    if (split) {
      Li[i] = s[i].Li;
      Lc[i] = s[i].Lc;
    }
    if (variance) var[i] = s[i].variance;
  }
  if (ownVariance) *ownVariance = variance ? var : std::vector<RGB>{};
  if (variance && varianceRadius > 0) {
    // A pixel's own variance has a degree of freedom or two: pooled over its
    // surface, as the exact pixels' is.
    GuideImage ids;
    DCM_RETURN_IF_ERROR(
        Guides(Bounds2i{{0, 0}, {caps_.width, caps_.height}}, {caps_.objectId, caps_.shaderId, false, false}, &ids));
    var = SurfaceWindowRelativeMean(var, L, caps_.width, caps_.height, ids.objectId, ids.shaderId, varianceRadius);
  }
  *out = std::make_unique<ImagePreviewProvider>(caps_.width, caps_.height, caps_.width, caps_.height, std::move(L),
                                                std::move(Li), std::move(Lc), std::move(var));
  return Status::Ok();
}

}  // namespace dcm::pipe
