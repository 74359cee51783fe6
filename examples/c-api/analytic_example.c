/* dcm's C API with an analytic "renderer": the exact value of every pixel is
 * closed-form, so the reconstruction can be checked against the truth.
 *
 * The scene (W x H working pixels): a background lit by smooth, non-linear gradients
 * (object 1), a disc (object 2, its own shader) with a checker texture tau,
 * and the radiance split as L = L_i * tau + L_c. The renderer hands dcm the
 * cheap guides (object ID, shader ID, tau) as images and evaluates exact
 * samples in batches through a callback that counts the pixels it was asked
 * for.
 *
 * Prints the exact fraction, the callback's pixel count and the error against
 * the analytic image; exits 0 only when fewer than all pixels were evaluated,
 * the statistics agree with the callback and the error is within tolerance. */
#include <dcm/dcm.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { W = 160, H = 120 };

typedef struct Scene {
  long evaluated; /* pixels the callback evaluated */
  long calls;     /* callback invocations */
} Scene;

static int OnDisc(int x, int y) {
  const double dx = x + 0.5 - 96.0, dy = y + 0.5 - 58.0;
  return dx * dx + dy * dy < 34.0 * 34.0;
}

static void Tau(int x, int y, float tau[3]) {
  const int check = ((x / 8) + (y / 8)) & 1;
  if (!OnDisc(x, y)) {
    tau[0] = tau[1] = tau[2] = 1.f;
  } else if (check) {
    tau[0] = 0.9f; tau[1] = 0.7f; tau[2] = 0.3f;
  } else {
    tau[0] = 0.3f; tau[1] = 0.5f; tau[2] = 0.8f;
  }
}

/* Radiance before texturing (L_i) and the unmodulated part (L_c). */
static void Split(int x, int y, float li[3], float lc[3]) {
  const float u = (float)x / W, v = (float)y / H;
  if (OnDisc(x, y)) {
    const float shade = 0.4f + 0.5f * (1.f - v) * (1.f - v);
    li[0] = li[1] = li[2] = shade;
    lc[0] = 0.02f; lc[1] = 0.02f; lc[2] = 0.05f * u;
  } else {
    li[0] = 0.2f + 0.6f * u * u; li[1] = 0.3f + 0.3f * (float)sin(3.0 * v); li[2] = 0.5f;
    lc[0] = lc[1] = lc[2] = 0.f;
  }
}

static void Truth(int x, int y, float L[3]) {
  float tau[3], li[3], lc[3];
  int c;
  Tau(x, y, tau);
  Split(x, y, li, lc);
  for (c = 0; c < 3; ++c) L[c] = li[c] * tau[c] + lc[c];
}

/* The "renderer": evaluates a batch of pixels. */
static int Evaluate(void* user, const int* xy, int count, float* rgb, float* li, float* lc) {
  Scene* scene = (Scene*)user;
  int i;
  for (i = 0; i < count; ++i) {
    const int x = xy[2 * i], y = xy[2 * i + 1];
    if (x < 0 || x >= W || y < 0 || y >= H) return 1;
    Truth(x, y, rgb + 3 * i);
    if (li && lc) Split(x, y, li + 3 * i, lc + 3 * i);
  }
  scene->evaluated += count;
  scene->calls += 1;
  return 0;
}

static int Check(DCMReconstructor r, const char* what) {
  const char* message = NULL;
  const DCMError e = dcmGetError(r, &message);
  if (e != DCM_ERROR_NONE) {
    fprintf(stderr, "dcm_c_example: %s: error %d: %s\n", what, (int)e, message);
    return 0;
  }
  return 1;
}

