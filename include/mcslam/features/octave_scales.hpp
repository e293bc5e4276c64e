#pragma once
// Powers of the image pyramid's scale factor by octave, computed once: std::pow in per-keypoint loops showed
// in profiles.
#include <algorithm>
#include <array>

namespace mcslam {

class OctaveScales {
 public:
  explicit OctaveScales(double factor = 1.2) {
    double s = 1.0;
    for (double& v : scale_) {
      v = s;
      s *= factor;
    }
  }
  double operator[](int octave) const { return scale_[std::clamp(octave, 0, kMaxOctaves - 1)]; }

 private:
  static constexpr int kMaxOctaves = 32;
  std::array<double, kMaxOctaves> scale_{};
};

}  // namespace mcslam
