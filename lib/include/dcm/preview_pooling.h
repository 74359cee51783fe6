// Preview pooling: an exact pixel's preview samples are more samples of it.
// Where the preview renders on random numbers of its own (dcm blender: seeds
// of its own), a pixel's preview and its exact value are independent
// estimates of the same converged value, and their inverse-variance mean has
// less noise than either: the preview's samples, paid for at every pixel,
// then also serve the pixels rendered exactly.
#pragma once

#include <cstdint>

#include "dcm/reconstructor.h"
#include "dcm/sample_provider.h"
#include "dcm/status.h"

namespace dcm {

/// The weight of the preview in an exact pixel pooled with it, for exact
/// samples whose variance is `exactShare` of the preview's: s / (1 + s), the
/// inverse-variance weight (0 for noise-free exact samples). It is also the
/// pooled pixel's variance as a share of the preview's.
double PreviewPoolWeight(double exactShare);

/// Moves every exact pixel of `rec` (HoldsExactSample) toward `preview`'s
/// value there by PreviewPoolWeight(exactShare), and makes `rec->image`
/// again, downsampled by `downsample`.
/// A denoised exact value (noisy samples) takes its raw sample's weight: its
/// error is more than its reduced variance, and the weight of that variance
/// alone did worse (docs/TUNING.md).
/// The preview must give every working pixel's L from samples independent of
/// the exact ones (pooling a preview that is the first of the exact samples
/// would count those twice). A pixel whose preview or exact value is not
/// finite keeps its value. `pooled` (if given): how many pixels moved.
Status PoolExactWithPreview(SampleProvider& preview, double exactShare, int downsample, Reconstruction* rec,
                            int64_t* pooled = nullptr);

}  // namespace dcm
