// The C API (dcm/dcm.h): a thin wrapper of the C++ engine. Every entry point
// catches everything; errors are recorded on the handle (or per thread for a
// NULL handle) and never cross the boundary as exceptions.
#include "dcm/dcm.h"

#include <atomic>
#include <cmath>
#include <cstring>
#include <exception>
#include <limits>
#include <mutex>
#include <new>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "dcm/option_names.h"
#include "dcm/preview_target.h"
#include "dcm/quality_target.h"
#include "dcm/reconstructor.h"
#include "dcm/round_schedule.h"

#ifndef DCM_VERSION_STRING
#define DCM_VERSION_STRING "unknown"
#endif

static_assert(DCM_REASON_INTERPOLATED == int(dcm::SampleReason::kInterpolated));
static_assert(DCM_REASON_CORNER == int(dcm::SampleReason::kCorner));
static_assert(DCM_REASON_BORDER == int(dcm::SampleReason::kBorder));
static_assert(DCM_REASON_FIRST_ORDER_PROBE == int(dcm::SampleReason::kFirstOrderProbe));
static_assert(DCM_REASON_LAZY_CENTRE == int(dcm::SampleReason::kLazyCentre));
static_assert(DCM_REASON_CENTRE_PROBE == int(dcm::SampleReason::kCentreProbe));
static_assert(DCM_REASON_THIN_OBJECT == int(dcm::SampleReason::kThinObject));
static_assert(DCM_REASON_FALLBACK == int(dcm::SampleReason::kFallback));
static_assert(DCM_REASON_FULL == int(dcm::SampleReason::kFull));
static_assert(DCM_REASON_PREVIEW_STAND_IN == int(dcm::SampleReason::kPreviewStandIn));
static_assert(DCM_REASON_RENDERED == int(dcm::SampleReason::kRendered));
static_assert(DCM_REASON_VALIDATION == int(dcm::SampleReason::kValidation));
static_assert(DCM_REASON_COUNT == dcm::kSampleReasonCount);

/// The object behind a DCMReconstructor handle.
struct DCMReconstructorImpl {
  std::atomic<int> refs{1};
  dcm::ReconstructionOptions options;
  int width = 0, height = 0;
  std::vector<uint32_t> objectIds, shaderIds;
  std::vector<dcm::RGB> texture;
  std::vector<dcm::Vec3f> normals;
  DCMSampleFunction sample = nullptr;
  DCMNoisySampleFunction noisySample = nullptr;  ///< set instead of `sample`
  void* sampleUser = nullptr;
  int sampleFlags = 0;
  DCMProgressFunction progress = nullptr;
  void* progressUser = nullptr;
  DCMLevelFunction level = nullptr;
  void* levelUser = nullptr;
  dcm::RoundCost roundCost;
  int maxRounds = 3;
  int previewWidth = 0, previewHeight = 0;
  std::vector<dcm::RGB> previewL, previewLi, previewLc, previewVariance;
  double targetPsnr = 0, budget = 0;  ///< "target_psnr", "budget" (0: none; dcm/quality_target.h)
  bool targetRender = false;          ///< "target_render" (QualityGoal::targetRender)

  bool hasResult = false;
  dcm::Reconstruction result;
  dcm::PreviewScheduleStats schedule;
  std::optional<dcm::QualityReport> quality;  ///< of the last result, with a target or budget
  std::vector<uint8_t> sampleMap;

  std::mutex errorMutex;
  DCMError error = DCM_ERROR_NONE;
  std::string errorMessage;
  std::string reportedMessage;  ///< the string dcmGetError() handed out last
};

