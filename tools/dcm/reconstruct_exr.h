// `dcm reconstruct` on EXR inputs, up to the files it writes: the output
// windows, the engine, the error against the full input or a reference, the
// statistics JSON. Shared by the command (cmd_reconstruct.cpp) and the Python
// module (python/src/module.cpp, dcm.reconstruct_exr), so that both give the
// same pixels and the same statistics.
#pragma once

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

#include "aov_common.h"
#include "common/metrics.h"
#include "common/output_exr.h"
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
  std::optional<QualityReport> quality;  ///< with --target-psnr / --budget
};

/// The most exact pixels the noisy default spends: issue 26's bound (at the
/// same samples, at least as close to the converged image as the render, at
/// most 35 % exact). --target-psnr render alone spends more.
inline constexpr double kNoisyDefaultBudget = 0.35;

/// `dcm reconstruct`'s default on noisy dense samples (their variance given
/// or estimated) without a goal, threshold or method of the user's: refine
/// from the default threshold until the result is estimated at least as close
/// to the converged image as the render itself, with at most
/// kNoisyDefaultBudget of the pixels exact (--target-psnr render --budget
/// 0.35, the search starting at the default threshold:
/// QualityGoal::budgetFromThreshold; docs/NOISE.md). Sets the goal in `e`;
/// false (and `e` unchanged) where it does not apply.
bool ApplyNoisyDefaultGoal(const aov::AovProvider& provider, bool sparse, EngineFlags* e);

/// Reconstructs the whole frame of `provider` as `dcm reconstruct` does:
/// checks the output windows, reads `referencePath` (when not empty), runs
/// the engine (progress on stderr unless engine.quiet), compares with the
/// reference (or the full input, dense mode) and fills the statistics.
/// Where the noisy default's bound (ApplyNoisyDefaultGoal) cannot hold the
/// image's coarsest lattice and validation (a tiny image, a strip of one
/// row: the search's Status::OverBudget), runs again without it, as
/// --target-psnr render (-v says why).
/// `*usage` tells whether an error is the caller's (exit 2) rather than a
/// failure.
Status ReconstructWholeExr(const std::string& cmd, aov::AovProvider& provider, const aov_common::AovFlags& aov,
                           const EngineFlags& engine, const ReconstructionOptions& options,
                           const std::string& referencePath, ExrReconstruction* out, bool* usage);

/// The output EXR's layout, planned from the inputs' headers before the
/// engine runs: the input's own names for the beauty, its alpha, its other
/// passes and its metadata.
struct OutputLayout {
  /// An input channel carried to the output.
  struct Source {
    int file = 0, subimage = 0, index = 0;
    std::string name;
    OIIO::TypeDesc type;  ///< stored as FLOAT, HALF or UINT
    bool raw = false;     ///< an ID (AovProvider::IdChannels, UINT) or a Cryptomatte hash: -d leaves it alone
    /// Sparse mode: held by every samples file, read there at the exact
    /// pixels and reconstructed with the beauty's interpolation record (IDs,
    /// `raw`, by ChannelKind::kId); `where` is its (subimage, index) in each
    /// samples file. Otherwise copied from input `file`.
    bool reconstructed = false;
    std::vector<std::pair<int, int>> where;
  };
  enum class Kind { kBeauty, kAlpha, kPass };
  /// One output channel: a beauty component (`index` 0..2), the alpha, or
  /// the pass passes[index].
  struct Channel {
    Kind kind;
    int index = 0;
    std::string name;
  };
  std::vector<Channel> channels;  ///< in the output's order (the input's)
  std::optional<Source> alpha;    ///< the input's alpha; none: A = 1 (--alpha) or no alpha
  std::vector<Source> passes;     ///< carried over (downsampled by pass_downsample.h)
  std::vector<std::string> samples;  ///< sparse mode: the samples files the reconstructed channels are read from
  std::vector<std::string> cryptoLayers;  ///< the inputs' Cryptomatte layer names (their metadata)
  OIIO::ParamValueList attributes;  ///< the inputs' metadata (IsStructuralAttribute excluded)
  std::vector<std::string> notes;   ///< what the output keeps and what not, for -v
  Point2i inputSize;                ///< the inputs' data window's size
  /// The output channel names.
  std::vector<std::string> Names() const;
  /// Whether any output channel is reconstructed from the samples (sparse
  /// mode): the engine must then keep its interpolation record.
  bool Reconstructs() const;
};

/// Plans the output of `provider` (opened from `inputs` and, in sparse mode,
/// `samples`): the beauty under its input names (provider.BeautyChannels(),
/// else R, G, B), the input's alpha (the channel beside the beauty's R named
/// A), or A = 1 when `alpha` and the input has none; every other channel of
/// the inputs. In sparse mode the channels every samples file holds (but the
/// beauty and the mask) are reconstructed from them, in the inputs' place
/// where the inputs hold them too (but the alpha, which the inputs' guides
/// render gives at every pixel); the alpha too when only they hold it. A
/// file that cannot be read is an error naming it.
Status PlanOutputLayout(const aov::AovProvider& provider, const std::vector<std::string>& inputs,
                        const std::vector<std::string>& samples, bool alpha, int downsample, OutputLayout* out);

/// The output image of `run` laid out as `layout` says: the beauty
/// reconstructed, the alpha and passes read from `inputs` or, reconstructed
/// ones, from the samples files at the exact pixels (each pixel from the
/// samples file whose beauty it has, AovProvider::SamplesFileOf) and
/// reconstructed with `run.result.interpolation` (with `downsample` > 1 the
/// alpha box-filtered, the passes as DownsamplePasses filters them), the
/// inputs' metadata plus `provenance`. With `region` (a part of the output's
/// data window, --tile/--region), `run.result` holds that region only: the
/// image's data window is the region, the alpha and the passes are cut to it.
Status BuildOutputImage(const aov::AovProvider& provider, const OutputLayout& layout, const std::vector<std::string>& inputs,
                        const ExrReconstruction& run, int downsample, const toolkit::Metadata& provenance,
                        toolkit::OutputImage* out, const Bounds2i* region = nullptr);

}  // namespace dcm::cli
