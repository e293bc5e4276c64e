#include "orb_fast.hpp"

#include "orb_fast_kernel.hpp"
#include "orb_simd.hpp"

namespace mcslam::orb_detail {

bool fastHasNativeSimd() {
#if defined(MCSLAM_ORB_HAVE_NATIVE)
  return true;
#else
  return false;
#endif
}

bool fastHasWideSimd() {
#if defined(MCSLAM_ORB_HAVE_AVX2_UNIT)
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return avx2;
#else
  return false;
#endif
}

int fastScoreRow(const uint8_t* image, int stride, int y, int x0, int x1, int threshold, uint8_t* out,
                 FastBackend backend) {
#if defined(MCSLAM_ORB_HAVE_AVX2_UNIT)
  if (backend == FastBackend::kWide && fastHasWideSimd())
    return fastScoreRowAvx2(image, stride, y, x0, x1, threshold, out);
#endif
#if defined(MCSLAM_ORB_HAVE_NATIVE)
  if (backend != FastBackend::kScalar) return scoreRow<NativeU8x16>(image, stride, y, x0, x1, threshold, out);
#endif
  return scoreRow<ScalarU8x16>(image, stride, y, x0, x1, threshold, out);
}

}  // namespace mcslam::orb_detail
