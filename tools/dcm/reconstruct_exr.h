// `dcm reconstruct` on EXR inputs, up to the files it writes: the output
// windows, the engine, the error against the full input or a reference, the
// statistics JSON. Shared by the command (cmd_reconstruct.cpp) and the Python
// module (python/src/module.cpp, dcm.reconstruct_exr), so that both give the
// same pixels and the same statistics.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "aov_common.h"
#include "common/metrics.h"
#include "dcm/aov/aov_provider.h"
#include "dcm/reconstructor.h"
#include "engine_flags.h"

namespace dcm::cli {

/// The error metrics as JSON (null for an infinite PSNR or a non-finite value).
nlohmann::json ErrorJson(const toolkit::ImageError& e);

/// The statistics of a whole reconstruction and of a part alike: the engine's,
/// the command, inputs, mode, method, resolutions, time, options, warnings.
nlohmann::json ExrStatsJson(const std::string& cmd, const aov_common::AovFlags& aov, const EngineFlags& engine,
                            const aov::AovProvider& provider, const Reconstruction& r,
                            const ReconstructionOptions& options, double wallS);

/// The sparse round trip ran out of samples: the message saying how many of
/// the `pending` pixels (`forWhat`: " for this part" or "") were not rendered.
std::string MissingSamplesMessage(const aov::AovProvider& provider, const std::vector<Point2i>& pending,
                                  const std::string& forWhat);

/// The output's place in the frame: the inputs' data and display windows (a
/// render region stays a region of its frame, overscan stays overscan), at
/// the output resolution of `n` (--downsample). An error (a window off the
/// n-pixel lattice) is a usage error.
Status OutputWindows(const aov::AovProvider& provider, int n, Bounds2i* display, Bounds2i* data);

/// A whole-frame reconstruction of EXR inputs, before anything is written.
struct ExrReconstruction {
  Reconstruction result;
  Bounds2i display, data;         ///< the output's windows (OutputWindows)
  bool haveReference = false;     ///< `error` is against `reference`
  std::vector<RGB> reference;     ///< --reference, or the full input (dense), at the output resolution
  toolkit::ImageError error;
  nlohmann::json stats;           ///< what --stats writes
};

/// Reconstructs the whole frame of `provider` as `dcm reconstruct` does:
/// checks the output windows, reads `referencePath` (when not empty), runs
/// the engine (progress on stderr unless engine.quiet), compares with the
/// reference (or the full input, dense mode) and fills the statistics.
/// `*usage` tells whether an error is the caller's (exit 2) rather than a
/// failure.
Status ReconstructWholeExr(const std::string& cmd, aov::AovProvider& provider, const aov_common::AovFlags& aov,
                           const EngineFlags& engine, const ReconstructionOptions& options,
                           const std::string& referencePath, ExrReconstruction* out, bool* usage);

}  // namespace dcm::cli
