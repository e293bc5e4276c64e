#pragma once
// FAST-9 corner scores (Rosten & Drummond) on a row segment, 16 pixels at a time.
#include <cstdint>

namespace mcslam::orb_detail {

// Which implementation of the vector kernel runs; all give identical scores. kNative is the 16-lane SIMD one
// where the build has it (SSE2 on x86-64, NEON on AArch64), the scalar one elsewhere. kWide is the 32-lane AVX2
// one on x86-64 CPUs that have it (checked at run time: the build targets the baseline), else kNative.
enum class FastBackend { kScalar, kNative, kWide };

bool fastHasNativeSimd();
bool fastHasWideSimd();  // kWide runs the AVX2 kernel on this machine

// out[x - x0] = FAST-9 score of pixel (x, y) if it is a corner at `threshold`, else 0, for x in [x0, x1).
// The score is the largest d such that 9 contiguous circle pixels are all brighter than centre + d or
// all darker than centre - d, so "corner at threshold t" is "score > t" and one detection at a low
// threshold answers every higher one. Reads rows y-3..y+3 and columns x0-3..x1+34: the caller pads.
// Returns how many corners the segment holds.
int fastScoreRow(const uint8_t* image, int stride, int y, int x0, int x1, int threshold, uint8_t* out,
                 FastBackend backend = FastBackend::kWide);

#if defined(MCSLAM_ORB_HAVE_AVX2_UNIT)
// The AVX2 builds of the kernels (orb_avx2.cpp): call only when fastHasWideSimd().
int fastScoreRowAvx2(const uint8_t* image, int stride, int y, int x0, int x1, int threshold, uint8_t* out);
void gaussianBlur7Avx2(const uint8_t* src, int src_stride, uint8_t* dst, int dst_stride, uint8_t* tmp, int tmp_stride,
                       int w, int h);
#endif

}  // namespace mcslam::orb_detail
