#include "mcslam/odometry/epipolar_band_index.hpp"

#include <algorithm>

namespace mcslam {

EpipolarBandIndex::EpipolarBandIndex(int capacity, int octaves)
    : octaves_(std::max(octaves, 1)),
      added_(capacity),
      added_key_(capacity),
      sorted_(capacity),
      start_(static_cast<std::size_t>(octaves_) * kBins + 1),
      min_sine_(octaves_),
      near_(capacity),
      near_octave_(capacity) {}

bool EpipolarBandIndex::begin(const Vec3& axis) {
  added_count_ = 0;
  near_count_ = 0;
  const double norm = axis.norm();
  if (!(norm > 1e-12)) return false;
  axis_ = axis / norm;
  u_ = axis_.unitOrthogonal();
  v_ = axis_.cross(u_);
  std::fill(min_sine_.begin(), min_sine_.end(), 1.0f);
  return true;
}

void EpipolarBandIndex::add(int32_t id, const Vec3& bearing, int octave) {
  if (added_count_ + near_count_ >= static_cast<int>(added_.size())) return;  // capacity: the caller's bound
  octave = std::clamp(octave, 0, octaves_ - 1);
  const Entry e{{static_cast<float>(bearing.x()), static_cast<float>(bearing.y()), static_cast<float>(bearing.z())},
                id};
  const double x = u_.dot(bearing), y = v_.dot(bearing);
  const double sine = std::sqrt(x * x + y * y);
  if (sine < kNearAxisSine) {
    near_octave_[near_count_] = static_cast<int8_t>(octave);
    near_[near_count_++] = e;
    return;
  }
  min_sine_[octave] = std::min(min_sine_[octave], static_cast<float>(sine));
  added_key_[added_count_] = octave * kBins + binOf(std::atan2(y, x));
  added_[added_count_++] = e;
}

void EpipolarBandIndex::finish() {
  std::fill(start_.begin(), start_.end(), 0);
  for (int i = 0; i < added_count_; ++i) ++start_[added_key_[i] + 1];
  for (std::size_t k = 1; k < start_.size(); ++k) start_[k] += start_[k - 1];
  // Counting sort: added_key_ becomes each entry's destination, then the entries move.
  for (int i = 0; i < added_count_; ++i) sorted_[start_[added_key_[i]]++] = added_[i];
  // start_ was advanced to each bin's end: shift back.
  for (std::size_t k = start_.size() - 1; k > 0; --k) start_[k] = start_[k - 1];
  start_[0] = 0;
}

}  // namespace mcslam
