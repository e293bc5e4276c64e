#pragma once
// Powers of the image pyramid's scale factor by octave, computed once, so that per-keypoint loops need no
// std::pow (slow next to their other work).
#include <algorithm>
#include <array>
#include <cmath>

namespace mcslam {

class OctaveScales {
 public:
  explicit OctaveScales(double factor = 1.2) {
    for (int o = 0; o < kMaxOctaves; ++o) scale_[o] = std::pow(factor, o);
  }
  double operator[](int octave) const { return scale_[std::clamp(octave, 0, kMaxOctaves - 1)]; }

 private:
  static constexpr int kMaxOctaves = 32;
  std::array<double, kMaxOctaves> scale_{};
};

}  // namespace mcslam
