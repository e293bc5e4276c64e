#pragma once
// FAST-9 corner scores (Rosten & Drummond) on a row segment, 16 pixels at a time.
#include <cstdint>

namespace mcslam::orb_detail {

// Which implementation of the vector kernel runs. kNative is the SIMD one where the build has it
// (SSE2 on x86-64, NEON on AArch64) and the scalar one elsewhere; both give identical scores.
enum class FastBackend { kScalar, kNative };

bool fastHasNativeSimd();

// out[x - x0] = FAST-9 score of pixel (x, y) if it is a corner at `threshold`, else 0, for x in [x0, x1).
// The score is the largest d such that 9 contiguous circle pixels are all brighter than centre + d or
// all darker than centre - d, so "corner at threshold t" is "score > t" and one detection at a low
// threshold answers every higher one. Reads rows y-3..y+3 and columns x0-3..x1+15: the caller pads.
// Returns how many corners the segment holds.
int fastScoreRow(const uint8_t* image, int stride, int y, int x0, int x1, int threshold, uint8_t* out,
                 FastBackend backend = FastBackend::kNative);

}  // namespace mcslam::orb_detail