namespace {

/// Errors of calls with a NULL handle, per thread.
struct ThreadError {
  DCMError error = DCM_ERROR_NONE;
  std::string message;
  std::string reported;
};
thread_local ThreadError tlsError;

/// Records the first error since the last dcmGetError().
void SetError(DCMReconstructor r, DCMError code, const std::string& message) noexcept {
  try {
    if (!r) {
      if (tlsError.error == DCM_ERROR_NONE) {
        tlsError.error = code;
        tlsError.message = message;
      }
      return;
    }
    std::lock_guard<std::mutex> lock(r->errorMutex);
    if (r->error == DCM_ERROR_NONE) {
      r->error = code;
      r->errorMessage = message;
    }
  } catch (...) {
    // Out of memory while recording the message: keep at least the code.
    if (!r) {
      if (tlsError.error == DCM_ERROR_NONE) tlsError.error = code;
    } else if (r->error == DCM_ERROR_NONE) {
      r->error = code;
    }
  }
}

/// As above, for a message that is a C string (built inside the try).
void SetError(DCMReconstructor r, DCMError code, const char* message) noexcept {
  try {
    SetError(r, code, std::string(message));
  } catch (...) {
    SetError(r, code, std::string());
  }
}

/// Runs `body` of the entry point `function`, turning exceptions into errors
/// recorded on `r`.
template <typename F>
void Guard(DCMReconstructor r, const char* function, F&& body) noexcept {
  try {
    body();
  } catch (const std::bad_alloc&) {
    SetError(r, DCM_ERROR_OUT_OF_MEMORY, std::string("out of memory while running ") + function);
  } catch (const std::exception& e) {
    SetError(r, DCM_ERROR_UNKNOWN, std::string("internal error: ") + e.what());
  } catch (...) {
    SetError(r, DCM_ERROR_UNKNOWN, "internal error: unknown exception");
  }
}

/// Checks the handle and the name; records an error when either is NULL.
bool CheckArgsOrThrow(DCMReconstructor r, const char* name, const char* function) {
  if (!r) {
    SetError(nullptr, DCM_ERROR_INVALID_ARGUMENT, std::string(function) + ": NULL reconstructor");
    return false;
  }
  if (!name) {
    SetError(r, DCM_ERROR_INVALID_ARGUMENT, std::string(function) + ": NULL option name");
    return false;
  }
  return true;
}

/// As CheckArgsOrThrow, never throwing.
bool CheckArgs(DCMReconstructor r, const char* name, const char* function) noexcept {
  try {
    return CheckArgsOrThrow(r, name, function);
  } catch (...) {
    SetError(r, DCM_ERROR_OUT_OF_MEMORY, "out of memory");
    return false;
  }
}

// The option names are those of dcm/option_names.h (SetIntOption, ...): one
// table, shared with the Python module.
std::string UnknownOption(const char* kind, const char* name) {
  return std::string("unknown ") + kind + " option '" + name + "'";
}

/// The SampleProvider the engine sees: guides from the copied images,
/// samples from the host's callback.
class CallbackProvider final : public dcm::SampleProvider {
 public:
  explicit CallbackProvider(const DCMReconstructorImpl& r) : r_(r) {}

  dcm::ProviderCapabilities Capabilities() const override {
    dcm::ProviderCapabilities c;
    c.width = r_.width;
    c.height = r_.height;
    c.objectId = !r_.objectIds.empty();
    c.shaderId = !r_.shaderIds.empty();
    c.texture = !r_.texture.empty();
    c.normal = !r_.normals.empty();
    c.splitRadiance = (r_.sampleFlags & DCM_SAMPLE_SPLIT) != 0;
    c.variance = r_.noisySample != nullptr;
    c.threadSafe = (r_.sampleFlags & DCM_SAMPLE_THREAD_SAFE) != 0;
    c.hardShadowsGuided = (r_.sampleFlags & DCM_SAMPLE_HARD_SHADOWS_GUIDED) != 0;
    c.name = "C API sample function";
    return c;
  }

  dcm::Status Guides(const dcm::Bounds2i& region, const dcm::GuideRequest& what, dcm::GuideImage* out) override {
    const dcm::Bounds2i all{{0, 0}, {r_.width, r_.height}};
    if (dcm::Intersect(region, all) != region)
      return dcm::Status::Error("guide region outside the image");
    out->region = region;
    const size_t n = size_t(region.area());
    auto copy = [&](const auto& src, auto* dst) {
      dst->resize(n);
      size_t k = 0;
      for (int y = region.min.y; y < region.max.y; ++y)
        for (int x = region.min.x; x < region.max.x; ++x) (*dst)[k++] = src[size_t(all.offset({x, y}))];
    };
    if (what.objectId && !r_.objectIds.empty()) copy(r_.objectIds, &out->objectId);
    if (what.shaderId && !r_.shaderIds.empty()) copy(r_.shaderIds, &out->shaderId);
    if (what.texture && !r_.texture.empty()) copy(r_.texture, &out->texture);
    if (what.normal && !r_.normals.empty()) copy(r_.normals, &out->normal);
    return dcm::Status::Ok();
  }

