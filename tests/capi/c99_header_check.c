/* Compiled as strict C99 with -Wpedantic -Werror: dcm.h is plain C. */
#include <dcm/dcm.h>

/** Refers to every declaration kind of the header so that it is checked. */
int dcm_c99_header_check(void) {
  DCMReconstructor r = dcmNewReconstructor();
  DCMSampleFunction f = 0;
  DCMProgressFunction p = 0;
  DCMNoisySampleFunction nf = 0;
  DCMLevelFunction lf = 0;
  DCMError e = dcmGetError(r, 0);
  dcmSetSampleFunction(r, f, 0, DCM_SAMPLE_THREAD_SAFE | DCM_SAMPLE_SPLIT);
  dcmSetProgressFunction(r, p, 0);
  dcmSetNoisySampleFunction(r, nf, 0, DCM_SAMPLE_THREAD_SAFE);
  dcmSetLevelFunction(r, lf, 0);
  dcmSetNormals(r, 0);
  dcmReleaseReconstructor(r);
  return (int)e + DCM_REASON_COUNT + DCM_C_API_VERSION;
}
