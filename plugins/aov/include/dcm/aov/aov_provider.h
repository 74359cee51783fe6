// A SampleProvider over multichannel EXR AOVs written by any renderer
// (Blender Cycles, POV-Ray, a studio pipeline), read with OpenImageIO.
//
// Two modes:
//  - dense: the expensive channels (beauty L, or the split L_i, L_c) exist for
//    every pixel of the inputs; Evaluate() hands the engine the pixels it asks
//    for, so that `dcm reconstruct` can tell what DCM would have saved on this
//    render and at what error;
//  - sparse (the file-based round trip): the inputs carry only the cheap
//    guides; the exact samples come from "samples" EXRs that a renderer wrote
//    for the pixels `dcm plan` asked for (a `mask` channel marks them).
//    Evaluate() answers Status::Pending when a requested pixel is missing.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "dcm/sample_provider.h"
#include "dcm/status.h"

namespace dcm::aov {

/// What a channel (or a sum of products of channels) means for the engine.
enum class Role : int {
  kObjectId,  ///< "id": integer object ID (or a Cryptomatte layer)
  kShaderId,  ///< "shader": integer shader/material ID (or a Cryptomatte layer)
  kU,         ///< "u": texture coordinate, with --texture
  kV,         ///< "v": texture coordinate, with --texture
  kTauR, kTauG, kTauB,  ///< "tau.R/G/B": texture value
  kNX, kNY, kNZ,        ///< "N.X/Y/Z": surface normal (creases inside one object)
  kShadow,    ///< "shadow": light-visibility guide, > 0 where the light reaches the surface
  kHighlight, ///< "highlight": direct glossy light, a highlight where > AovOptions::highlightLevel
  /// "albedo.R/G/B": the albedo a denoiser reads, which continues through
  /// mirrors to the surface they show (Cycles' Denoising Albedo): divided out
  /// before the noise is estimated from one render, so that a texture, also
  /// a reflected one, is not taken for noise
  kAlbedoR, kAlbedoG, kAlbedoB,
  kLiR, kLiG, kLiB,     ///< "Li.R/G/B": radiance before texturing
  kLcR, kLcG, kLcB,     ///< "Lc.R/G/B": radiance not modulated by the texture
  /// "Lr.R/G/B": the radiance that a mirror reflects of the surfaces it
  /// shows (indirect glossy light), which their albedo modulates; with the
  /// albedo, L_i = Lr / tau there and the rest of L (a light's highlight,
  /// light through glass) is L_c
  kLrR, kLrG, kLrB,
  kLR, kLG, kLB,        ///< "L.R/G/B": beauty radiance
  kVarR, kVarG, kVarB,  ///< "var.R/G/B": variance of the estimate of L
  kMask,      ///< "mask": in a samples EXR, > 0 where the pixel was rendered
  kCount
};
inline constexpr int kRoleCount = int(Role::kCount);

/// The role's name on the command line ("id", "tau.R", "L.G", ...).
std::string_view RoleName(Role role);
/// Parses a role name (case-sensitive, as RoleName() writes it; "tau", "Li",
/// "Lc", "L" and "var" alone are accepted by ParseMapping for all three).
Status ParseRole(std::string_view name, Role* role);

/// Where the channel names come from.
enum class Preset {
  /// Plain names: id, shader, u, v, tau.R/G/B, N.X/Y/Z, shadow, highlight, albedo.R/G/B, Li.R/G/B,
  /// Lc.R/G/B, Lr.R/G/B, beauty R/G/B, var.R/G/B, mask.
  kGeneric,
  /// Blender Cycles multilayer EXR: <layer>.IndexOB.X, IndexMA.X (or the
  /// CryptoObject / CryptoMaterial layers), UV.U/V, Normal.X/Y/Z, tau = DiffCol,
  /// L_i = DiffDir + DiffInd, L = Combined, L_c = L - L_i*tau (so that
  /// L_i*tau + L_c = Combined; without Combined, L_c is the sum of the
  /// Gloss, Trans, Volume, Emit and Env contributions). The Combined of a
  /// view layer named ShadowGuide* is the shadow guide (R + G + B); the
  /// GlossDir of one named HighlightGuide* is the highlight guide (R + G + B).
  /// albedo = Denoising Albedo (the view layer's Denoising Data), where written;
  /// Lr = GlossCol*GlossInd.
  kBlender,
};
Status ParsePreset(std::string_view name, Preset* preset);

/// One --map ROLE=EXPR. EXPR is a channel name, a sum of products of channel
/// names ("DiffDir.R+DiffInd.R", "GlossCol.R*GlossDir.R"), or for the ID roles
/// "cryptomatte:LAYER" (the layer name as in the EXR metadata, or its suffix).
/// Channel names must not contain '+' or '*'. A three-channel role given
/// without its component ("tau=albedo") maps tau.R/G/B to albedo.R/G/B.
struct Mapping {
  Role role;
  std::string expression;
};
/// Parses "ROLE=EXPR"; "tau=NAME" style yields three mappings.
Status ParseMapping(std::string_view text, std::vector<Mapping>* out);

/// One --texture SHADER=FILE: tau(u,v) of pixels whose shader ID is SHADER (a
/// decimal ID, or a material name from the Cryptomatte manifest) is looked up
/// in FILE with OpenImageIO's TextureSystem.
struct TextureBinding {
  std::string shader;
  std::string file;
};
/// Parses "SHADER=FILE".
Status ParseTextureBinding(std::string_view text, TextureBinding* out);

struct AovOptions {
  Preset preset = Preset::kGeneric;
  std::vector<Mapping> mappings;          ///< override the preset
  std::vector<TextureBinding> textures;   ///< tau(u,v) from texture files
  std::string viewLayer;                  ///< Blender: empty = detect
  /// Sparse mode: the exact samples come from these files only (possibly none
  /// yet: the first round of `dcm plan`). Dense mode when false.
  bool sparse = false;
  std::vector<std::string> samples;       ///< samples EXRs (sparse mode)
  /// Offer the split (L_i, L_c) when tau is available. In sparse mode this
  /// decides which channels the samples must carry.
  bool split = true;
  /// Dense mode, noisy renders without a variance channel. An independent
  /// render of the same frame (another seed; same channels): the samples are
  /// the mean of the two renders, and the variance of that mean is
  /// (A - B)^2 / 4, averaged over a 5x5 window of pixels on the same surface
  /// (one pixel's difference alone is one degree of freedom).
  std::vector<std::string> secondRender;
  /// A pixel whose highlight guide (the value of the `highlight` role; with
  /// the Blender preset R + G + B of the guide's direct glossy light) exceeds
  /// this is a highlight: highlight and other pixels of one surface become
  /// different surfaces. 1.5 is R + G + B of a mean of 0.5, a highlight as
  /// bright as mid-grey on the display (calibration: docs/TUNING.md).
  float highlightLevel = 1.5f;
  /// Dense mode, one noisy render and no variance channel: the variance is
  /// estimated from the data (dcm::VarianceFromOneRender: per pixel the
  /// residual along the direction the image does not change in, its median
  /// over a 7x7 window on the same surface), of L_i times tau^2 plus of L_c
  /// when the split is available (the texture divided out), else of L. It
  /// fails where the image has real detail at the pixel scale that the guides
  /// do not explain over half of a window (an untextured pattern, hair,
  /// grass, aliased geometry inside one object): that detail is taken for
  /// noise and smoothed over.
  bool estimateVariance = false;
  /// Dense mode with the texture split (L_i, tau), and no variance channel,
  /// second render or estimateVariance:
  /// decide from the data whether the samples are noisy and, when they are,
  /// estimate their variance as estimateVariance does. Noisy: the display-
  /// referred PSNR their noise alone would cost, estimated from the median
  /// relative residual against the same-surface 4-neighbours (robust to the
  /// detail at few pixels that misleads a mean), is below dcm::kNoisyPsnr.
  bool detectNoise = false;
};



/// The provider. Create with Open(); all data is loaded (and checked) there,
/// so Guides() and Evaluate() only copy and are thread safe.
class AovProvider final : public SampleProvider {
 public:
  /// Reads `inputs` (one multilayer EXR or several EXRs of one resolution
  /// and data window)
  /// and, in sparse mode, `options.samples`. Errors name the file and channel.
  static Status Open(const std::vector<std::string>& inputs, const AovOptions& options,
                     std::unique_ptr<AovProvider>* out);
  ~AovProvider() override;

