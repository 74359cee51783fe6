// The record of how one reconstruction gave each working pixel its value,
// kept to reconstruct other channels of the same pixels (a renderer's passes:
// light passes, depth, normals, alpha, IDs, Cryptomatte) with the beauty's own
// decisions: its blocks, directions, surfaces, thin-object and lazy choices,
// border fills and checkerboard fills. Asked for with
// ReconstructionOptions::recordInterpolation; docs/OUTPUT.md says how
// `dcm reconstruct` uses it in sparse mode.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "dcm/geometry.h"
#include "dcm/status.h"

namespace dcm {

namespace detail {
class InterpolationRecorder;
}

/// How a channel is reconstructed from its values at the exact pixels.
enum class ChannelKind : uint8_t {
  /// Colour, light, depth, normals, alpha: every value the beauty computed
  /// (border fills, bilinear smooth blocks, oriented elements, lazy
  /// corrections clamped to the block's range, checkerboard fills) is
  /// computed for the channel with the same sources, weights and arithmetic;
  /// a channel equal to one component of what the beauty interpolates
  /// reconstructs to that component bit for bit.
  kContinuous,
  /// IDs (object or material index, Cryptomatte ranks, uint channels): every
  /// value takes the value of the source the beauty weighted most (the first
  /// of equal weights), never a blend. The choice depends on the weights
  /// alone, so all ID channels of a pixel come from one source pixel (a
  /// Cryptomatte rank's ID and coverage stay a pair).
  kId,
};

/// The steps of one reconstruction that gave non-exact pixels their values,
/// in the order the engine took them. Exact pixels keep the channel's own
/// value. What the beauty alone has no counterpart for a channel: the
/// texture split (the channel is interpolated itself, not as L_i tau + L_c)
/// and the denoising of noisy samples (the channel's exact values are kept
/// as they are).
class InterpolationRecord {
 public:
  InterpolationRecord();
  ~InterpolationRecord();
  InterpolationRecord(const InterpolationRecord&) = delete;
  InterpolationRecord& operator=(const InterpolationRecord&) = delete;

  /// The working pixels the record covers, in the working image of the
  /// provider given to Reconstruct() (the whole image) or to
  /// ReconstructRegion() (the region's window, dcm/window_provider.h).
  const Bounds2i& window() const { return window_; }
  /// Whether pixel i (row-major in window()) was evaluated exactly.
  bool IsExact(int64_t i) const { return exact_[size_t(i)] != 0; }
  /// Marks pixel i exact: a pixel the result took an exact value for after
  /// the reconstruction (a quality target's validation pixel), so that every
  /// channel takes its own value there too.
  void MarkExact(int64_t i) { exact_[size_t(i)] = 1; }

  /// Reconstructs one channel: `exact` holds its value at every pixel of
  /// window() (row-major; only the exact pixels' values are read), `out`
  /// receives every pixel: the exact ones copied bit for bit, the others
  /// computed as `kind` says. kId only copies values, so any 32-bit ID (a
  /// uint channel's bits carried in a float) comes out bit for bit. A size
  /// that is not window()'s is an error.
  Status Apply(std::span<const float> exact, ChannelKind kind, std::vector<float>* out) const;

  /// The memory the record holds, in bytes.
  size_t MemoryBytes() const;

  /// Moves window() to start at `origin` (ReconstructRegion: the window's
  /// corner in the frame's working image).
  void SetOrigin(Point2i origin) { window_ = {origin, {origin.x + window_.width(), origin.y + window_.height()}}; }

  struct Op;

 private:
  friend class detail::InterpolationRecorder;
  Bounds2i window_;
  std::vector<uint8_t> exact_;
  std::vector<Op> ops_;
  std::vector<uint32_t> index_;  ///< terms' pixels; kExactBit: read the channel's exact value
  std::vector<double> weight_;   ///< terms' weights
  uint32_t lazyLeaves_ = 0;
};

}  // namespace dcm