int main(void) {
  static uint32_t objectIds[W * H], shaderIds[W * H];
  static float tau[W * H * 3];
  Scene scene = {0, 0};
  const float* image;
  const uint8_t* map;
  const char* message = NULL;
  int x, y, w = 0, h = 0, mw = 0, mh = 0;
  long mapExact = 0;
  double sumErr = 0.0, maxErr = 0.0, fraction;
  DCMReconstructor r;

  printf("dcm %s (C API %d)\n", dcmGetVersionString(), dcmGetApiVersion());
  if (dcmGetApiVersion() != DCM_C_API_VERSION) {
    fprintf(stderr, "dcm_c_example: header/library API mismatch\n");
    return 1;
  }

  r = dcmNewReconstructor();
  if (!r) {
    dcmGetError(NULL, &message);
    fprintf(stderr, "dcm_c_example: %s\n", message);
    return 1;
  }

  /* Errors are recorded on the handle, never thrown. */
  dcmSetString(r, "method", "no-such-method");
  if (dcmGetError(r, &message) != DCM_ERROR_INVALID_ARGUMENT) {
    fprintf(stderr, "dcm_c_example: an unknown method was accepted\n");
    return 1;
  }
  printf("rejected option   %s\n", message);

  dcmSetString(r, "method", "dcm");
  dcmSetFloat(r, "contrast_threshold", 0.05f);
  dcmSetInt(r, "elementary_block", 8);
  dcmSetInt(r, "threads", 2);
  dcmSetString(r, "object_test", "id+shader");
  if (!Check(r, "options")) return 1;

  for (y = 0; y < H; ++y)
    for (x = 0; x < W; ++x) {
      objectIds[y * W + x] = OnDisc(x, y) ? 2u : 1u;
      shaderIds[y * W + x] = OnDisc(x, y) ? 7u : 3u;
      Tau(x, y, tau + 3 * (y * W + x));
    }
  dcmSetImageSize(r, W, H);
  dcmSetObjectIds(r, objectIds);
  dcmSetShaderIds(r, shaderIds);
  dcmSetTexture(r, tau);
  dcmSetSampleFunction(r, Evaluate, &scene, DCM_SAMPLE_SPLIT);
  if (!Check(r, "input")) return 1;

  if (dcmExecute(r) != DCM_ERROR_NONE) {
    Check(r, "dcmExecute");
    return 1;
  }

  image = dcmGetImage(r, &w, &h);
  map = dcmGetSampleMap(r, &mw, &mh);
  if (!Check(r, "result") || !image || !map || w != W || h != H || mw != W || mh != H) {
    fprintf(stderr, "dcm_c_example: unexpected result %dx%d, map %dx%d\n", w, h, mw, mh);
    return 1;
  }
  for (y = 0; y < H; ++y)
    for (x = 0; x < W; ++x) {
      float L[3];
      int c;
      Truth(x, y, L);
      for (c = 0; c < 3; ++c) {
        const double e = fabs((double)image[3 * (y * W + x) + c] - (double)L[c]);
        sumErr += e;
        if (e > maxErr) maxErr = e;
      }
      if (map[y * W + x] != DCM_REASON_INTERPOLATED) ++mapExact;
    }
  fraction = dcmGetStat(r, "exact_fraction");

  printf("image             %dx%d\n", w, h);
  printf("exact pixels      %.0f of %.0f\n", dcmGetStat(r, "exact_pixels"), dcmGetStat(r, "total_pixels"));
  printf("exact fraction    %.4f\n", fraction);
  printf("callback          %ld pixels in %ld calls\n", scene.evaluated, scene.calls);
  printf("sample map        %ld exact (first: %s)\n", mapExact, dcmSampleReasonName(map[0]));
  printf("mean abs error    %.6f\n", sumErr / (3.0 * W * H));
  printf("max abs error     %.6f\n", maxErr);

  dcmReleaseReconstructor(r);

  if (!(fraction > 0.0 && fraction < 1.0)) {
    fprintf(stderr, "dcm_c_example: exact fraction %.4f is not in (0, 1)\n", fraction);
    return 1;
  }
  if (scene.evaluated != mapExact || fabs((double)mapExact - fraction * W * H) > 0.5) {
    fprintf(stderr, "dcm_c_example: callback evaluated %ld pixels, the sample map has %ld\n", scene.evaluated,
            mapExact);
    return 1;
  }
  if (sumErr / (3.0 * W * H) > 0.002 || maxErr > 0.05) {
    fprintf(stderr, "dcm_c_example: error against the analytic image too large\n");
    return 1;
  }
  printf("OK\n");
  return 0;
}
