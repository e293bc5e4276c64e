#pragma once
// Candidates along epipolar curves between two cameras at different times, without walking the curves.
// Every epipolar plane of two camera centres contains their baseline: it is one half-plane of the pencil
// about the baseline axis, named by its angle. A scene point lies on the same half-plane seen from either
// centre, so the partners of a ray are the bearings of the other camera whose half-plane angle is within a
// small window of the ray's (the window widens near the baseline direction, where bearings are kept apart
// and checked one by one). Bearings are binned by octave and angle with a counting sort: O(n) per pair.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "mcslam/core/se3.hpp"

namespace mcslam {

class EpipolarBandIndex {
 public:
  static constexpr int kBins = 256;              // per octave, over the full turn
  static constexpr double kNearAxisSine = 0.05;  // bearings within ~3 degrees of the baseline: checked one by one

  EpipolarBandIndex(int capacity, int octaves);

  // Starts a new pair: `axis` is the baseline between the two centres, any length (zero: no geometry).
  // Returns false when the centres coincide.
  bool begin(const Vec3& axis);
  // Adds a bearing (unit, in the frame of the axis) of the indexed camera with its id and octave.
  void add(int32_t id, const Vec3& bearing, int octave);
  // Sorts what was added; call once before the queries.
  void finish();

  // Calls f(id, bearing) for every indexed bearing of octave [octave_lo, octave_hi] whose sine distance to
  // the epipolar plane of `ray` is at most gate[octave], and which lies on the same half-plane as `ray`.
  // Returns false when `ray` runs along the baseline (no plane).
  template <class F>
  bool forEachOnPlane(const Vec3& ray, int octave_lo, int octave_hi, const double* gate, F&& f) const;

 private:
  struct Entry {
    float d[3];
    int32_t id;
  };
  int binOf(double angle) const {
    const int b = static_cast<int>((angle + M_PI) * (kBins / (2 * M_PI)));
    return b < 0 ? 0 : (b >= kBins ? kBins - 1 : b);
  }

  int octaves_;
  Vec3 axis_ = Vec3::Zero(), u_ = Vec3::Zero(), v_ = Vec3::Zero();
  // Added, then sorted by (octave, bin).
  std::vector<Entry> added_;
  std::vector<int32_t> added_key_;
  int added_count_ = 0;
  std::vector<Entry> sorted_;
  std::vector<int32_t> start_;   // octaves * kBins + 1
  std::vector<float> min_sine_;  // per octave: smallest sine to the axis among its binned bearings
  std::vector<Entry> near_;      // near the axis, any octave
  std::vector<int8_t> near_octave_;
  int near_count_ = 0;
};

template <class F>
bool EpipolarBandIndex::forEachOnPlane(const Vec3& ray, int octave_lo, int octave_hi, const double* gate, F&& f) const {
  const double x = u_.dot(ray), y = v_.dot(ray);
  const double sine = std::sqrt(x * x + y * y);
  if (sine < 1e-9) return false;
  const Vec3 n = (axis_.cross(ray)) / sine;        // normal of the ray's epipolar plane
  const Vec3 perp = ray - axis_ * axis_.dot(ray);  // its half-plane
  const float nf[3] = {static_cast<float>(n.x()), static_cast<float>(n.y()), static_cast<float>(n.z())};
  const float pf[3] = {static_cast<float>(perp.x()), static_cast<float>(perp.y()), static_cast<float>(perp.z())};
  auto test = [&](const Entry& e, double g) {
    const float dot = nf[0] * e.d[0] + nf[1] * e.d[1] + nf[2] * e.d[2];
    if (std::abs(dot) > g) return;
    if (pf[0] * e.d[0] + pf[1] * e.d[1] + pf[2] * e.d[2] <= 0.f) return;  // the opposite half-plane
    f(e.id, e.d);
  };
  const double angle = std::atan2(y, x);
  octave_lo = std::max(octave_lo, 0);
  octave_hi = std::min(octave_hi, octaves_ - 1);
  for (int o = octave_lo; o <= octave_hi; ++o) {
    const int32_t* start = start_.data() + static_cast<std::size_t>(o) * kBins;
    if (start[0] == start[kBins]) continue;
    // |n . d| = sine(d, axis) * |sin(angle difference)|: the window that the gate allows at the smallest sine.
    const double s = gate[o] / min_sine_[o];
    if (s >= 0.7) {  // a wide window: scan the octave (the half-plane test keeps the right side)
      for (int32_t k = start[0]; k < start[kBins]; ++k) test(sorted_[k], gate[o]);
      continue;
    }
    const double w = std::asin(s) + 1e-5;  // margin for the float bearings
    const int first = binOf(angle - w < -M_PI ? angle - w + 2 * M_PI : angle - w);
    const int last = binOf(angle + w > M_PI ? angle + w - 2 * M_PI : angle + w);
    for (int b = first;; b = (b + 1) % kBins) {
      for (int32_t k = start[b]; k < start[b + 1]; ++k) test(sorted_[k], gate[o]);
      if (b == last) break;
    }
  }
  for (int k = 0; k < near_count_; ++k) {
    if (near_octave_[k] >= octave_lo && near_octave_[k] <= octave_hi) test(near_[k], gate[near_octave_[k]]);
  }
  return true;
}

}  // namespace mcslam
