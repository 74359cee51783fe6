// PipeProvider::FetchPreview: the child's preview as a provider of stand-in
// samples. Apart from pipe_provider.cpp, which reads the protocol alone (and is
// what fuzz/fuzz_pipe builds), because it needs the engine's round schedule.
#include <memory>
#include <utility>
#include <vector>

#include "dcm/pipe/pipe_provider.h"
#include "dcm/round_schedule.h"

namespace dcm::pipe {

Status PipeProvider::FetchPreview(const SampleRequest& what, std::unique_ptr<SampleProvider>* out,
                                  int varianceRadius, std::vector<RGB>* ownVariance,
                                  std::vector<RGB>* textureCovariance) {
  std::vector<ExactSample> s;
  DCM_RETURN_IF_ERROR(Preview(Bounds2i{{0, 0}, {caps_.width, caps_.height}}, what, &s, textureCovariance));
  const bool variance = what.variance && previewHasVariance();
  GuideImage ids;
  if (variance && varianceRadius > 0)
    DCM_RETURN_IF_ERROR(
        Guides(Bounds2i{{0, 0}, {caps_.width, caps_.height}}, {caps_.objectId, caps_.shaderId, false, false}, &ids));
  *out = PreviewFromSamples(s, caps_.width, caps_.height, what.split && caps_.splitRadiance, variance, ids,
                            varianceRadius, ownVariance);
  return Status::Ok();
}

}  // namespace dcm::pipe
