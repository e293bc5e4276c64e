#include "mcslam/features/epipolar_uniqueness.hpp"

#include <algorithm>
#include <cmath>

#include "bilinear_sample.hpp"
#include "mcslam/features/epipolar_alignment.hpp"

namespace mcslam {

namespace {

constexpr int kMaxHalf = AlignmentTemplate::kMaxHalf;
constexpr int kMaxRows = 2 * kMaxHalf + 1;
constexpr int kMaxColumns = 2 * (EpipolarRepeatSearch::kMaxOffset + kMaxHalf) + 1;

// The image resampled along the line, column by column as the search reaches them: column c holds the samples
// at offset (c - centre) along the direction, (r - half) across it, contiguously, so that a window of columns
// is one run of floats. Columns that leave the image are invalid.
class Strip {
 public:
  Strip(const ImageView& im, const EpipolarRepeatSearch& s, int half) : im_(im), half_(half), rows_(2 * half + 1) {
    tx_ = static_cast<float>(s.direction.x() * s.spacing);
    ty_ = static_cast<float>(s.direction.y() * s.spacing);
    x0_ = static_cast<float>(s.uv.x());
    y0_ = static_cast<float>(s.uv.y());
  }
  static constexpr int centre = kMaxColumns / 2;
  int rows() const { return rows_; }
  const float* column(int offset) const { return v_ + (centre + offset) * rows_; }
  float sum(int offset) const { return sum_[centre + offset]; }
  float sum2(int offset) const { return sum2_[centre + offset]; }

  // Samples the column at `offset`; false when part of it lies outside the image.
  bool sample(int offset) {
    const int c = centre + offset;
    float* out = v_ + c * rows_;
    const float u = static_cast<float>(offset);
    const float xmax = static_cast<float>(im_.width - 1), ymax = static_cast<float>(im_.height - 1);
    float s = 0, s2 = 0;
    for (int r = 0; r < rows_; ++r) {
      const float w = static_cast<float>(r - half_);
      const float x = x0_ + u * tx_ - w * ty_, y = y0_ + u * ty_ + w * tx_;
      if (!(x >= 0 && y >= 0 && x < xmax && y < ymax)) return false;
      out[r] = sampleBilinear(im_, x, y);
      s += out[r];
      s2 += out[r] * out[r];
    }
    sum_[c] = s;
    sum2_[c] = s2;
    return true;
  }

 private:
  const ImageView& im_;
  int half_, rows_;
  float tx_, ty_, x0_, y0_;
  float v_[kMaxColumns * kMaxRows];
  float sum_[kMaxColumns], sum2_[kMaxColumns];
};

// Sum of products in 4 lanes added in a fixed order (the same result on every platform and call site).
float dot(const float* a, const float* b, int n) {
  float l[4] = {0, 0, 0, 0};
  int k = 0;
  for (; k + 4 <= n; k += 4) {
    for (int j = 0; j < 4; ++j) l[j] += a[k + j] * b[k + j];
  }
  for (; k < n; ++k) l[0] += a[k] * b[k];
  return (l[0] + l[1]) + (l[2] + l[3]);
}

}  // namespace

int repeatsAlongEpipolar(const ImageView& image, const EpipolarRepeatSearch& s, int half, double min_zncc, int* offsets,
                         int max_count) {
  half = std::clamp(half, 1, kMaxHalf);
  const int lowest = std::max(s.lowest, -EpipolarRepeatSearch::kMaxOffset);
  const int highest = std::min(s.highest, EpipolarRepeatSearch::kMaxOffset);
  if (image.empty() || (lowest > -1 && highest < 1) || max_count < 1) return 0;
  Strip strip(image, s, half);
  const int rows = strip.rows(), n = rows * rows;
  for (int c = -half; c <= half; ++c) {
    if (!strip.sample(c)) return 0;
  }
  // The patch at the match, zero mean.
  float ref[kMaxRows * kMaxRows];
  float mean = 0;
  for (int c = -half; c <= half; ++c) mean += strip.sum(c);
  mean /= static_cast<float>(n);
  const float* first = strip.column(-half);
  for (int k = 0; k < n; ++k) ref[k] = first[k] - mean;
  const double ref_norm2 = dot(ref, ref, n);
  if (!(ref_norm2 > 0)) return 0;
  // Against the zero-mean reference, the window's own mean drops out of the product.
  auto zncc = [&](int offset) {
    float sum = 0, sum2 = 0;
    for (int c = offset - half; c <= offset + half; ++c) {
      sum += strip.sum(c);
      sum2 += strip.sum2(c);
    }
    const double var = static_cast<double>(sum2) - static_cast<double>(sum) * sum / n;
    return var > 0 ? dot(strip.column(offset - half), ref, n) / std::sqrt(var * ref_norm2) : 0.0;
  };
  // Outward from the match on either side: first off its own peak, then the best of every run as alike as a match.
  int count = 0;
  for (const int step : {1, -1}) {
    const int last = step > 0 ? highest : lowest;
    bool left_peak = false;
    int run_best = 0;
    double run_zncc = -1;
    for (int k = step; step > 0 ? k <= last : k >= last; k += step) {
      const bool inside = strip.sample(k + step * half);  // false: the window reached the image's border
      const double z = inside ? zncc(k) : -1.0;
      if (!left_peak) {
        left_peak = z < min_zncc;
      } else if (z >= min_zncc) {
        if (z > run_zncc) {
          run_zncc = z;
          run_best = k;
        }
      } else if (run_zncc >= 0) {  // a run ended
        offsets[count++] = run_best;
        if (count == max_count) return count;
        run_zncc = -1;
      }
      if (!inside) break;
    }
    if (run_zncc >= 0) {
      offsets[count++] = run_best;
      if (count == max_count) return count;
    }
  }
  return count;
}

}  // namespace mcslam
