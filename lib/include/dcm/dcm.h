/* The C API of dcm: Directional Coherence Maps reconstruction for host
 * applications written in any language that can call C.
 *
 * In the manner of Open Image Denoise: an opaque, reference-counted handle;
 * options set by name; the renderer supplies the cheap guides (object ID,
 * shader ID, texture value tau) as images and the expensive exact samples
 * through a callback that evaluates batches of pixels. Nothing is thrown
 * across this boundary: every function records its error on the handle (or,
 * for a NULL handle, per thread) and dcmGetError() reports it.
 *
 *   DCMReconstructor r = dcmNewReconstructor();
 *   dcmSetString(r, "method", "dcm");            // preset first, then overrides
 *   dcmSetFloat(r, "contrast_threshold", 0.05f);
 *   dcmSetImageSize(r, width, height);
 *   dcmSetObjectIds(r, ids);                     // optional guides
 *   dcmSetSampleFunction(r, evaluate, &scene, DCM_SAMPLE_THREAD_SAFE);
 *   if (dcmExecute(r) != DCM_ERROR_NONE) { const char* m; dcmGetError(r, &m); ... }
 *   const float* rgb = dcmGetImage(r, &w, &h);   // w*h*3 floats, row-major
 *   dcmReleaseReconstructor(r);
 *
 * The C++ API (dcm/reconstructor.h) is the primary one; this wraps it.
 * Link with -ldcm (pkg-config dcm, or find_package(dcm) and dcm::dcm). */
#ifndef DCM_DCM_H_
#define DCM_DCM_H_

#include <stddef.h>
#include <stdint.h>

#if defined(_WIN32)
#if defined(DCM_C_API_BUILD)
#define DCM_API __declspec(dllexport)
#else
#define DCM_API __declspec(dllimport)
#endif
#else
#define DCM_API __attribute__((visibility("default")))
#endif

