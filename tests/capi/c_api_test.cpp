// The C API through libdcm.so only (the engine's C++ symbols are hidden there).
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "dcm/dcm.h"

namespace {

/// A scene of two surfaces: a smooth ramp with a vertical step at x = split.
struct Scene {
  int width = 64, height = 48, split = 29;
  std::atomic<long> evaluated{0};
  std::atomic<int> inFlight{0};
  std::atomic<int> maxInFlight{0};
  std::atomic<bool> sawSplitBuffers{false};
  std::atomic<bool> sawOutOfRange{false};
  int failWith = 0;

  void Truth(int x, int y, float* L) const {
    const float base = x < split ? 0.2f : 0.7f;
    L[0] = base + 0.002f * float(y);
    L[1] = base * 0.5f + 0.001f * float(x);
    L[2] = 0.1f;
  }
};

int Evaluate(void* user, const int* xy, int count, float* rgb, float* li, float* lc) {
  auto* s = static_cast<Scene*>(user);
  const int now = ++s->inFlight;
  int seen = s->maxInFlight.load();
  while (now > seen && !s->maxInFlight.compare_exchange_weak(seen, now)) {
  }
  if (li || lc) s->sawSplitBuffers = true;
  for (int i = 0; i < count; ++i) {
    const int x = xy[2 * i], y = xy[2 * i + 1];
    if (x < 0 || y < 0 || x >= s->width || y >= s->height) s->sawOutOfRange = true;
    s->Truth(x, y, rgb + 3 * i);
    if (li && lc) {
      for (int c = 0; c < 3; ++c) {
        li[3 * i + c] = rgb[3 * i + c];
        lc[3 * i + c] = 0.f;
      }
    }
  }
  s->evaluated += count;
  --s->inFlight;
  return s->failWith;
}

std::string TakeError(DCMReconstructor r, DCMError* code = nullptr) {
  const char* m = nullptr;
  const DCMError e = dcmGetError(r, &m);
  if (code) *code = e;
  return m ? m : "(null)";
}

/// A reconstructor set up for `scene` with object IDs.
DCMReconstructor Make(Scene& scene, int flags = DCM_SAMPLE_THREAD_SAFE) {
  DCMReconstructor r = dcmNewReconstructor();
  std::vector<uint32_t> ids(size_t(scene.width * scene.height));
  for (int y = 0; y < scene.height; ++y)
    for (int x = 0; x < scene.width; ++x) ids[size_t(y * scene.width + x)] = x < scene.split ? 1u : 2u;
  dcmSetImageSize(r, scene.width, scene.height);
  dcmSetObjectIds(r, ids.data());
  dcmSetSampleFunction(r, Evaluate, &scene, flags);
  return r;
}

TEST(CApi, VersionMatchesHeader) {
  EXPECT_EQ(dcmGetApiVersion(), DCM_C_API_VERSION);
  EXPECT_STRNE(dcmGetVersionString(), "unknown");
  EXPECT_STREQ(dcmSampleReasonName(DCM_REASON_CORNER), "corner");
  EXPECT_STREQ(dcmSampleReasonName(DCM_REASON_INTERPOLATED), "interpolated");
  EXPECT_STREQ(dcmSampleReasonName(DCM_REASON_COUNT), "?");
  EXPECT_STREQ(dcmSampleReasonName(-1), "?");
}

TEST(CApi, MethodPresetsResetEveryOption) {
  DCMReconstructor r = dcmNewReconstructor();
  ASSERT_NE(r, nullptr);
  // dcm's defaults are what method "dcm" restores: the block and the
  // threshold depend on the regime, so they read as unset (0, -1).
  const int block = dcmGetInt(r, "elementary_block");
  const float threshold = dcmGetFloat(r, "contrast_threshold");
  EXPECT_EQ(block, 0);
  EXPECT_EQ(threshold, -1.f);
  EXPECT_EQ(dcmGetBool(r, "surface_aware"), 1);
  EXPECT_EQ(dcmGetBool(r, "adaptive_borders"), 1);
  dcmSetInt(r, "elementary_block", 32);
  dcmSetFloat(r, "contrast_threshold", 0.3f);
  EXPECT_EQ(dcmGetInt(r, "elementary_block"), 32);
  EXPECT_FLOAT_EQ(dcmGetFloat(r, "contrast_threshold"), 0.3f);
  dcmSetBool(r, "surface_aware", 0);
  dcmSetString(r, "method", "dcm");
  EXPECT_EQ(dcmGetInt(r, "elementary_block"), block) << "a preset resets overrides";
  EXPECT_EQ(dcmGetFloat(r, "contrast_threshold"), threshold);
  EXPECT_EQ(dcmGetBool(r, "surface_aware"), 1);
  // The published methods (Guo 1998; Scheel et al. 2001).
  EXPECT_EQ(dcmGetBool(r, "checkerboard"), 1);
  EXPECT_GT(dcmGetInt(r, "simple_surface_changes"), 2);
  EXPECT_GE(dcmGetInt(r, "fallback_shading_changes"), 0);
  // The directions too depend on the regime (more under the supersampled
  // rules), and the crossing fill applies under those rules only (dcm only).
  EXPECT_EQ(dcmGetInt(r, "directions"), 0);
  EXPECT_GT(dcmGetInt(r, "crossing_fill_reach"), 0);
  // A value set serves every regime; 0 (a negative float) unsets it again.
  dcmSetInt(r, "directions", 4);
  EXPECT_EQ(dcmGetInt(r, "directions"), 4);
  dcmSetFloat(r, "directions", 0.f);
  EXPECT_EQ(dcmGetInt(r, "directions"), 0);
  dcmSetFloat(r, "contrast_threshold", -1.f);
  EXPECT_EQ(dcmGetFloat(r, "contrast_threshold"), -1.f);
  dcmSetString(r, "thin_objects", "any-differs");
  dcmSetString(r, "thin_objects", "default");
  dcmSetString(r, "thin_objects", "sometimes");  // recorded as an error, taken below
  DCMError bad;
  EXPECT_NE(TakeError(r, &bad).find("thin-object test"), std::string::npos);
  EXPECT_EQ(bad, DCM_ERROR_INVALID_ARGUMENT);
  dcmSetString(r, "contrast_metric", "mitchell");
  dcmSetString(r, "contrast_metric", "loud");
  EXPECT_NE(TakeError(r, &bad).find("contrast metric: unknown value 'loud'"), std::string::npos);
  EXPECT_EQ(bad, DCM_ERROR_INVALID_ARGUMENT);
  // The twins of API version 3 are gone.
  dcmSetInt(r, "directions_supersampled", 16);
  EXPECT_NE(TakeError(r, &bad).find("unknown integer option 'directions_supersampled'"), std::string::npos);
  dcmSetString(r, "method", "paper");
  EXPECT_EQ(dcmGetBool(r, "checkerboard"), 0);
  EXPECT_EQ(dcmGetInt(r, "simple_surface_changes"), 2);
  EXPECT_EQ(dcmGetInt(r, "fallback_shading_changes"), -1);  // every change counts
  // The paper's values serve every regime.
  EXPECT_GT(dcmGetFloat(r, "contrast_threshold"), 0.f);
  EXPECT_GT(dcmGetInt(r, "directions"), 0);
  EXPECT_GT(dcmGetInt(r, "elementary_block"), 0);
  EXPECT_EQ(dcmGetInt(r, "crossing_fill_reach"), 0);
  EXPECT_EQ(dcmGetBool(r, "surface_aware"), 0);
  EXPECT_EQ(dcmGetBool(r, "texture_split"), 1);
  EXPECT_EQ(dcmGetBool(r, "fallback"), 1);
  EXPECT_EQ(dcmGetBool(r, "adaptive_borders"), 0);
  dcmSetString(r, "method", "guo");
  EXPECT_EQ(dcmGetBool(r, "surface_aware"), 0);
  EXPECT_EQ(dcmGetBool(r, "texture_split"), 0);
  EXPECT_EQ(dcmGetBool(r, "fallback"), 0);
  DCMError code;
  EXPECT_EQ(TakeError(r, &code), "");
  EXPECT_EQ(code, DCM_ERROR_NONE);
  dcmReleaseReconstructor(r);
}

TEST(CApi, SettersMapToOptions) {
  DCMReconstructor r = dcmNewReconstructor();
  dcmSetInt(r, "min_block", 2);
  dcmSetFloat(r, "contrast_threshold", 0.125f);
  dcmSetFloat(r, "batch_size", 512.f);
  dcmSetBool(r, "lazy_evaluation", 0);
  dcmSetInt(r, "full_evaluation", 1);
  EXPECT_EQ(dcmGetInt(r, "min_block"), 2);
  EXPECT_FLOAT_EQ(dcmGetFloat(r, "contrast_threshold"), 0.125f);
  EXPECT_EQ(dcmGetInt(r, "batch_size"), 512);
  EXPECT_EQ(dcmGetBool(r, "lazy_evaluation"), 0);
  EXPECT_EQ(dcmGetBool(r, "full_evaluation"), 1);
  EXPECT_EQ(TakeError(r), "");
  dcmSetFloat(r, "batch_size", 1.5f);
  DCMError code;
  EXPECT_NE(TakeError(r, &code).find("whole number"), std::string::npos);
  EXPECT_EQ(code, DCM_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(dcmGetInt(r, "batch_size"), 512);
  dcmReleaseReconstructor(r);
}

TEST(CApi, UnknownNamesAndValuesAreErrorsOnTheHandle) {
  DCMReconstructor r = dcmNewReconstructor();
  dcmSetInt(r, "no_such_option", 3);
  dcmSetString(r, "object_test", "bogus");  // second error: the first one is kept
  DCMError code;
  const std::string m = TakeError(r, &code);
  EXPECT_EQ(code, DCM_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(m.find("no_such_option"), std::string::npos) << m;
  EXPECT_EQ(TakeError(r, &code), "") << "dcmGetError clears the error";
  EXPECT_EQ(code, DCM_ERROR_NONE);
  dcmSetString(r, "object_test", "bogus");
  EXPECT_NE(TakeError(r, &code).find("bogus"), std::string::npos);
  dcmSetString(r, "thin_objects", nullptr);
  EXPECT_NE(TakeError(r, &code).find("NULL value"), std::string::npos);
  dcmSetBool(r, "elementary_block", 1);  // not a bool option
  EXPECT_EQ(code, DCM_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(TakeError(r, &code).find("unknown bool option"), std::string::npos);
  EXPECT_EQ(dcmGetFloat(r, "surface_aware"), 0.f);
  EXPECT_NE(TakeError(r, &code).find("unknown float option"), std::string::npos);
  dcmSetString(r, nullptr, "x");
  EXPECT_NE(TakeError(r, &code).find("NULL option name"), std::string::npos);
  dcmReleaseReconstructor(r);
}

TEST(CApi, NullHandleErrorsArePerThread) {
  DCMError code;
  TakeError(nullptr);
  dcmSetInt(nullptr, "threads", 1);
  dcmExecute(nullptr);
  const std::string m = TakeError(nullptr, &code);
  EXPECT_EQ(code, DCM_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(m.find("dcmSetInt: NULL reconstructor"), std::string::npos) << m;
  EXPECT_EQ(TakeError(nullptr, &code), "");
  EXPECT_EQ(code, DCM_ERROR_NONE);
  EXPECT_EQ(dcmGetImage(nullptr, nullptr, nullptr), nullptr);
  EXPECT_EQ(TakeError(nullptr, &code).find("dcmGetImage"), 0u);
  dcmReleaseReconstructor(nullptr);  // ignored
  EXPECT_EQ(TakeError(nullptr, &code), "");
}

TEST(CApi, ExecuteNeedsSizeAndSampleFunction) {
  DCMReconstructor r = dcmNewReconstructor();
  EXPECT_EQ(dcmExecute(r), DCM_ERROR_INVALID_OPERATION);
  EXPECT_NE(TakeError(r).find("dcmSetImageSize"), std::string::npos);
  uint32_t id = 1;
  dcmSetObjectIds(r, &id);
  EXPECT_NE(TakeError(r).find("call dcmSetImageSize() first"), std::string::npos);
  dcmSetImageSize(r, 0, 5);
  EXPECT_NE(TakeError(r).find("unusable size 0x5"), std::string::npos);
  dcmSetImageSize(r, 16, 16);
  EXPECT_EQ(dcmExecute(r), DCM_ERROR_INVALID_OPERATION);
  EXPECT_NE(TakeError(r).find("dcmSetSampleFunction"), std::string::npos);
  EXPECT_EQ(dcmGetImage(r, nullptr, nullptr), nullptr);
  EXPECT_NE(TakeError(r).find("no result"), std::string::npos);
  EXPECT_EQ(dcmGetStat(r, "exact_fraction"), 0.0);
  EXPECT_NE(TakeError(r).find("no result"), std::string::npos);
  dcmReleaseReconstructor(r);
}

TEST(CApi, ReconstructsTwoSurfacesWithFewExactPixels) {
  Scene scene;
  DCMReconstructor r = Make(scene);
  dcmSetInt(r, "threads", 2);
  dcmSetInt(r, "batch_size", 64);
  ASSERT_EQ(dcmExecute(r), DCM_ERROR_NONE) << TakeError(r);
  int w = 0, h = 0, mw = 0, mh = 0;
  const float* img = dcmGetImage(r, &w, &h);
  const uint8_t* map = dcmGetSampleMap(r, &mw, &mh);
  ASSERT_NE(img, nullptr);
  ASSERT_NE(map, nullptr);
  ASSERT_EQ(w, scene.width);
  ASSERT_EQ(h, scene.height);
  ASSERT_EQ(mw, scene.width);
  ASSERT_EQ(mh, scene.height);
  long exact = 0;
  double maxErr = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float L[3];
      scene.Truth(x, y, L);
      for (int c = 0; c < 3; ++c) maxErr = std::max(maxErr, double(std::fabs(img[3 * (y * w + x) + c] - L[c])));
      ASSERT_LT(map[y * w + x], DCM_REASON_COUNT);
      if (map[y * w + x] != DCM_REASON_INTERPOLATED) ++exact;
    }
  EXPECT_LT(maxErr, 1e-4) << "a linear ramp per surface is reconstructed exactly";
  EXPECT_EQ(exact, scene.evaluated.load()) << "every exact pixel once, through the callback";
  EXPECT_EQ(double(exact), dcmGetStat(r, "exact_pixels"));
  EXPECT_EQ(double(w * h), dcmGetStat(r, "total_pixels"));
  EXPECT_GT(dcmGetStat(r, "exact_fraction"), 0.0);
  EXPECT_LT(dcmGetStat(r, "exact_fraction"), 0.5);
  EXPECT_GT(dcmGetStat(r, "provider_calls"), 1.0);
  EXPECT_FALSE(scene.sawSplitBuffers.load()) << "no texture guide: no split buffers";
  EXPECT_FALSE(scene.sawOutOfRange.load());
  dcmGetStat(r, "no_such_stat");
  EXPECT_NE(TakeError(r).find("no_such_stat"), std::string::npos);
  dcmReleaseReconstructor(r);
}

TEST(CApi, RoundCostPlansOnThePreviewInFewCalls) {
  Scene plain, planned;
  DCMReconstructor a = Make(plain, 0);
  DCMReconstructor b = Make(planned, 0);
  // Not thread safe: each Evaluate is one callback call, so calls count rounds.
  std::vector<float> preview(size_t(planned.width * planned.height) * 3);
  for (int y = 0; y < planned.height; ++y)
    for (int x = 0; x < planned.width; ++x) planned.Truth(x, y, &preview[3 * size_t(y * planned.width + x)]);
  dcmSetPreview(b, planned.width, planned.height, preview.data(), nullptr, nullptr);
  dcmSetRoundCost(b, 0.5, 0.0, 3);
  ASSERT_EQ(dcmExecute(a), DCM_ERROR_NONE) << TakeError(a);
  ASSERT_EQ(dcmExecute(b), DCM_ERROR_NONE) << TakeError(b);
  // An exact preview plans exactly the pixels the engine needs: one round,
  // no stand-in, the same image and the same pixels as level by level.
  EXPECT_EQ(dcmGetStat(b, "rounds"), 1.0);
  EXPECT_EQ(dcmGetStat(b, "provider_calls"), 1.0);
  EXPECT_EQ(dcmGetStat(b, "preview_stand_ins"), 0.0);
  EXPECT_GT(dcmGetStat(a, "provider_calls"), 1.0);
  EXPECT_EQ(dcmGetStat(a, "rounds"), 0.0);
  EXPECT_EQ(planned.evaluated.load(), plain.evaluated.load());
  int w = 0, h = 0;
  const float* ia = dcmGetImage(a, &w, &h);
  const float* ib = dcmGetImage(b, nullptr, nullptr);
  EXPECT_EQ(std::vector<float>(ia, ia + 3 * w * h), std::vector<float>(ib, ib + 3 * w * h));
  // Bad costs and previews are errors on the handle.
  dcmSetRoundCost(b, -1.0, 0.0, 3);
  EXPECT_NE(TakeError(b).find("dcmSetRoundCost"), std::string::npos);
  dcmSetRoundCost(b, 1.0, 0.0, 0);
  EXPECT_NE(TakeError(b).find("max_rounds"), std::string::npos);
  dcmSetPreview(b, planned.width + 1, planned.height, preview.data(), nullptr, nullptr);
  EXPECT_NE(TakeError(b).find("dcmSetPreview"), std::string::npos);
  dcmReleaseReconstructor(a);
  dcmReleaseReconstructor(b);
}

TEST(CApi, APreviewWithItsVarianceCorrectsTheInterpolatedPixels) {
  Scene scene;
  DCMReconstructor r = Make(scene, 0);
  const size_t n = size_t(scene.width * scene.height);
  // A preview 0.1 above the truth everywhere, said to have sd 0.01: its
  // departure from the interpolation is far beyond its noise, so the
  // interpolated pixels follow it by b / (b + v) = 0.0099 / 0.01 = 0.99.
  std::vector<float> preview(3 * n), variance(3 * n, 1e-4f);
  for (int y = 0; y < scene.height; ++y)
    for (int x = 0; x < scene.width; ++x) {
      float* p = &preview[3 * size_t(y * scene.width + x)];
      scene.Truth(x, y, p);
      for (int c = 0; c < 3; ++c) p[c] += 0.1f;
    }
  dcmSetPreview(r, scene.width, scene.height, preview.data(), nullptr, nullptr);
  dcmSetPreviewVariance(r, variance.data());
  dcmSetRoundCost(r, 0.5, 0.0, 3);
  ASSERT_EQ(dcmExecute(r), DCM_ERROR_NONE) << TakeError(r);
  EXPECT_GT(dcmGetStat(r, "preview_corrected"), 0.0);
  int w = 0, h = 0;
  const float* image = dcmGetImage(r, &w, &h);
  const uint8_t* map = dcmGetSampleMap(r, nullptr, nullptr);
  int interpolated = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float truth[3];
      scene.Truth(x, y, truth);
      const size_t i = size_t(y * w + x);
      // Exact pixels keep the truth; interpolated ones are 0.099 above it
      // (windows at the image's edge count fewer pixels, not other values).
      const float expected = map[i] == DCM_REASON_INTERPOLATED ? truth[0] + 0.099f : truth[0];
      EXPECT_NEAR(image[3 * i], expected, 2e-3f) << x << "," << y;
      interpolated += map[i] == DCM_REASON_INTERPOLATED;
    }
  EXPECT_GT(interpolated, 0);
  // dcmSetPreview() removes the variance: no correction.
  dcmSetPreview(r, scene.width, scene.height, preview.data(), nullptr, nullptr);
  ASSERT_EQ(dcmExecute(r), DCM_ERROR_NONE) << TakeError(r);
  EXPECT_EQ(dcmGetStat(r, "preview_corrected"), 0.0);
  // A coarser preview takes no variance.
  dcmSetPreview(r, scene.width / 2, scene.height / 2, preview.data(), nullptr, nullptr);
  dcmSetPreviewVariance(r, variance.data());
  EXPECT_NE(TakeError(r).find("dcmSetPreviewVariance"), std::string::npos);
  dcmReleaseReconstructor(r);
}

TEST(CApi, TargetAndBudgetReportTheEstimateAndStayWithinTheBudget) {
  Scene scene;
  DCMReconstructor r = Make(scene);
  dcmSetFloat(r, "target_psnr", 40.f);
  dcmSetFloat(r, "budget", 0.4f);
  EXPECT_EQ(dcmGetFloat(r, "target_psnr"), 40.f);
  ASSERT_EQ(dcmExecute(r), DCM_ERROR_NONE) << TakeError(r);
  // The ramp is reconstructed exactly: no validation pixel errs (+inf dB).
  EXPECT_GE(dcmGetStat(r, "estimated_psnr_low"), 40.0);
  EXPECT_GE(dcmGetStat(r, "estimated_psnr_effective_pixels"), 1.0);  // a count of pixels, or +inf
  EXPECT_EQ(dcmGetStat(r, "target_reached"), 1.0);
  EXPECT_GT(dcmGetStat(r, "validation_pixels"), 1.0);
  // Every pixel evaluated (validation included) is counted once, within the budget.
  EXPECT_EQ(double(scene.evaluated.load()), dcmGetStat(r, "exact_pixels"));
  EXPECT_LE(dcmGetStat(r, "exact_fraction"), 0.4);
  // The callback reports no variance: the estimate is against the full render.
  EXPECT_EQ(dcmGetStat(r, "estimate_against_converged"), 0.0);
  EXPECT_TRUE(std::isnan(dcmGetStat(r, "estimated_render_psnr")));
  // A target of the render's own PSNR needs variance, and not also a target in dB.
  dcmSetBool(r, "target_render", 1);
  EXPECT_EQ(dcmGetBool(r, "target_render"), 1);
  EXPECT_NE(dcmExecute(r), DCM_ERROR_NONE);
  EXPECT_NE(TakeError(r).find("--target-psnr render"), std::string::npos);
  dcmSetBool(r, "target_render", 0);
  dcmSetFloat(r, "target_psnr", 120.f);
  EXPECT_NE(TakeError(r).find("target_psnr"), std::string::npos);
  dcmSetFloat(r, "budget", -0.5f);
  EXPECT_NE(TakeError(r).find("budget"), std::string::npos);
  dcmReleaseReconstructor(r);
}

TEST(CApi, ATargetWithAPreviewOfKnownVarianceIsJudgedByThePreview) {
  // The preview is the truth plus noise of sd 0.01 (its own PSNR about 40 dB,
  // enough to tell) with that variance; rounds cost: the target is judged by
  // the preview's estimate, against the converged image, with no validation
  // pixel, and every pixel rendered is counted once.
  Scene scene;
  DCMReconstructor r = Make(scene, 0);
  const size_t n = size_t(scene.width * scene.height);
  std::vector<float> preview(3 * n), variance(3 * n, 1e-4f);
  std::mt19937 rng(11);
  std::normal_distribution<float> noise(0.f, 0.01f);
  for (size_t i = 0; i < n; ++i) {
    scene.Truth(int(i % size_t(scene.width)), int(i / size_t(scene.width)), &preview[3 * i]);
    for (int c = 0; c < 3; ++c) preview[3 * i + c] += noise(rng);
  }
  dcmSetPreview(r, scene.width, scene.height, preview.data(), nullptr, nullptr);
  dcmSetPreviewVariance(r, variance.data());
  dcmSetRoundCost(r, 0.5, 0.0, 3);
  // Without a goal: the preview's estimate is reported all the same.
  ASSERT_EQ(dcmExecute(r), DCM_ERROR_NONE) << TakeError(r);
  EXPECT_EQ(dcmGetStat(r, "estimate_from_preview"), 1.0);
  EXPECT_GT(dcmGetStat(r, "estimated_psnr"), 30.0) << "a ramp and a step: interpolation errs little";
  scene.evaluated = 0;
  dcmSetFloat(r, "target_psnr", 35.f);
  ASSERT_EQ(dcmExecute(r), DCM_ERROR_NONE) << TakeError(r);
  EXPECT_EQ(dcmGetStat(r, "estimate_from_preview"), 1.0);
  EXPECT_EQ(dcmGetStat(r, "estimate_against_converged"), 1.0);
  EXPECT_EQ(dcmGetStat(r, "validation_pixels"), 0.0);
  EXPECT_EQ(dcmGetStat(r, "target_reached"), 1.0);
  EXPECT_GE(dcmGetStat(r, "estimated_psnr_low"), 35.0);
  EXPECT_GE(dcmGetStat(r, "estimated_psnr_effective_pixels"), 1.0);
  // A round the target did not need leaves its pixels at their preview value.
  const double stopped = dcmGetStat(r, "stopped_at_target");
  EXPECT_TRUE(stopped == 0.0 || (stopped == 1.0 && dcmGetStat(r, "preview_stand_ins") > 0)) << stopped;
  EXPECT_EQ(double(scene.evaluated.load()), dcmGetStat(r, "exact_pixels"));
  // A budget alone (API version 8) is judged by the preview too: never passed.
  const double total = double(scene.width) * scene.height;
  dcmSetFloat(r, "target_psnr", 0.f);
  dcmSetFloat(r, "budget", 0.2f);
  scene.evaluated = 0;
  ASSERT_EQ(dcmExecute(r), DCM_ERROR_NONE) << TakeError(r);
  EXPECT_EQ(dcmGetStat(r, "estimate_from_preview"), 1.0);
  EXPECT_EQ(dcmGetStat(r, "validation_pixels"), 0.0);
  EXPECT_LE(dcmGetStat(r, "exact_pixels"), 0.2 * total);
  EXPECT_EQ(double(scene.evaluated.load()), dcmGetStat(r, "exact_pixels"));
  // With a target too: whichever binds first (here the ladder's plateau, at
  // 1.3 % exact), judged by the preview.
  dcmSetFloat(r, "target_psnr", 90.f);
  ASSERT_EQ(dcmExecute(r), DCM_ERROR_NONE) << TakeError(r);
  EXPECT_EQ(dcmGetStat(r, "estimate_from_preview"), 1.0);
  EXPECT_EQ(dcmGetStat(r, "target_reached"), 0.0);
  EXPECT_LE(dcmGetStat(r, "exact_pixels"), 0.2 * total);
  // A budget below the plan at the coarsest threshold: an error naming it.
  dcmSetFloat(r, "target_psnr", 0.f);
  dcmSetFloat(r, "budget", 0.001f);
  scene.evaluated = 0;
  EXPECT_EQ(dcmExecute(r), DCM_ERROR_RECONSTRUCTION);
  EXPECT_NE(TakeError(r).find("--budget"), std::string::npos);
  EXPECT_EQ(scene.evaluated.load(), 0) << "before any pixel is rendered";
  dcmReleaseReconstructor(r);
}

TEST(CApi, FullEvaluationEvaluatesEveryPixel) {
  Scene scene;
  DCMReconstructor r = Make(scene);
  dcmSetBool(r, "full_evaluation", 1);
  ASSERT_EQ(dcmExecute(r), DCM_ERROR_NONE) << TakeError(r);
  EXPECT_EQ(dcmGetStat(r, "exact_fraction"), 1.0);
  EXPECT_EQ(scene.evaluated.load(), long(scene.width * scene.height));
  dcmReleaseReconstructor(r);
}

TEST(CApi, CallbackFailureStopsWithCallbackError) {
  Scene scene;
  scene.failWith = 7;
  DCMReconstructor r = Make(scene);
  DCMError code;
  EXPECT_EQ(dcmExecute(r), DCM_ERROR_CALLBACK);
  const std::string m = TakeError(r, &code);
  EXPECT_EQ(code, DCM_ERROR_CALLBACK);
  EXPECT_NE(m.find("returned 7"), std::string::npos) << m;
  EXPECT_EQ(dcmGetImage(r, nullptr, nullptr), nullptr) << "no result after a failure";
  TakeError(r);
  scene.failWith = 0;
  EXPECT_EQ(dcmExecute(r), DCM_ERROR_NONE) << "the handle is usable again";
  dcmReleaseReconstructor(r);
}

TEST(CApi, InvalidOptionValuesAreReportedByExecute) {
  Scene scene;
  DCMReconstructor r = Make(scene);
  dcmSetInt(r, "elementary_block", 6);
  DCMError code;
  EXPECT_EQ(dcmExecute(r), DCM_ERROR_RECONSTRUCTION);
  const std::string m = TakeError(r, &code);
  EXPECT_NE(m.find("elementaryBlock"), std::string::npos) << m;
  EXPECT_EQ(scene.evaluated.load(), 0);
  dcmSetInt(r, "elementary_block", 8);
  dcmSetInt(r, "neighbour_directions", -1);
  EXPECT_EQ(dcmExecute(r), DCM_ERROR_RECONSTRUCTION);
  const std::string n = TakeError(r, &code);
  EXPECT_NE(n.find("neighbourDirections"), std::string::npos) << n;
  EXPECT_EQ(scene.evaluated.load(), 0);
  dcmReleaseReconstructor(r);
}

TEST(CApi, NotThreadSafeCallbackIsCalledFromOneThreadAtATime) {
  Scene scene;
  scene.width = 256;
  scene.height = 256;
  DCMReconstructor r = Make(scene, 0);
  dcmSetInt(r, "threads", 4);
  dcmSetInt(r, "batch_size", 16);
  ASSERT_EQ(dcmExecute(r), DCM_ERROR_NONE) << TakeError(r);
  EXPECT_EQ(scene.maxInFlight.load(), 1);
  EXPECT_GT(dcmGetStat(r, "provider_calls"), 4.0);
  dcmReleaseReconstructor(r);
}

TEST(CApi, SplitBuffersWithTextureAndFlag) {
  Scene scene;
  DCMReconstructor r = Make(scene, DCM_SAMPLE_SPLIT);
  std::vector<float> tau(size_t(3 * scene.width * scene.height), 1.f);
  dcmSetTexture(r, tau.data());
  ASSERT_EQ(dcmExecute(r), DCM_ERROR_NONE) << TakeError(r);
  EXPECT_TRUE(scene.sawSplitBuffers.load());
  dcmReleaseReconstructor(r);
}

TEST(CApi, DownsampleGivesTheOutputResolution) {
  Scene scene;
  DCMReconstructor r = Make(scene);
  dcmSetInt(r, "downsample", 2);
  ASSERT_EQ(dcmExecute(r), DCM_ERROR_NONE) << TakeError(r);
  int w = 0, h = 0, mw = 0, mh = 0;
  ASSERT_NE(dcmGetImage(r, &w, &h), nullptr);
  ASSERT_NE(dcmGetSampleMap(r, &mw, &mh), nullptr);
  EXPECT_EQ(w, scene.width / 2);
  EXPECT_EQ(h, scene.height / 2);
  EXPECT_EQ(mw, scene.width);
  EXPECT_EQ(mh, scene.height);
  dcmSetInt(r, "downsample", 5);
  EXPECT_EQ(dcmExecute(r), DCM_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(TakeError(r).find("not a multiple of downsample 5"), std::string::npos);
  dcmReleaseReconstructor(r);
}

TEST(CApi, ProgressIsReported) {
  Scene scene;
  DCMReconstructor r = Make(scene);
  struct P {
    int calls = 0;
    float last = -1;
    bool stageNamed = true;
  } p;
  dcmSetProgressFunction(
      r,
      [](void* u, float f, const char* stage) {
        auto* pp = static_cast<P*>(u);
        if (!stage || !*stage) pp->stageNamed = false;
        pp->last = f;
        ++pp->calls;
      },
      &p);
  ASSERT_EQ(dcmExecute(r), DCM_ERROR_NONE) << TakeError(r);
  EXPECT_GT(p.calls, 0);
  EXPECT_LE(p.last, 1.f);
  EXPECT_TRUE(p.stageNamed);
  dcmReleaseReconstructor(r);
}

TEST(CApi, RetainKeepsTheHandleAlive) {
  Scene scene;
  DCMReconstructor r = Make(scene);
  dcmRetainReconstructor(r);
  dcmReleaseReconstructor(r);
  EXPECT_EQ(dcmExecute(r), DCM_ERROR_NONE) << "still alive after one release";
  dcmReleaseReconstructor(r);
}

/// The two-surface scene with Gaussian noise of sd 0.03 per pixel (fixed by
/// the pixel), reporting its variance when asked.
struct NoisyScene : Scene {
  std::atomic<bool> sawVarianceBuffer{false};
};

int EvaluateNoisy(void* user, const int* xy, int count, float* rgb, float* li, float* lc, float* variance) {
  auto* s = static_cast<NoisyScene*>(user);
  if (variance) s->sawVarianceBuffer = true;
  for (int i = 0; i < count; ++i) {
    const int x = xy[2 * i], y = xy[2 * i + 1];
    s->Truth(x, y, rgb + 3 * i);
    // A deviate fixed by the pixel (Box-Muller from a hash).
    uint32_t h = uint32_t(x) * 0x9e3779b1u ^ uint32_t(y) * 0x85ebca6bu;
    h ^= h >> 15, h *= 0x2c1b3c6du, h ^= h >> 12, h *= 0x297a2d39u, h ^= h >> 15;
    const double u1 = (double(h >> 8) + 0.5) * 0x1p-24, u2 = double((h * 2654435761u) >> 8) * 0x1p-24;
    const float n = float(std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2));
    for (int c = 0; c < 3; ++c) {
      rgb[3 * i + c] += 0.03f * n;
      if (variance) variance[3 * i + c] = 0.03f * 0.03f;
      if (li && lc) li[3 * i + c] = rgb[3 * i + c], lc[3 * i + c] = 0.f;
    }
  }
  s->evaluated += count;
  return 0;
}

}  // namespace

TEST(CApi, NoisySampleFunctionReportsVariance) {
  // With the variance reported, the engine does not chase the noise: fewer
  // exact pixels than with the noise taken at face value (noise_significance
  // 0), on the same samples and the same lattice (elementary_block 16: the
  // blocks of noiseless samples for both).
  auto exactPixels = [](float significance, bool* sawVariance) {
    NoisyScene scene;
    DCMReconstructor r = Make(scene);
    dcmSetNoisySampleFunction(r, EvaluateNoisy, &scene, DCM_SAMPLE_THREAD_SAFE);
    dcmSetFloat(r, "noise_significance", significance);
    dcmSetInt(r, "elementary_block", 16);
    EXPECT_FLOAT_EQ(dcmGetFloat(r, "noise_significance"), significance);
    EXPECT_EQ(dcmExecute(r), DCM_ERROR_NONE) << TakeError(r);
    *sawVariance = scene.sawVarianceBuffer;
    const long n = scene.evaluated;
    dcmReleaseReconstructor(r);
    return n;
  };
  bool withVariance = false, without = true;
  const long aware = exactPixels(1.5f, &withVariance), literal = exactPixels(0.f, &without);
  EXPECT_TRUE(withVariance) << "the engine asks for the variance when it weighs noise";
  EXPECT_FALSE(without) << "and not when it ignores it";
  EXPECT_LT(aware, literal);
}

namespace {

/// One surface folded at x = kFold: the light is continuous there but turns
/// from rising to falling (the contrast test alone does not see it).
constexpr int kFoldW = 64, kFoldH = 48, kFold = 29;
float Folded(int x) { return x < kFold ? 0.2f + 0.006f * float(x) : 0.2f + 0.006f * float(kFold) - 0.009f * float(x - kFold); }

int EvaluateFolded(void*, const int* xy, int count, float* rgb, float*, float*) {
  for (int i = 0; i < count; ++i)
    for (int c = 0; c < 3; ++c) rgb[3 * i + c] = Folded(xy[2 * i]);
  return 0;
}

}  // namespace

TEST(CApi, NormalGuidesMarkCreases) {
  // Normals turn by 90 degrees at the fold: with crease_angle 30 the fold is
  // a surface change and the pixels next to it come out (nearly) exact;
  // with crease_angle 0 the normals are ignored and the fold is smoothed.
  auto errorNearFold = [](float creaseAngle) {
    DCMReconstructor r = dcmNewReconstructor();
    dcmSetImageSize(r, kFoldW, kFoldH);
    std::vector<float> n(size_t(3 * kFoldW * kFoldH));
    for (int y = 0; y < kFoldH; ++y)
      for (int x = 0; x < kFoldW; ++x) n[size_t(3 * (y * kFoldW + x) + (x < kFold ? 0 : 1))] = 1.f;
    dcmSetNormals(r, n.data());
    dcmSetSampleFunction(r, EvaluateFolded, nullptr, DCM_SAMPLE_THREAD_SAFE);
    dcmSetFloat(r, "crease_angle", creaseAngle);
    EXPECT_EQ(dcmExecute(r), DCM_ERROR_NONE) << TakeError(r);
    int w = 0, h = 0;
    const float* rgb = dcmGetImage(r, &w, &h);
    double err = 0;
    for (int y = 0; y < h; ++y)
      for (int x = kFold - 6; x <= kFold + 6; ++x) err += std::fabs(rgb[3 * (y * w + x)] - Folded(x));
    dcmReleaseReconstructor(r);
    return err / (13.0 * h);
  };
  const double with = errorNearFold(30.f), without = errorNearFold(0.f);
  // Measured: float rounding against ~0.02; a factor 3 is asked.
  EXPECT_LT(3 * with, without) << "with normals " << with << ", without " << without;
}

namespace {

struct Levels {
  std::vector<int> seen;
  std::vector<float> last;
  int width = 0, height = 0;
};

void OnLevel(void* user, int level, int w, int h, const float* rgb) {
  auto* l = static_cast<Levels*>(user);
  l->seen.push_back(level);
  l->width = w, l->height = h;
  l->last.assign(rgb, rgb + 3 * w * h);
}

}  // namespace

TEST(CApi, LevelFunctionGivesProgressiveImages) {
  // A picture after refinement levels, coarsest first (a level the image no
  // longer needs is skipped); the last one is the final working image (here
  // the output: no downsampling).
  Scene scene;
  DCMReconstructor r = Make(scene);
  Levels levels;
  dcmSetLevelFunction(r, OnLevel, &levels);
  ASSERT_EQ(dcmExecute(r), DCM_ERROR_NONE) << TakeError(r);
  ASSERT_GE(levels.seen.size(), 2u);
  EXPECT_EQ(levels.seen.front(), 0);
  for (size_t i = 1; i < levels.seen.size(); ++i) EXPECT_GT(levels.seen[i], levels.seen[i - 1]);
  int w = 0, h = 0;
  const float* rgb = dcmGetImage(r, &w, &h);
  ASSERT_EQ(levels.width, w);
  ASSERT_EQ(levels.height, h);
  EXPECT_EQ(levels.last, std::vector<float>(rgb, rgb + 3 * w * h));
  dcmReleaseReconstructor(r);
}

namespace {

// DCM_SAMPLE_HARD_SHADOWS_GUIDED: the host's guides show every hard shadow,
// so the smooth blocks get no centre probes: fewer exact pixels on the same
// two flat surfaces.
TEST(CApi, HardShadowsGuidedSkipsTheCentreProbes) {
  Scene a, b;
  DCMReconstructor probed = Make(a), guided = Make(b, DCM_SAMPLE_THREAD_SAFE | DCM_SAMPLE_HARD_SHADOWS_GUIDED);
  ASSERT_EQ(dcmExecute(probed), DCM_ERROR_NONE) << TakeError(probed);
  ASSERT_EQ(dcmExecute(guided), DCM_ERROR_NONE) << TakeError(guided);
  EXPECT_LT(dcmGetStat(guided, "exact_pixels"), dcmGetStat(probed, "exact_pixels"));
  dcmReleaseReconstructor(probed);
  dcmReleaseReconstructor(guided);
}

}  // namespace

#if !defined(__SANITIZE_ADDRESS__)  // RLIMIT_AS and ASan's shadow memory exclude each other
namespace {

int ConstantGray(void*, const int*, int count, float* rgb, float*, float*) {
  for (int i = 0; i < 3 * count; ++i) rgb[i] = 0.5f;
  return 0;
}

TEST(CApi, OutOfMemoryIsAnErrorStatus) {
  // A 32768x32768 image (the largest size dcmSetImageSize accepts, 2^30
  // pixels) needs tens of GiB of working images; in a child whose address
  // space is limited to 1 GiB the allocation fails, and dcmExecute must
  // return DCM_ERROR_OUT_OF_MEMORY with a message, not let std::bad_alloc out.
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const rlimit limit{rlim_t(1) << 30, rlim_t(1) << 30};
    if (::setrlimit(RLIMIT_AS, &limit) != 0) _exit(101);
    DCMReconstructor r = dcmNewReconstructor();
    if (!r) _exit(102);
    dcmSetInt(r, "threads", 1);
    dcmSetImageSize(r, 32768, 32768);
    dcmSetSampleFunction(r, ConstantGray, nullptr, 0);
    const DCMError code = dcmExecute(r);
    const char* message = nullptr;
    dcmGetError(r, &message);
    const bool named = message && std::string(message).find("out of memory while reconstructing") != std::string::npos;
    _exit(code == DCM_ERROR_OUT_OF_MEMORY ? (named ? 0 : 103) : 110 + int(code));
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << WTERMSIG(status);
  EXPECT_EQ(WEXITSTATUS(status), 0) << "101: setrlimit failed, 103: message without the step, 110+N: error code N";
}
}  // namespace
#endif
