#pragma once
// How long tracking has been lost, in the frames' own time (relocalization_timeout_s is measured with it), summed
// frame by frame: a stamp that is not after the one before (a camera clock stepped back, a frame delivered twice)
// adds nothing, so a clock stepped back cannot hold a loss open. Stamps that do not increase are counted.
#include <cstdint>

#include "mcslam/core/time.hpp"

namespace mcslam {

class LossClock {
 public:
  // Every frame, in order: false when its stamp is not after the last frame's.
  bool frame(Timestamp t);
  void startLoss() { lost_ns_ = 0; }  // at the first lost frame (after frame())
  double lostSeconds() const { return static_cast<double>(lost_ns_) * 1e-9; }
  uint64_t stampsNotIncreasing() const { return not_increasing_; }

 private:
  bool has_last_ = false;
  Timestamp last_ = 0;
  int64_t lost_ns_ = 0;
  uint64_t not_increasing_ = 0;
};

}  // namespace mcslam
