#pragma once
// Orientation by intensity centroid and the steered BRIEF descriptor (rBRIEF) of one keypoint.
#include <cstdint>
#include <vector>

#include "mcslam/features/keypoint.hpp"

namespace mcslam::orb_detail {

constexpr int kPatchRadius = 15;  // orientation disc and every (rotated) test point stay within it
constexpr int kAngleBins = 128;   // the pattern is pre-rotated for each bin (2.8 degrees)
constexpr int kTests = 256;

// One binary test: bit = I(a) < I(b), offsets from the keypoint in level pixels.
struct PointPair {
  int8_t ax, ay, bx, by;
};

// The 256 test pairs, rotated for every angle bin. Generated once (process-wide, read-only).
struct RotatedPattern {
  PointPair tests[kAngleBins][kTests];
};
const RotatedPattern& rotatedPattern();

// The unrotated pattern in continuous coordinates (for tests): generated from a fixed seed.
struct PatternPoint {
  float x, y;
};
void generateBriefPattern(PatternPoint (&a)[kTests], PatternPoint (&b)[kTests]);

// Angle (radians, [0, 2 pi)) from the keypoint to the intensity centroid of the disc of radius 15
// around `center` (unsmoothed image). The disc must lie inside the image.
float intensityCentroidAngle(const uint8_t* center, int stride);

// The rotated pattern as address offsets for one row stride: two per test, for every angle bin.
class PatternOffsets {
 public:
  explicit PatternOffsets(int stride);
  int stride() const { return stride_; }
  const int32_t* forAngle(float angle) const;  // 2 * kTests offsets

 private:
  int stride_;
  std::vector<int32_t> offsets_;
};

// Descriptor of the keypoint at `center` in the smoothed image (its stride is the table's).
void steeredBrief(const uint8_t* center, const int32_t* offsets, Descriptor& out);

}  // namespace mcslam::orb_detail
