// The input's other passes at the output resolution (--downsample N): each
// kind of pass filtered as a renderer filters it, so that a compositor's
// mattes and IDs stay valid.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/output_exr.h"
#include "dcm/status.h"

namespace dcm::cli {

/// Box mean of an N x N box per output pixel (radiance, colour, normal,
/// depth, coverage: what a film filter averages), with the beauty's
/// arithmetic (dcm::BoxDownsample).
std::vector<float> BoxMeanPlane(const std::vector<float>& plane, int width, int height, int n);

/// The value most of the box's pixels hold (the first in scan order on a
/// tie): an ID is never averaged into another object's ID. `float` IDs are
/// compared by their bits.
std::vector<uint32_t> MajorityPlane(const std::vector<uint32_t>& plane, int width, int height, int n);
std::vector<float> MajorityPlane(const std::vector<float>& plane, int width, int height, int n);

/// One Cryptomatte layer's channels in rank order (id 0, coverage 0, id 1,
/// coverage 1, ...: <layer>00.R, .G, .B, .A, <layer>01.R, ...), downsampled
/// in place: per output pixel the coverage of each ID summed over the box
/// and divided by N^2, the IDs sorted by coverage (most first), as many
/// ranks as the layer has; coverage the ranks cannot hold is dropped, as a
/// renderer drops it.
Status DownsampleCryptomatte(std::vector<std::vector<float>*> rankChannels, int width, int height, int n);

/// Downsamples the output's pass channels (`passes`: indices into
/// `channels`, all width x height): Cryptomatte layers (`cryptoLayers`, their
/// names from the metadata) by rank, other raw channels (IDs) by majority,
/// the rest by box mean.
Status DownsamplePasses(std::vector<toolkit::OutputChannel>* channels, const std::vector<size_t>& passes,
                        const std::vector<std::string>& cryptoLayers, int width, int height, int n);

}  // namespace dcm::cli
