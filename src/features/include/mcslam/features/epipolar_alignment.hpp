#pragma once
// Subpixel alignment of a matched keypoint along its epipolar curve: the patch around the reference keypoint
// is found in the other camera's image by one-parameter Gauss-Newton (inverse compositional) on the shift along
// the epipolar direction, with gain and bias normalised away (the residual is that of zero-mean normalised
// cross-correlation). FAST keypoints are integer pixels of their octave; aligning the partner to the reference
// pixel removes the partner's quantisation (up to half a pixel of its octave) from the disparity, which at
// disparities of tens of pixels is several percent of the depth.
//
// The patch warp between the cameras is the local affine map A of the geometry (rotation, scale and lens
// distortion about the point, the surface taken normal to the reference ray), given by the caller; only the
// shift along the epipolar direction is estimated, so the aperture problem of edges cannot move the match off
// the epipolar curve. No allocation: the patches live in the caller's AlignmentTemplate and on the stack.
#include "mcslam/core/image.hpp"
#include "mcslam/core/se3.hpp"

namespace mcslam {

struct EpipolarAlignmentOptions {
  int half_size = 3;  // patch of (2 half_size + 1)^2 samples, spaced by the reference octave's scale
  int max_iterations = 8;
  double converged_px = 0.01;  // stop when a step is below this
  // Patches that correlate less than this after alignment show different surfaces (a wrong match, or a depth
  // edge where the two views see different backgrounds).
  double min_zncc = 0.85;
  // The shift may not exceed this many sample spacings (reference plus partner octave scales): both keypoints are
  // within half a pixel of their octave of the corner, so a longer shift converged on another structure.
  double max_shift_spacings = 1.0;
  // Position sigma added in quadrature to the one the residual gives: bilinear interpolation and the affine patch
  // model are not exact (a fraction of a sample spacing).
  double sigma_floor_spacings = 0.05;
  // The SSE2 (x86-64) or NEON (AArch64) kernels where the build has them; false: the portable ones. Both give
  // identical results (tests/frontend/epipolar_alignment_test.cpp).
  bool use_simd = true;
};

enum class AlignmentStatus : uint8_t {
  Ok = 0,
  NotRefinable,  // patch outside either image, no texture along the epipolar direction, singular warp
  Disagrees,     // the patches do not correlate, or the shift left the keypoints' neighbourhood
};

struct EpipolarAlignment {
  AlignmentStatus status = AlignmentStatus::NotRefinable;
  Vec2 uv = Vec2::Zero();  // aligned position in the partner image
  double shift = 0;        // along the direction, pixels
  double sigma_px = 0;     // standard deviation of the position along the direction
  double zncc = 0;
  bool ok() const { return status == AlignmentStatus::Ok; }
};

// The reference side of the alignment, sampled once per track and shared by all its partners (they differ only
// in the warp): the patch around the reference pixel, zero mean and unit norm, and its derivatives per reference
// pixel in x and y (normalised alike). Padded to whole groups of 4 samples with zeros.
struct AlignmentTemplate {
  static constexpr int kMaxHalf = 6;
  static constexpr int kMaxSamples = (2 * kMaxHalf + 1) * (2 * kMaxHalf + 1);
  static constexpr int kMaxPadded = (kMaxSamples + 3) / 4 * 4;
  bool ok = false;  // false: outside the image or no texture
  int half = 3;
  int samples = 0;  // (2 half + 1)^2
  int padded = 0;   // samples rounded up to a multiple of 4
  double spacing = 1;
  Vec2 uv = Vec2::Zero();
  alignas(16) float value[kMaxPadded];
  alignas(16) float dx[kMaxPadded];
  alignas(16) float dy[kMaxPadded];
  Vec2 axis = Vec2::UnitX();  // the dominant gradient's direction (main axis of the structure tensor)
};

// Where in the template the alignment's information lies, relative to its centre (reference pixels): the
// centroid of each sample's share of the Gauss-Newton information (its squared derivative along the dominant
// axis, mean removed as the ZNCC residual removes it), projected on that axis. A patch of one edge (a silhouette
// against a flat background) measures the disparity of that edge, wherever its centre is: the point belongs
// toward the edge (the fattening of window matching at depth discontinuities).
Vec2 informationCentroid(const AlignmentTemplate& tmpl);

// Samples the template of `ref` around ref_uv with the given spacing (reference pixels: the reference octave's
// scale). Returns tmpl.ok.
bool makeAlignmentTemplate(const ImageView& ref, const Vec2& ref_uv, double spacing,
                           const EpipolarAlignmentOptions& options, AlignmentTemplate& tmpl);

// Finds the point of `image` that shows what the template shows at its centre. uv0: start on the epipolar curve
// (the partner keypoint projected onto it); direction: unit tangent of the curve there; A: reference pixel
// offset -> partner pixel offset; partner_spacing: the partner octave's scale (bounds the shift).
EpipolarAlignment alignAlongEpipolar(const AlignmentTemplate& tmpl, const ImageView& image, const Vec2& uv0,
                                     const Vec2& direction, const Mat2& A, double partner_spacing,
                                     const EpipolarAlignmentOptions& options);

// Both steps for one partner: spacing is the reference octave's scale.
EpipolarAlignment alignAlongEpipolar(const ImageView& ref, const Vec2& ref_uv, const ImageView& image, const Vec2& uv0,
                                     const Vec2& direction, const Mat2& A, double spacing, double partner_spacing,
                                     const EpipolarAlignmentOptions& options);

}  // namespace mcslam