#ifdef __cplusplus
extern "C" {
#endif

/** Version of this C interface; raised on incompatible changes. Version 4:
 *  the options whose default depends on the regime (final resolution, the
 *  supersampled rules, noisy samples) are one option each, unset by default;
 *  their twins "noisy_elementary_block", "contrast_threshold_supersampled",
 *  "contrast_metric_supersampled", "directions_supersampled" and
 *  "thin_objects_supersampled" are gone (a value set serves every regime).
 *  Version 5 adds dcmSetPreviewVariance(). Version 6 adds DCM_REASON_RENDERED.
 *  Version 7: "target_psnr" with a preview of known variance is judged by the
 *  preview's estimate (the statistic "estimate_from_preview"), and a
 *  preview-planned run without a goal reports that estimate. Version 8:
 *  "budget" (alone or with "target_psnr") is judged by the preview's estimate
 *  where "target_psnr" alone was. Version 9: a target judged by the preview
 *  leaves a round after the first unrendered where the result reaches the
 *  target without it (the statistic "stopped_at_target"). Version 10: the
 *  statistic "estimated_psnr_effective_pixels". Version 11 adds
 *  DCM_REASON_VALIDATION: a quality target's or budget's validation pixels
 *  keep their exact values where the samples carry no variance. */
#define DCM_C_API_VERSION 11

/** A reconstructor: options, guides, the sample callback and the last result. */
typedef struct DCMReconstructorImpl* DCMReconstructor;

/** Error codes. */
typedef enum DCMError {
  DCM_ERROR_NONE = 0,              /**< no error */
  DCM_ERROR_INVALID_ARGUMENT = 1,  /**< a NULL pointer, an unknown option name, a value out of range */
  DCM_ERROR_INVALID_OPERATION = 2, /**< a call at the wrong time (e.g. executing without a size) */
  DCM_ERROR_CALLBACK = 3,          /**< the sample callback reported a failure */
  DCM_ERROR_OUT_OF_MEMORY = 4,     /**< an allocation failed */
  DCM_ERROR_RECONSTRUCTION = 5,    /**< the engine rejected the input (its message says why) */
  DCM_ERROR_UNKNOWN = 6            /**< anything else (an internal error) */
} DCMError;

/** Flags of dcmSetSampleFunction(). */
enum {
  /** The callback may be called concurrently from several threads on disjoint batches. */
  DCM_SAMPLE_THREAD_SAFE = 1,
  /** The callback can fill the split radiance (L_i, L_c), L = L_i * tau + L_c
   *  (Scheel et al. 2001, 3.3); used together with a texture guide. */
  DCM_SAMPLE_SPLIT = 2,
  /** Every hard shadow of the scene shows in the guides: the scene has no
   *  point or directional light, or the IDs set carry a shadow guide (lit and
   *  unlit pixels of a surface have different IDs); and, where a material has
   *  highlights, so does every highlight. Smooth blocks then get no centre
   *  probe. */
  DCM_SAMPLE_HARD_SHADOWS_GUIDED = 4
};

/** Why a pixel of the working image was evaluated exactly: the values of
 *  dcmGetSampleMap(). DCM_REASON_INTERPOLATED means "not exact". */
enum {
  DCM_REASON_INTERPOLATED = 0,
  DCM_REASON_CORNER = 1,
  DCM_REASON_BORDER = 2,
  DCM_REASON_FIRST_ORDER_PROBE = 3,
  DCM_REASON_LAZY_CENTRE = 4,
  DCM_REASON_CENTRE_PROBE = 5,
  DCM_REASON_THIN_OBJECT = 6,
  DCM_REASON_FALLBACK = 7,
  DCM_REASON_FULL = 8,
  DCM_REASON_PREVIEW_STAND_IN = 9, /**< left at its preview value (dcmSetRoundCost); since API version 3 */
  DCM_REASON_RENDERED = 10, /**< rendered in a round or a run of a quality search that the final plan did not need; since API version 6 */
  DCM_REASON_VALIDATION = 11, /**< a validation pixel of "target_psnr" or "budget", kept exact; since API version 11 */
  DCM_REASON_COUNT = 12
};

/** Evaluates `count` pixels exactly. `xy` holds 2*count ints (x0, y0, x1, y1,
 *  ...) in working-image coordinates (x right, y down). Writes 3*count floats
 *  of linear RGB radiance L to `rgb`. `li` and `lc` are NULL unless split
 *  radiance is in use (DCM_SAMPLE_SPLIT and a texture guide); then they receive
 *  3*count floats each of L_i and L_c. Returns 0 on success; any other value
 *  stops the reconstruction with DCM_ERROR_CALLBACK (the value is in the
 *  message). Exact samples must be deterministic per pixel. */
typedef int (*DCMSampleFunction)(void* user, const int* xy, int count, float* rgb, float* li, float* lc);

/** A sample function of a noisy (Monte Carlo) renderer: as DCMSampleFunction,
 *  and `variance`, when not NULL, receives 3*count floats: the variance of the
 *  estimate of L per channel (the variance of the pixel's mean). The engine
 *  then asks whether differences are significant given that noise (option
 *  "noise_significance") and denoises the samples ("denoise_samples"). Since
 *  API version 2. */
typedef int (*DCMNoisySampleFunction)(void* user, const int* xy, int count, float* rgb, float* li, float* lc,
                                      float* variance);

/** Reports progress in [0,1] with the name of the current stage; called from
 *  the thread that runs dcmExecute(). */
typedef void (*DCMProgressFunction)(void* user, float fraction, const char* stage);

/** Progressive output (the paper's progressive refinement): after refinement
 *  level `level` (0 = coarsest), a usable picture of the working image,
 *  width*height*3 floats of linear RGB, valid during the call only. Called
 *  from the thread that runs dcmExecute(); the last call is the final working
 *  image. Since API version 2. */
typedef void (*DCMLevelFunction)(void* user, int level, int width, int height, const float* rgb);

/** The version of the library, e.g. "0.1.0". */
DCM_API const char* dcmGetVersionString(void);

/** DCM_C_API_VERSION of the library that is loaded (compare with the header's). */
DCM_API int dcmGetApiVersion(void);

/** Creates a reconstructor with dcm's default options (method "dcm") and a
 *  reference count of 1. Returns NULL on failure; dcmGetError(NULL, ...) then
 *  says why. */
DCM_API DCMReconstructor dcmNewReconstructor(void);

/** Adds a reference to `r`. */
DCM_API void dcmRetainReconstructor(DCMReconstructor r);

/** Drops a reference to `r`; the last one frees it, its guides and its result.
 *  NULL is ignored. */
DCM_API void dcmReleaseReconstructor(DCMReconstructor r);

/** Returns the first error recorded on `r` since the last call and clears it;
 *  with `r` NULL, the first error of a call with a NULL handle (or of
 *  dcmNewReconstructor) on this thread. When `message` is not NULL it receives
 *  a description (valid until the next call on `r` from this thread; "" when
 *  there is no error). */
DCM_API DCMError dcmGetError(DCMReconstructor r, const char** message);

/** Sets a string option:
 *   "method"             "dcm" (default), "paper" (Scheel et al. 2001) or "guo"
 *                        (Guo 1998): resets EVERY option to that preset, so set
 *                        it first;
 *   "object_test"        "none" | "id" | "id+shader" | "id|shader";
 *   "thin_objects"       "off" | "none-matches" | "any-differs" | "end-differs";
 *   "contrast_metric"    "mitchell" | "display" | "display-weighted";
 *   "smooth_refinement"  "always" | "centre-probe" | "never".
 *  "thin_objects" and "contrast_metric" depend on the regime when unset
 *  (the default; "default" unsets them): under the supersampled rules
 *  (downsample >= 2 and samples that are not noisy) "none-matches" and
 *  "display-weighted", otherwise "end-differs" and "mitchell".
 *  An unknown name or value records DCM_ERROR_INVALID_ARGUMENT. */
DCM_API void dcmSetString(DCMReconstructor r, const char* name, const char* value);

/** Sets an integer option: "elementary_block" (unset by default: 16, 8 with
 *  noisy samples), "min_block", "directions" (unset by default: 8, 16 under
 *  the supersampled rules), "fallback_max_changes",
 *  "fallback_shading_changes" (a finest block over fallback_max_changes
 *  falls back only when more than this many of its changes are no surface
 *  change, default 2; -1: every such block), "simple_surface_changes"
 *  (a block of at most twice the finest size whose border changes only at
 *  surface changes, up to this many, counts as simple; 2: Guo's test),
 *  "neighbour_directions" (directions each side an interior pixel tries
 *  before the thin-object test makes it exact, default 8: every direction),
 *  "crossing_fill_reach" (under the supersampled rules: the sides below the
 *  elementary block between two lattice lines of the level above take their surface-change pixels
 *  from exact pixels of the same surface on both lines within this many
 *  pixels, where they agree; default 2, 0: off), "downsample",
 *  "threads" (0: all cores),
 *  "tile_size", "batch_size" (pixels per callback call). Bool options accept
 *  0/1 here too. 0 unsets "elementary_block" and "directions" (dcm's default
 *  for the regime), and dcmGetInt() reads them as 0 while unset. Ranges are
 *  checked by dcmExecute(). */
DCM_API void dcmSetInt(DCMReconstructor r, const char* name, int value);

/** Sets a float option: "contrast_threshold" (unset by default: 0.14, 0.15
 *  under the supersampled rules; a negative value unsets it, and
 *  dcmGetFloat() reads -1 while unset), "noise_significance" (with a
 *  provider that reports variance), "probe_lc_share" (a finest edge block
 *  whose border changes only at surface changes is probed only where L_c
 *  exceeds this share of L at some border pixel, default 0.5),
 *  "target_psnr" (dB in (0, 99]: refine until the estimated display-referred
 *  PSNR against the full render, its 95 % lower bound, reaches it; the
 *  threshold is then chosen; 0, the default: none) and "budget" (share of
 *  the working pixels in (0, 1] evaluated at most, validation included; 0:
 *  none); docs/QUALITY.md. Integer options accept whole
 *  numbers here too. */
DCM_API void dcmSetFloat(DCMReconstructor r, const char* name, float value);

/** Sets a bool option: "target_render" (a quality goal: at least as close to
 *  the converged image as the full render, whose PSNR against it is
 *  estimated from the samples' variance; needs a provider that reports
 *  variance, not with "target_psnr"; docs/QUALITY.md), "surface_aware", "texture_split", "adaptive_borders",
 *  "zero_order_test", "gradient_blocks_simple", "first_order_test",
 *  "first_order_from_guides",
 *  "lazy_evaluation", "fallback", "fallback_filled_borders",
 *  "finest_centre_probe", "checkerboard" (of the pixels the thin-object test
 *  or a fallback wants exact, one checkerboard colour first, the other filled
 *  where its exact neighbours agree), "full_evaluation", "denoise_samples". */
DCM_API void dcmSetBool(DCMReconstructor r, const char* name, int value);

/** The value of an integer (or bool) option; 0 and an error for an unknown name. */
DCM_API int dcmGetInt(DCMReconstructor r, const char* name);

/** The value of a float option (or an integer one); 0 and an error for an unknown name. */
DCM_API float dcmGetFloat(DCMReconstructor r, const char* name);

/** The value of a bool option as 0/1; 0 and an error for an unknown name. */
DCM_API int dcmGetBool(DCMReconstructor r, const char* name);

/** Sets the size of the working image in pixels (with option "downsample" N,
 *  the output is width/N x height/N). Clears the guides set before. */
DCM_API void dcmSetImageSize(DCMReconstructor r, int width, int height);

/** Sets the object ID guide: width*height values, row-major, copied. NULL
 *  removes it. Call after dcmSetImageSize(). */
DCM_API void dcmSetObjectIds(DCMReconstructor r, const uint32_t* ids);

/** Sets the shader (material) ID guide: width*height values, row-major,
 *  copied. NULL removes it. Used only together with object IDs. */
DCM_API void dcmSetShaderIds(DCMReconstructor r, const uint32_t* ids);

/** Sets the texture guide tau: width*height*3 floats (linear RGB), row-major,
 *  copied. NULL removes it. Used for texture de-modulation when the sample
 *  function has DCM_SAMPLE_SPLIT. */
DCM_API void dcmSetTexture(DCMReconstructor r, const float* rgb);

/** Sets the normal guide: width*height*3 floats (x, y, z; any consistent
 *  space, need not be unit length, zero where there is none), row-major,
 *  copied. NULL removes it. Neighbours whose normals differ by more than the
 *  option "crease_angle" (degrees) are a surface change. Since API version 2. */
DCM_API void dcmSetNormals(DCMReconstructor r, const float* xyz);

/** Sets the function that evaluates exact samples, its user pointer and
 *  DCM_SAMPLE_* flags. Without DCM_SAMPLE_THREAD_SAFE it is called from one
 *  thread at a time. */
DCM_API void dcmSetSampleFunction(DCMReconstructor r, DCMSampleFunction fn, void* user, int flags);

/** Sets a sample function that also reports the variance of its samples
 *  (replaces one set by dcmSetSampleFunction(), and the other way round).
 *  Flags as for dcmSetSampleFunction(). Since API version 2. */
DCM_API void dcmSetNoisySampleFunction(DCMReconstructor r, DCMNoisySampleFunction fn, void* user, int flags);

/** Sets (or with NULL removes) a progress function. */
DCM_API void dcmSetProgressFunction(DCMReconstructor r, DCMProgressFunction fn, void* user);

/** Sets (or with NULL removes) a function that receives a usable image after
 *  each refinement level (progressive output; costs one pass over the image
 *  per level). Since API version 2. */
DCM_API void dcmSetLevelFunction(DCMReconstructor r, DCMLevelFunction fn, void* user);

/** Says what a call of the sample function costs: `latency_s` seconds per
 *  call whatever its size (a render call, a process start-up) and
 *  `seconds_per_sample` per pixel (0: unknown). Where a call costs more than
 *  about 1000 samples (or the per-sample cost is unknown and the latency is
 *  not 0) and a preview is set (dcmSetPreview()), dcmExecute() chooses the
 *  exact pixels on the preview and calls the sample function once per round,
 *  at most `max_rounds` times (>= 1); pixels still wanted after the last round
 *  keep their preview value (statistic "preview_stand_ins"). The default,
 *  0 and 0, calls it as the refinement goes. Since API version 3. */
DCM_API void dcmSetRoundCost(DCMReconstructor r, double latency_s, double seconds_per_sample, int max_rounds);

/** Sets the preview that plans the rounds: a cheap render of the image at
 *  `width` x `height` (the working size or coarser; upsampled bilinearly),
 *  `rgb` width*height*3 floats of L, `li` and `lc` the split radiance (both or
 *  neither; needed when the sample function has DCM_SAMPLE_SPLIT), copied.
 *  NULL `rgb` removes it. Since API version 3. */
DCM_API void dcmSetPreview(DCMReconstructor r, int width, int height, const float* rgb, const float* li,
                           const float* lc);

/** Sets (or with NULL removes) the variance of the preview's L, per pixel and
 *  channel: width*height*3 floats for a preview at the image size (a
 *  few-samples render), copied; call after dcmSetPreview(), which removes it.
 *  With it the planning weighs the preview's noise where the samples carry
 *  their variance, and after the last round the interpolated pixels move
 *  toward the preview where they differ from it by more than its noise
 *  explains (the preview correction, lib/include/dcm/preview_correction.h;
 *  statistic "preview_corrected"). A coarser preview takes none: its
 *  upsampling would pass for the interpolation's error. Since API version 5. */
DCM_API void dcmSetPreviewVariance(DCMReconstructor r, const float* variance);

/** Runs the reconstruction: calls the sample function for the pixels it needs
 *  and keeps the result on `r`. Returns DCM_ERROR_NONE on success, otherwise
 *  the error (also recorded for dcmGetError()); the previous result is then
 *  discarded. */
DCM_API DCMError dcmExecute(DCMReconstructor r);

/** The reconstructed image of the last successful dcmExecute(): width*height*3
 *  floats of linear RGB, row-major, at the output resolution; NULL before.
 *  `width` and `height` may be NULL. Valid until the next dcmExecute() or the
 *  release of `r`. */
DCM_API const float* dcmGetImage(DCMReconstructor r, int* width, int* height);

/** Why each pixel of the working image was exact: one DCM_REASON_* byte per
 *  pixel, row-major, at the working resolution; NULL before a successful
 *  dcmExecute(). Valid like dcmGetImage(). */
DCM_API const uint8_t* dcmGetSampleMap(DCMReconstructor r, int* width, int* height);

/** A statistic of the last successful dcmExecute(): "exact_pixels",
 *  "total_pixels", "exact_fraction", "provider_calls", "non_finite_samples",
 *  "clamped_samples",
 *  "smooth_blocks", "simple_edge_blocks", "complex_edge_blocks",
 *  "fallback_blocks", "time_provider_s", "time_guides_s", "time_engine_s",
 *  "rounds" (calls planned on the preview; 0 without), "preview_stand_ins"
 *  (since API version 3), "preview_corrected" (since API version 5),
 *  "stopped_at_target" (0/1: the stand-ins' round was not rendered, a target
 *  judged by the preview being met without it; since API version 9); with "target_psnr" or "budget" set also
 *  "estimated_psnr", "estimated_psnr_low", "estimated_psnr_high" (the 90 %
 *  interval), "estimated_psnr_effective_pixels" (how many validation pixels
 *  carry the estimate, dcm::PsnrEstimate::effective; +inf where none saw an
 *  error; since API version 10), "validation_pixels", "quality_runs", "target_reached" and
 *  "budget_bound" (0/1), "estimate_against_converged" (1: the provider
 *  reports variance, and the estimate is against the converged image),
 *  "estimated_render_psnr", "estimated_render_psnr_low",
 *  "estimated_render_psnr_high" (the full render's own PSNR against the
 *  converged image; NaN without variance), "estimate_from_preview" (1: the
 *  goal was judged by the preview's estimate, dcm/preview_target.h: with
 *  "target_psnr" or "budget" or both, a preview at the image size with its variance
 *  (dcmSetPreviewVariance), rounds that cost (dcmSetRoundCost) and noise-free
 *  samples, where the preview's own noise costs less than 25 dB; against the
 *  converged image, no validation pixels), and "exact_pixels" counts every
 *  pixel evaluated over the runs. Without a goal, a preview-planned run whose
 *  preview carries its variance reports "estimated_psnr" (_low, _high) from the
 *  preview, with "estimate_against_converged" and "estimate_from_preview" 1
 *  (since API version 7).
 *  0 and an error for an unknown name or before a result. */
DCM_API double dcmGetStat(DCMReconstructor r, const char* name);

/** The name of a DCM_REASON_* value ("interpolated", "corner", ...); "?" when
 *  out of range. */
DCM_API const char* dcmSampleReasonName(int reason);

#ifdef __cplusplus
}
#endif

#endif /* DCM_DCM_H_ */