  ProviderCapabilities Capabilities() const override;
  Status Guides(const Bounds2i& region, const GuideRequest& what, GuideImage* out) override;
  /// Dense mode: the stored samples. Sparse mode: the samples read from the
  /// samples files; Status::Pending when any requested pixel has none.
  Status Evaluate(std::span<const Point2i> pixels, const SampleRequest& what,
                  std::span<ExactSample> out) override;

  /// The size of the inputs' data window: the image the engine reconstructs.
  int width() const;
  int height() const;
  /// Where that image lies in the frame: the inputs' data window (a render
  /// region, or overscan) and display window, in EXR pixel coordinates.
  /// Engine pixel (x, y) is frame pixel DataWindow().min + (x, y).
  Bounds2i DataWindow() const;
  Bounds2i DisplayWindow() const;
  /// True when every pixel has an exact sample (dense input).
  bool dense() const;
  /// Whether pixel (x, y) has an exact sample.
  bool HasSample(Point2i p) const;
  /// Sparse mode: the index (in AovOptions::samples) of the samples file
  /// whose values pixel (x, y) has: the last that rendered it. -1 where none
  /// did, and in dense mode.
  int SamplesFileOf(Point2i p) const;
  /// Number of pixels with an exact sample.
  int64_t SampleCount() const;
  /// Beauty L of every pixel (row-major); pixels without a sample are 0.
  const std::vector<RGB>& Beauty() const;
  /// The input channels of the beauty L.R, L.G, L.B when each is one channel
  /// of the inputs ("ViewLayer.Combined.R" with the Blender preset, "R"
  /// generic): the names the output EXR keeps. In sparse mode, where the
  /// inputs do not carry it, those of the first samples file. Empty when L
  /// is an expression (--map L=a+b).
  const std::vector<std::string>& BeautyChannels() const;
  /// Sparse mode: the samples files' channels read as the mask.
  const std::vector<std::string>& MaskChannels() const;
  /// The input channels read as object or shader IDs (not Cryptomatte
  /// layers): integers, which a conversion to half would change above 2048.
  const std::vector<std::string>& IdChannels() const;
  /// What was found and how it is used (role -> channels, tests switched off);
  /// printed by -v.
  const std::vector<std::string>& Notes() const;
  /// Suspicious data kept as is (NaN/Inf/negative samples, per file and channel).
  const std::vector<std::string>& Warnings() const;
  /// Where the samples' variance comes from, and what the noise detector
  /// (AovOptions::detectNoise) found: for the stats and the EXR metadata.
  struct NoiseInfo {
    /// "channels" (a variance pass, var.R/G/B), "second render",
    /// "estimated" (AovOptions::estimateVariance), "detected" (the detector
    /// called the samples noisy and estimated it), "none" (noise-free).
    std::string variance = "none";
    /// The PSNR that the samples' noise alone would cost, by the detector;
    /// NaN where it did not run (another source, no texture split, sparse).
    double detectedPsnr = std::numeric_limits<double>::quiet_NaN();
  };
  const NoiseInfo& Noise() const;
  /// The channel names a samples EXR must carry for this configuration
  /// (including the mask channel), for `dcm plan` to tell the renderer.
  std::vector<std::string> SampleChannels() const;

  struct Data;

 private:
  explicit AovProvider(std::unique_ptr<Data> data);
  std::unique_ptr<Data> d_;
};

}  // namespace dcm::aov