  dcm::Status Evaluate(std::span<const dcm::Point2i> pixels, const dcm::SampleRequest& what,
                       std::span<dcm::ExactSample> out) override {
    const size_t n = pixels.size();
    if (n > size_t(std::numeric_limits<int>::max()))
      return dcm::Status::Error("batch too large for the C sample function");
    std::vector<int> xy(2 * n);
    for (size_t i = 0; i < n; ++i) {
      xy[2 * i] = pixels[i].x;
      xy[2 * i + 1] = pixels[i].y;
    }
    std::vector<float> rgb(3 * n, 0.f), li, lc, var;
    if (what.split) {
      li.assign(3 * n, 0.f);
      lc.assign(3 * n, 0.f);
    }
    const bool variance = what.variance && r_.noisySample;
    if (variance) var.assign(3 * n, 0.f);
    float* const liOut = what.split ? li.data() : nullptr;
    float* const lcOut = what.split ? lc.data() : nullptr;
    const int code = r_.noisySample ? r_.noisySample(r_.sampleUser, xy.data(), int(n), rgb.data(), liOut, lcOut,
                                                     variance ? var.data() : nullptr)
                                    : r_.sample(r_.sampleUser, xy.data(), int(n), rgb.data(), liOut, lcOut);
    if (code != 0) {
      failed_ = true;
      return dcm::Status::Error("the sample function returned " + std::to_string(code) + " for a batch of " +
                                std::to_string(n) + " pixels");
    }
    for (size_t i = 0; i < n; ++i) {
      out[i].L = {rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]};
      if (what.split) {
        out[i].Li = {li[3 * i], li[3 * i + 1], li[3 * i + 2]};
        out[i].Lc = {lc[3 * i], lc[3 * i + 1], lc[3 * i + 2]};
      }
      if (variance) out[i].variance = {var[3 * i], var[3 * i + 1], var[3 * i + 2]};
    }
    return dcm::Status::Ok();
  }

 /// Whether the sample function reported a failure.
  bool failed() const { return failed_; }

 private:
  const DCMReconstructorImpl& r_;
  std::atomic<bool> failed_{false};
};

/// Whether a guide may be set now; records the error otherwise.
bool CanSetGuideOrThrow(DCMReconstructor r, const char* function) {
  if (!r) {
    SetError(nullptr, DCM_ERROR_INVALID_ARGUMENT, std::string(function) + ": NULL reconstructor");
    return false;
  }
  if (r->width <= 0 || r->height <= 0) {
    SetError(r, DCM_ERROR_INVALID_OPERATION, std::string(function) + ": call dcmSetImageSize() first");
    return false;
  }
  return true;
}

/// As CanSetGuideOrThrow, never throwing.
bool CanSetGuide(DCMReconstructor r, const char* function) noexcept {
  try {
    return CanSetGuideOrThrow(r, function);
  } catch (...) {
    SetError(r, DCM_ERROR_OUT_OF_MEMORY, "out of memory");
    return false;
  }
}

/// Copies an image of three floats per pixel (n*3, row-major) into `out`
/// (RGB for tau and previews, Vec3f for normals); NULL clears it.
template <typename Triple>
void CopyTriples(const float* v, size_t n, std::vector<Triple>* out) {
  if (!v) return out->clear();
  out->resize(n);
  for (size_t i = 0; i < n; ++i) (*out)[i] = {v[3 * i], v[3 * i + 1], v[3 * i + 2]};
}

/// The one sample function of `r`: plain or noisy (the other is cleared).
void SetSampleFunctions(DCMReconstructor r, const char* function, DCMSampleFunction plain,
                        DCMNoisySampleFunction noisy, void* user, int flags) noexcept {
  try {
    if (!r) return SetError(nullptr, DCM_ERROR_INVALID_ARGUMENT, std::string(function) + ": NULL reconstructor");
    if (flags & ~(DCM_SAMPLE_THREAD_SAFE | DCM_SAMPLE_SPLIT | DCM_SAMPLE_HARD_SHADOWS_GUIDED))
      return SetError(r, DCM_ERROR_INVALID_ARGUMENT, std::string(function) + ": unknown flags");
  } catch (...) {  // the message could not be built
    return SetError(r, DCM_ERROR_OUT_OF_MEMORY, "out of memory");
  }
  r->sample = plain;
  r->noisySample = noisy;
  r->sampleUser = user;
  r->sampleFlags = flags;
}

}  // namespace

