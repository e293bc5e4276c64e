#pragma once
// Uniqueness of a match along its epipolar curve. On repeating texture (brick, tiles, grids) the true partner
// of a keypoint is often not among the other camera's keypoints (the detector keeps a few of many equal
// corners) while a repetition of it is, and the descriptor ratio test, which sees only keypoints, passes the
// repetition: a depth off by a period. The image shows what the keypoints do not: the patch at the match
// recurs further along the curve. No allocation (the samples live on the stack).
#include "mcslam/core/image.hpp"
#include "mcslam/core/se3.hpp"

namespace mcslam {

struct EpipolarRepeatSearch {
  Vec2 uv = Vec2::Zero();                // the match in the partner image
  Vec2 direction = Vec2::UnitX();        // unit tangent of the epipolar curve there
  double spacing = 1;                    // sample spacing along and across it (the partner octave's scale), pixels
  int lowest = 0, highest = 0;           // offsets searched, in samples (those of depths the matcher accepts)
  static constexpr int kMaxOffset = 96;  // cost bound; the curve is taken straight over it
};

// Where the patch of (2 half + 1)^2 samples at s.uv recurs along the direction: on either side, past the match's
// own peak (the correlation first falls below min_zncc), the best offset of every run of offsets that correlate
// with it at least min_zncc (places that look alike; whether they look like the other camera's keypoint as much
// as the match does is the caller's test). Writes at most max_count offsets, nearest first per side; returns
// their count.
int repeatsAlongEpipolar(const ImageView& image, const EpipolarRepeatSearch& s, int half, double min_zncc, int* offsets,
                         int max_count);

}  // namespace mcslam
