#pragma once
// ORB features (FAST-9 corners on an image pyramid, intensity-centroid orientation, 256-bit steered
// BRIEF) with fixed memory: every buffer is sized in the constructor from the largest image and the
// options, and extract() allocates nothing.
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "mcslam/core/image.hpp"
#include "mcslam/features/keypoint.hpp"

namespace mcslam {

struct OrbOptions {
  int max_features = 1000;     // features per image, shared among the levels in proportion to 1/scale^level
  int levels = 8;              // pyramid levels
  float scale_factor = 1.2f;   // size ratio between consecutive levels
  int fast_threshold = 20;     // FAST intensity threshold
  int min_fast_threshold = 7;  // used instead in grid cells where fast_threshold finds no corner
  int fallback_cell = 32;      // size of those cells, level pixels (ORB-SLAM uses 30)
  // Features of a level keep at least spacing_ratio * sqrt(area / budget) pixels apart (the spacing of
  // an even spread), strongest first; passes at half that and at none fill the budget. 0: strongest only.
  float spacing_ratio = 0.25f;
  int edge_margin = 16;  // pixels kept free at every border of each level; at least the patch radius (15)
  bool use_simd = true;  // false forces the portable FAST kernel (tests compare the two)
};

// Per-level scale factors: scale[l] = scale_factor^l, sigma2[l] = scale[l]^2 (keypoint position
// variance in level-0 pixels at octave l, as the odometry weights its residuals).
struct OrbLevelScales {
  std::vector<float> scale, inv_scale, sigma2, inv_sigma2;
};
OrbLevelScales orbLevelScales(const OrbOptions& options);

enum class OrbStatus {
  kOk,              // features written (possibly none: empty, tiny or textureless image)
  kImageTooLarge,   // wider or taller than the size given at construction; no features
  kOutputTooSmall,  // out.capacity() < max_features; no features
};

class OrbExtractor {
 public:
  // The patch radius of orientation and descriptor, in level pixels.
  static constexpr int kPatchRadius = 15;

  // Throws mcslam::InputError on options that cannot work (no level, scale <= 1, features < 1...).
  OrbExtractor(const OrbOptions& options, int max_width, int max_height);
  ~OrbExtractor();
  OrbExtractor(OrbExtractor&&) noexcept;
  OrbExtractor& operator=(OrbExtractor&&) noexcept;
  OrbExtractor(const OrbExtractor&) = delete;
  OrbExtractor& operator=(const OrbExtractor&) = delete;

  // Replaces the contents of `out` (out.count). Any image up to the maximum size; allocation-free.
  // Keypoints come level by level; coordinates are level-0 pixels.
  OrbStatus extract(const ImageView& image, FeatureSet& out);

  const OrbOptions& options() const;
  int maxWidth() const;
  int maxHeight() const;
  const OrbLevelScales& levelScales() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mcslam