extern "C" {

DCM_API const char* dcmGetVersionString(void) { return DCM_VERSION_STRING; }

DCM_API int dcmGetApiVersion(void) { return DCM_C_API_VERSION; }

DCM_API DCMReconstructor dcmNewReconstructor(void) {
  try {
    return new DCMReconstructorImpl();
  } catch (...) {
    SetError(nullptr, DCM_ERROR_OUT_OF_MEMORY, "dcmNewReconstructor: out of memory");
    return nullptr;
  }
}

DCM_API void dcmRetainReconstructor(DCMReconstructor r) {
  if (!r) {
    SetError(nullptr, DCM_ERROR_INVALID_ARGUMENT, "dcmRetainReconstructor: NULL reconstructor");
    return;
  }
  r->refs.fetch_add(1, std::memory_order_relaxed);
}

DCM_API void dcmReleaseReconstructor(DCMReconstructor r) {
  if (!r) return;
  if (r->refs.fetch_sub(1, std::memory_order_acq_rel) == 1) delete r;
}

DCM_API DCMError dcmGetError(DCMReconstructor r, const char** message) {
  DCMError code = DCM_ERROR_NONE;
  try {
    if (!r) {
      code = tlsError.error;
      tlsError.reported = std::move(tlsError.message);
      tlsError.message.clear();
      tlsError.error = DCM_ERROR_NONE;
      if (message) *message = tlsError.reported.c_str();
      return code;
    }
    std::lock_guard<std::mutex> lock(r->errorMutex);
    code = r->error;
    r->reportedMessage = std::move(r->errorMessage);
    r->errorMessage.clear();
    r->error = DCM_ERROR_NONE;
    if (message) *message = r->reportedMessage.c_str();
  } catch (...) {
    if (message) *message = "";
  }
  return code;
}

DCM_API void dcmSetString(DCMReconstructor r, const char* name, const char* value) {
  if (!CheckArgs(r, name, "dcmSetString")) return;
  Guard(r, "dcmSetString", [&] {
    if (!value) return SetError(r, DCM_ERROR_INVALID_ARGUMENT, std::string("option ") + name + ": NULL value");
    const dcm::Status st = dcm::SetStringOption(&r->options, name, value);
    if (!st.ok()) SetError(r, DCM_ERROR_INVALID_ARGUMENT, st.message());
  });
}

DCM_API void dcmSetInt(DCMReconstructor r, const char* name, int value) {
  if (!CheckArgs(r, name, "dcmSetInt")) return;
  Guard(r, "dcmSetInt", [&] {
    if (dcm::SetIntOption(r->options, name, value)) return;
    if (bool* b = dcm::FindBoolOption(r->options, name)) *b = value != 0;
    else SetError(r, DCM_ERROR_INVALID_ARGUMENT, UnknownOption("integer", name));
  });
}

DCM_API void dcmSetFloat(DCMReconstructor r, const char* name, float value) {
  if (!CheckArgs(r, name, "dcmSetFloat")) return;
  Guard(r, "dcmSetFloat", [&] {
    const std::string_view n(name);
    if (n == "target_psnr" || n == "budget") {
      const float hi = n == "budget" ? 1.f : 99.f;
      if (!(value >= 0.f && value <= hi))
        return SetError(r, DCM_ERROR_INVALID_ARGUMENT,
                        std::string("option ") + name + ": must be in (0, " + (n == "budget" ? "1]" : "99] dB") +
                            " (0: none), got " + std::to_string(value));
      (n == "budget" ? r->budget : r->targetPsnr) = double(value);
    } else if (dcm::SetFloatOption(r->options, name, value)) {
    } else if (dcm::KindOfOption(name) == dcm::OptionKind::kInt) {
      if (!(std::nearbyint(value) == value) || std::fabs(value) > 1e9f)
        return SetError(r, DCM_ERROR_INVALID_ARGUMENT,
                        std::string("option ") + name + ": expected a whole number, got " + std::to_string(value));
      dcm::SetIntOption(r->options, name, int(value));
    } else {
      SetError(r, DCM_ERROR_INVALID_ARGUMENT, UnknownOption("float", name));
    }
  });
}

DCM_API void dcmSetBool(DCMReconstructor r, const char* name, int value) {
  if (!CheckArgs(r, name, "dcmSetBool")) return;
  Guard(r, "dcmSetBool", [&] {
    if (std::string_view(name) == "target_render") r->targetRender = value != 0;
    else if (bool* b = dcm::FindBoolOption(r->options, name)) *b = value != 0;
    else SetError(r, DCM_ERROR_INVALID_ARGUMENT, UnknownOption("bool", name));
  });
}

DCM_API int dcmGetInt(DCMReconstructor r, const char* name) {
  if (!CheckArgs(r, name, "dcmGetInt")) return 0;
  int result = 0;
  Guard(r, "dcmGetInt", [&] {
    if (dcm::GetIntOption(r->options, name, &result)) return;
    if (bool* b = dcm::FindBoolOption(r->options, name)) result = *b ? 1 : 0;
    else SetError(r, DCM_ERROR_INVALID_ARGUMENT, UnknownOption("integer", name));
  });
  return result;
}

DCM_API float dcmGetFloat(DCMReconstructor r, const char* name) {
  if (!CheckArgs(r, name, "dcmGetFloat")) return 0.f;
  float result = 0.f;
  Guard(r, "dcmGetFloat", [&] {
    if (std::string_view(name) == "target_psnr") result = float(r->targetPsnr);
    else if (std::string_view(name) == "budget") result = float(r->budget);
    else if (dcm::GetFloatOption(r->options, name, &result)) return;
    else if (int i = 0; dcm::GetIntOption(r->options, name, &i)) result = float(i);
    else SetError(r, DCM_ERROR_INVALID_ARGUMENT, UnknownOption("float", name));
  });
  return result;
}

DCM_API int dcmGetBool(DCMReconstructor r, const char* name) {
  if (!CheckArgs(r, name, "dcmGetBool")) return 0;
  int result = 0;
  Guard(r, "dcmGetBool", [&] {
    if (std::string_view(name) == "target_render") result = r->targetRender ? 1 : 0;
    else if (bool* b = dcm::FindBoolOption(r->options, name)) result = *b ? 1 : 0;
    else SetError(r, DCM_ERROR_INVALID_ARGUMENT, UnknownOption("bool", name));
  });
  return result;
}

DCM_API void dcmSetImageSize(DCMReconstructor r, int width, int height) {
  if (!r) return SetError(nullptr, DCM_ERROR_INVALID_ARGUMENT, "dcmSetImageSize: NULL reconstructor");
  Guard(r, "dcmSetImageSize", [&] {
    constexpr int kMaxSide = 1 << 17;
    if (width < 1 || height < 1 || width > kMaxSide || height > kMaxSide || int64_t(width) * height > (int64_t(1) << 30))
      return SetError(r, DCM_ERROR_INVALID_ARGUMENT,
                      "dcmSetImageSize: unusable size " + std::to_string(width) + "x" + std::to_string(height));
    r->width = width;
    r->height = height;
    r->objectIds.clear();
    r->shaderIds.clear();
    r->texture.clear();
    r->normals.clear();
  });
}

DCM_API void dcmSetObjectIds(DCMReconstructor r, const uint32_t* ids) {
  if (!CanSetGuide(r, "dcmSetObjectIds")) return;
  Guard(r, "dcmSetObjectIds", [&] {
    if (!ids) return r->objectIds.clear();
    r->objectIds.assign(ids, ids + size_t(r->width) * size_t(r->height));
  });
}

DCM_API void dcmSetShaderIds(DCMReconstructor r, const uint32_t* ids) {
  if (!CanSetGuide(r, "dcmSetShaderIds")) return;
  Guard(r, "dcmSetShaderIds", [&] {
    if (!ids) return r->shaderIds.clear();
    r->shaderIds.assign(ids, ids + size_t(r->width) * size_t(r->height));
  });
}

DCM_API void dcmSetTexture(DCMReconstructor r, const float* rgb) {
  if (!CanSetGuide(r, "dcmSetTexture")) return;
  Guard(r, "dcmSetTexture", [&] { CopyTriples(rgb, size_t(r->width) * size_t(r->height), &r->texture); });
}

DCM_API void dcmSetNormals(DCMReconstructor r, const float* xyz) {
  if (!CanSetGuide(r, "dcmSetNormals")) return;
  Guard(r, "dcmSetNormals", [&] { CopyTriples(xyz, size_t(r->width) * size_t(r->height), &r->normals); });
}

DCM_API void dcmSetSampleFunction(DCMReconstructor r, DCMSampleFunction fn, void* user, int flags) {
  SetSampleFunctions(r, "dcmSetSampleFunction", fn, nullptr, user, flags);
}

DCM_API void dcmSetNoisySampleFunction(DCMReconstructor r, DCMNoisySampleFunction fn, void* user, int flags) {
  SetSampleFunctions(r, "dcmSetNoisySampleFunction", nullptr, fn, user, flags);
}

DCM_API void dcmSetLevelFunction(DCMReconstructor r, DCMLevelFunction fn, void* user) {
  if (!r) return SetError(nullptr, DCM_ERROR_INVALID_ARGUMENT, "dcmSetLevelFunction: NULL reconstructor");
  r->level = fn;
  r->levelUser = user;
}

DCM_API void dcmSetProgressFunction(DCMReconstructor r, DCMProgressFunction fn, void* user) {
  if (!r) return SetError(nullptr, DCM_ERROR_INVALID_ARGUMENT, "dcmSetProgressFunction: NULL reconstructor");
  r->progress = fn;
  r->progressUser = user;
}

DCM_API void dcmSetRoundCost(DCMReconstructor r, double latency_s, double seconds_per_sample, int max_rounds) {
  if (!r) return SetError(nullptr, DCM_ERROR_INVALID_ARGUMENT, "dcmSetRoundCost: NULL reconstructor");
  if (!(latency_s >= 0 && latency_s <= 1e9) || !(seconds_per_sample >= 0 && seconds_per_sample <= 1e9))
    return SetError(r, DCM_ERROR_INVALID_ARGUMENT, "dcmSetRoundCost: costs must be finite and >= 0");
  if (max_rounds < 1) return SetError(r, DCM_ERROR_INVALID_ARGUMENT, "dcmSetRoundCost: max_rounds must be >= 1");
  r->roundCost = {latency_s, seconds_per_sample};
  r->maxRounds = max_rounds;
}

DCM_API void dcmSetPreview(DCMReconstructor r, int width, int height, const float* rgb, const float* li,
                           const float* lc) {
  if (!r) return SetError(nullptr, DCM_ERROR_INVALID_ARGUMENT, "dcmSetPreview: NULL reconstructor");
  Guard(r, "dcmSetPreview", [&] {
    r->previewL.clear();
    r->previewLi.clear();
    r->previewLc.clear();
    r->previewVariance.clear();
    r->previewWidth = r->previewHeight = 0;
    if (!rgb) return;
    if (width < 1 || height < 1 || width > r->width || height > r->height)
      return SetError(r, DCM_ERROR_INVALID_ARGUMENT,
                      "dcmSetPreview: size " + std::to_string(width) + "x" + std::to_string(height) +
                          " must be 1x1 up to the image size (call dcmSetImageSize() first)");
    if (!li != !lc) return SetError(r, DCM_ERROR_INVALID_ARGUMENT, "dcmSetPreview: li and lc go together");
    const size_t n = size_t(width) * size_t(height);
    CopyTriples(rgb, n, &r->previewL);
    CopyTriples(li, n, &r->previewLi);
    CopyTriples(lc, n, &r->previewLc);
    r->previewWidth = width;
    r->previewHeight = height;
  });
}

DCM_API void dcmSetPreviewVariance(DCMReconstructor r, const float* variance) {
  if (!r) return SetError(nullptr, DCM_ERROR_INVALID_ARGUMENT, "dcmSetPreviewVariance: NULL reconstructor");
  Guard(r, "dcmSetPreviewVariance", [&] {
    r->previewVariance.clear();
    if (!variance) return;
    if (r->previewL.empty() || r->previewWidth != r->width || r->previewHeight != r->height)
      return SetError(r, DCM_ERROR_INVALID_ARGUMENT,
                      "dcmSetPreviewVariance: needs a preview at the image size (dcmSetPreview() first)");
    CopyTriples(variance, size_t(r->width) * size_t(r->height), &r->previewVariance);
  });
}

DCM_API DCMError dcmExecute(DCMReconstructor r) {
  if (!r) {
    SetError(nullptr, DCM_ERROR_INVALID_ARGUMENT, "dcmExecute: NULL reconstructor");
    return DCM_ERROR_INVALID_ARGUMENT;
  }
  DCMError code = DCM_ERROR_NONE;
  auto fail = [&](DCMError c, const auto& message) noexcept {
    code = c;
    SetError(r, c, message);
  };
  try {
    r->hasResult = false;
    r->result = dcm::Reconstruction{};
    r->sampleMap.clear();
    if (r->width <= 0 || r->height <= 0) {
      fail(DCM_ERROR_INVALID_OPERATION, "dcmExecute: no image size (call dcmSetImageSize())");
      return code;
    }
    if (!r->sample && !r->noisySample) {
      fail(DCM_ERROR_INVALID_OPERATION,
           "dcmExecute: no sample function (call dcmSetSampleFunction() or dcmSetNoisySampleFunction())");
      return code;
    }
    if (r->options.downsample > 0 &&
        (r->width % r->options.downsample != 0 || r->height % r->options.downsample != 0)) {
      fail(DCM_ERROR_INVALID_ARGUMENT, "dcmExecute: image size " + std::to_string(r->width) + "x" +
                                           std::to_string(r->height) + " is not a multiple of downsample " +
                                           std::to_string(r->options.downsample));
      return code;
    }
    CallbackProvider provider(*r);
    dcm::ReconstructionOptions options = r->options;
    if (r->progress) {
      options.progress = [r](float v, std::string_view stage) {
        const std::string s(stage);
        r->progress(r->progressUser, v, s.c_str());
      };
    }
    if (r->level) {
      // RGB is three packed floats: the working image is passed as it is.
      static_assert(sizeof(dcm::RGB) == 3 * sizeof(float));
      options.onLevel = [r](int level, int w, int h, const std::vector<dcm::RGB>& image) {
        r->level(r->levelUser, level, w, h, reinterpret_cast<const float*>(image.data()));
      };
    }
    r->schedule = {};
    r->quality.reset();
    dcm::Status st;
    if (r->targetPsnr > 0 || r->budget > 0 || r->targetRender) {
      // A quality goal runs the engine level by level (its runs share one sample cache).
      dcm::QualityGoal goal;
      goal.targetPsnr = r->targetPsnr;
      goal.budget = r->budget;
      goal.targetRender = r->targetRender;
      dcm::QualityReport report;
      // A target or a budget, with a preview of known variance, noise-free exact
      // samples and rounds that cost: judged by the preview's estimate where it can tell.
      const bool fromPreview = !r->targetRender && !r->noisySample &&
                               !r->previewVariance.empty() &&
                               dcm::ChooseSchedule(r->roundCost) == dcm::RoundSchedule::kPreview;
      bool judged = false;
      if (fromPreview) {
        dcm::ImagePreviewProvider preview(r->width, r->height, r->previewWidth, r->previewHeight, r->previewL,
                                          r->previewLi, r->previewLc, r->previewVariance);
        dcm::PreviewScheduleOptions schedule;
        schedule.maxRounds = r->maxRounds;
        if ((judged = dcm::CanTargetFromPreview(preview, schedule))) {
          dcm::PreviewTargetStats ladder;
          st = dcm::ReconstructToTargetFromPreview(provider, preview, options, goal, schedule, &r->result, &report,
                                                   &ladder);
          r->schedule = std::move(ladder.last);
          r->schedule.rounds = ladder.rounds;
        }
      }
      if (!judged) st = dcm::ReconstructToQuality(provider, options, goal, &r->result, &report);
      if (st.ok()) r->quality = std::move(report);
    } else if (!r->previewL.empty() && dcm::ChooseSchedule(r->roundCost) == dcm::RoundSchedule::kPreview) {
      dcm::ImagePreviewProvider preview(r->width, r->height, r->previewWidth, r->previewHeight, r->previewL,
                                        r->previewLi, r->previewLc, r->previewVariance);
      dcm::PreviewScheduleOptions schedule;
      schedule.maxRounds = r->maxRounds;
      st = dcm::ReconstructWithPreview(provider, preview, options, schedule, &r->result, &r->schedule);
    } else {
      st = dcm::Reconstruct(provider, options, &r->result);
    }
    if (!st.ok()) {
      r->result = dcm::Reconstruction{};
      fail(provider.failed() ? DCM_ERROR_CALLBACK : DCM_ERROR_RECONSTRUCTION, st.message());
      return code;
    }
    r->sampleMap.resize(r->result.sampleMap.size());
    for (size_t i = 0; i < r->sampleMap.size(); ++i) r->sampleMap[i] = uint8_t(r->result.sampleMap[i]);
    r->hasResult = true;
  } catch (const std::bad_alloc&) {
    r->result = dcm::Reconstruction{};
    fail(DCM_ERROR_OUT_OF_MEMORY, "dcmExecute: out of memory while reconstructing");
  } catch (const std::exception& e) {
    r->result = dcm::Reconstruction{};
    fail(DCM_ERROR_UNKNOWN, std::string("dcmExecute: internal error: ") + e.what());
  } catch (...) {
    r->result = dcm::Reconstruction{};
    fail(DCM_ERROR_UNKNOWN, "dcmExecute: internal error: unknown exception");
  }
  return code;
}

DCM_API const float* dcmGetImage(DCMReconstructor r, int* width, int* height) {
  if (width) *width = 0;
  if (height) *height = 0;
  if (!r) {
    SetError(nullptr, DCM_ERROR_INVALID_ARGUMENT, "dcmGetImage: NULL reconstructor");
    return nullptr;
  }
  if (!r->hasResult) {
    SetError(r, DCM_ERROR_INVALID_OPERATION, "dcmGetImage: no result (dcmExecute() has not succeeded)");
    return nullptr;
  }
  static_assert(sizeof(dcm::RGB) == 3 * sizeof(float), "RGB must be three packed floats");
  if (width) *width = r->result.width;
  if (height) *height = r->result.height;
  return r->result.image.empty() ? nullptr : &r->result.image[0].r;
}

DCM_API const uint8_t* dcmGetSampleMap(DCMReconstructor r, int* width, int* height) {
  if (width) *width = 0;
  if (height) *height = 0;
  if (!r) {
    SetError(nullptr, DCM_ERROR_INVALID_ARGUMENT, "dcmGetSampleMap: NULL reconstructor");
    return nullptr;
  }
  if (!r->hasResult) {
    SetError(r, DCM_ERROR_INVALID_OPERATION, "dcmGetSampleMap: no result (dcmExecute() has not succeeded)");
    return nullptr;
  }
  if (width) *width = r->result.workWidth;
  if (height) *height = r->result.workHeight;
  return r->sampleMap.data();
}

DCM_API double dcmGetStat(DCMReconstructor r, const char* name) {
  if (!CheckArgs(r, name, "dcmGetStat")) return 0.0;
  if (!r->hasResult) {
    SetError(r, DCM_ERROR_INVALID_OPERATION, "dcmGetStat: no result (dcmExecute() has not succeeded)");
    return 0.0;
  }
  const dcm::ReconstructionStats& s = r->result.stats;
  const std::string_view n(name);
  if (n == "exact_pixels") return double(s.exactPixels);
  if (n == "total_pixels") return double(s.totalPixels);
  if (n == "exact_fraction") return s.exactFraction();
  if (n == "provider_calls") return double(s.providerCalls);
  if (n == "non_finite_samples") return double(s.nonFiniteSamples);
  if (n == "clamped_samples") return double(s.clampedSamples);
  if (n == "smooth_blocks") return double(s.smoothBlocks);
  if (n == "simple_edge_blocks") return double(s.simpleEdgeBlocks);
  if (n == "complex_edge_blocks") return double(s.complexEdgeBlocks);
  if (n == "fallback_blocks") return double(s.fallbackBlocks);
  if (n == "time_provider_s") return s.timeProviderS;
  if (n == "time_guides_s") return s.timeGuidesS;
  if (n == "time_engine_s") return s.timeEngineS;
  if (n == "rounds") return double(r->schedule.rounds);
  if (n == "preview_stand_ins") return double(r->schedule.previewStandIns);
  if (n == "preview_corrected") return double(r->schedule.correction.pixels);
  if (n == "stopped_at_target") return r->schedule.stoppedAtTarget ? 1.0 : 0.0;
  if (r->quality) {
    const dcm::QualityReport& q = *r->quality;
    if (n == "estimate_from_preview") return q.estimateSource == dcm::EstimateSource::kPreview ? 1.0 : 0.0;
    if (n == "estimated_psnr") return q.estimate.psnr;
    if (n == "estimated_psnr_low") return q.estimate.low;
    if (n == "estimated_psnr_high") return q.estimate.high;
    if (n == "estimated_psnr_effective_pixels") return q.estimate.effective;
    if (n == "estimated_render_psnr") return q.renderEstimate.psnr;
    if (n == "estimated_render_psnr_low") return q.renderEstimate.low;
    if (n == "estimated_render_psnr_high") return q.renderEstimate.high;
    if (n == "estimate_against_converged") return q.againstConverged ? 1.0 : 0.0;
    if (n == "validation_pixels") return double(q.validationPixels);
    if (n == "quality_runs") return double(q.runs);
    if (n == "target_reached") return q.targetReached ? 1.0 : 0.0;
    if (n == "budget_bound") return q.budgetBound ? 1.0 : 0.0;
  } else if (const dcm::PsnrEstimate& e = r->schedule.correction.estimate; std::isfinite(e.low)) {
    // Without a goal, the preview correction's estimate against the converged image.
    if (n == "estimated_psnr") return e.psnr;
    if (n == "estimated_psnr_low") return e.low;
    if (n == "estimated_psnr_high") return e.high;
    if (n == "estimate_against_converged" || n == "estimate_from_preview") return 1.0;
  }
  Guard(r, "dcmGetStat", [&] { SetError(r, DCM_ERROR_INVALID_ARGUMENT, "dcmGetStat: unknown statistic '" + std::string(n) + "'"); });
  return 0.0;
}

DCM_API const char* dcmSampleReasonName(int reason) {
  if (reason < 0 || reason >= dcm::kSampleReasonCount) return "?";
  // ToString returns views of string literals: NUL-terminated.
  return dcm::ToString(dcm::SampleReason(reason)).data();
}

}  // extern "C"
